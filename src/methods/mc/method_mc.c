#include "methods/mc/method_mc.h"

#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kernels/ppb_fresnel.h"
#include "physics/medium.h"
#include "methods/mc/mc_cache.h"
#include "model/metrics.h"
#include "base/memory.h"
#include "base/progress.h"

/* Host and kernel must agree on the parameter block passed by value (kernels/mc_params.h). */
_Static_assert(sizeof(ppb_mc_params) == 4 * 8 + sizeof(ppb_medium) + 11 * 4 + 5 * 4,
               "ppb_mc_params layout changed: check mc.cl");

/* Everything one trace holds on the device, released by one NULL-safe cleanup. */
typedef struct mc_device {
    cl_program prog;
    cl_kernel kernel;
    cl_mem cells, totals;
} mc_device;

static void mc_device_release(mc_device *d)
{
    if (d->cells)
        clReleaseMemObject(d->cells);
    if (d->totals)
        clReleaseMemObject(d->totals);
    if (d->kernel)
        clReleaseKernel(d->kernel);
    if (d->prog)
        clReleaseProgram(d->prog);
    memset(d, 0, sizeof *d);
}

static int device_has(cl_device_id dev, const char *ext, ppb_err *err, int *has)
{
    size_t n = 0;
    if (ppb_cl_check(clGetDeviceInfo(dev, CL_DEVICE_EXTENSIONS, 0, NULL, &n),
                     "clGetDeviceInfo(CL_DEVICE_EXTENSIONS)", err))
        return -1;
    char *s = malloc(n + 1);
    if (!s)
        return ppb_fail(err, "mc: out of memory");
    cl_int rc = clGetDeviceInfo(dev, CL_DEVICE_EXTENSIONS, n, s, NULL);
    s[n] = 0;
    *has = rc == CL_SUCCESS && strstr(s, ext) != NULL;
    free(s);
    return ppb_cl_check(rc, "clGetDeviceInfo(CL_DEVICE_EXTENSIONS)", err);
}

static ppb_mc_params make_params(const ppb_config *cfg)
{
    const ppb_scene *sc = &cfg->scene;
    ppb_layout lo = ppb_scene_layout(sc);
    double wl[3];
    ppb_scene_light_dir(sc, wl);
    float entry_weight = 1.0f;
    if (sc->n > 1.0) {
        /* The beam enters refracted (Snell) with 1 - F; F is the specular total. At
         * n = 1 nothing here runs, so the photons are those of before bit for bit. */
        double cos_l = ppb_scene_cos_theta_l(sc);
        wl[0] = wl[0] / sc->n;
        wl[1] = -ppb_refract_cos(cos_l, sc->n);
        entry_weight = (float)(1.0 - ppb_fresnel(cos_l, sc->n));
    }
    double lit_lo, lit_hi; /* S1's lit part (reference: Light); a line: lit_lo == lit_hi */
    ppb_scene_lit_range(sc, &lit_lo, &lit_hi);
    ppb_mc_params p = {
        .seed = (ppb_u64)cfg->mc.seed,
        .ncells = (ppb_u64)lo.ncells,
        .med = ppb_medium_of(sc),
        .batches = cfg->mc.batches,
        .ntheta = sc->ntheta,
        .nphi = sc->nphi,
        .light_x = (float)wl[0],
        .light_y = (float)wl[1],
        .enter_x0 = (float)lit_lo,
        .enter_width = (float)ppb_scene_lit_width(sc),
        .entry_weight = entry_weight,
    };
    for (int s = 0; s < PPB_NSURF; s++) {
        p.nseg[s] = lo.nseg[s];
        p.offset[s] = lo.offset[s];
    }
    return p;
}

/* nch channels' tallies t[0 .. nch - 1]; the fingerprint is checked for the first, whose scene
 * cfg is (the others' media differ: ppb_mc_trace_channels). */
static int check_settings(const ppb_config *cfg, long long first, long long count,
                          const ppb_mc_tallies *t, int nch, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    if (first < 0 || count < 0)
        return ppb_fail(err, "mc: photon range [%lld, +%lld) is negative", first, count);
    for (int c = 0; c < nch; c++)
        if (cfg->mc.batches != t[c].batches || (uint64_t)cfg->mc.seed != t[c].seed ||
            (c == 0 && ppb_mc_scene_fingerprint(sc) != t->fingerprint))
            return ppb_fail(err, "mc: tallies were made for another scene, seed or batch count");
    if (sc->geometry == PPB_GEOM_SLAB && sc->step != PPB_STEP_NONE)
        return ppb_fail(err, "mc: steps are not defined in slab mode (docs/reference.md)");
    if (sc->theta_deg < 0 || sc->theta_deg >= 90)
        return ppb_fail(err, "mc: theta_deg must lie in [0, 90) (got %g)", sc->theta_deg);
    if (sc->sigma_t <= 0 || (sc->step == PPB_STEP_DENSITY && sc->sigma_t_right <= 0))
        return ppb_fail(err, "mc: sigma_t must be positive");
    /* Fixed-point headroom (kernels/mc_params.h): fewer than 2^31 photons per batch; with
     * several channels a weight reaches nch times a single run's (mc_rgb.cl), so 2^29. */
    uint64_t per_batch = (uint64_t)count / (uint64_t)t->batches + 1;
    int bits = nch > 1 ? 29 : 31;
    for (int b = 0; b < t->batches; b++)
        if (t->photons[b] + per_batch >= ((uint64_t)1 << bits))
            return ppb_fail(err,
                            "mc: more than 2^%d photons per batch would overflow the "
                            "fixed-point tallies; raise [mc] batches",
                            bits);
    return 0;
}

/* Sizes of a tallies' arrays (shapes in src/methods/mc_tally.h), the same on the device and the
 * host. */
static size_t cell_bytes(const ppb_mc_tallies *t)
{
    return (size_t)t->batches * PPB_MC_NTALLY * t->ncells * sizeof(uint64_t);
}

static size_t total_bytes(const ppb_mc_tallies *t)
{
    return (size_t)t->batches * PPB_MC_NTOT * sizeof(uint64_t);
}

/* How the kernel is laid out on a device: photons side by side per work-item (SIMD lanes on a
 * CPU, where nothing vectorises across work-items: its native float vector width, 16 with
 * AVX-512 and 8 with AVX2, clamped to [8, 16]; 2 on a GPU, whose SIMD is the work-items) and
 * work-items per launch (enough to fill a GPU's compute units, 2048 resident threads each, or
 * to balance a CPU's cores). None of it changes a photon's path. */
typedef struct mc_shape {
    int lanes;
    long long items;
    size_t local; /* work-group size when [mc] workgroup is 0 (pick_workgroup) */
    int cpu;      /* prefetch tally lines by clang's builtin (mc.cl PPB_MC_CPU_PREFETCH) */
} mc_shape;

static int device_shape(const ppb_ocl *ocl, mc_shape *shape, ppb_err *err)
{
    cl_device_type type = 0;
    if (ppb_cl_check(clGetDeviceInfo(ocl->device, CL_DEVICE_TYPE, sizeof type, &type, NULL),
                     "clGetDeviceInfo(CL_DEVICE_TYPE)", err))
        return -1;
    long long units = ocl->compute_units ? (long long)ocl->compute_units : 1;
    int cpu = (type & CL_DEVICE_TYPE_CPU) != 0;
    cl_uint width = 0;
    if (cpu && ppb_cl_check(clGetDeviceInfo(ocl->device, CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT,
                                            sizeof width, &width, NULL),
                            "clGetDeviceInfo(CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT)", err))
        return -1;
    /* 16 lanes on PoCL's AVX-512 device take 10-15% less CPU time than 8 */
    shape->lanes = cpu ? (width >= 16 ? 16 : 8) : 2;
    /* $PPBENCH_MC_LANES (2, 4, 8 or 16) overrides the lane count: tests/test_mc.c checks that
     * it never changes a tally, and benchmarks compare widths with it. */
    const char *env = getenv("PPBENCH_MC_LANES");
    if (env && *env) {
        int lanes = atoi(env);
        if (lanes != 2 && lanes != 4 && lanes != 8 && lanes != 16)
            return ppb_fail(err, "mc: PPBENCH_MC_LANES must be 2, 4, 8 or 16 (got '%s')", env);
        shape->lanes = lanes;
    }
    shape->items = units * (cpu ? 1024 : 2048);
    shape->local = cpu ? 1 : 64;
    shape->cpu = cpu;
    return 0;
}

/* Photons per launch: 64 per lane keeps the lanes busy to the end and the launch overhead
 * below a percent. Fixed by the device, never by timing, so a target-noise run stops at the
 * same photon count every time on the same device. */
static long long auto_chunk(const mc_shape *shape)
{
    return shape->items * shape->lanes * 64;
}

int ppb_mc_chunk(ppb_run_ctx *ctx, long long *chunk, ppb_err *err)
{
    ppb_ocl *ocl;
    mc_shape shape;
    if (ctx->cfg->mc.chunk > 0) {
        *chunk = ctx->cfg->mc.chunk;
        return 0;
    }
    if (ppb_ctx_ocl(ctx, &ocl, err) || device_shape(ocl, &shape, err))
        return -1;
    *chunk = auto_chunk(&shape);
    return 0;
}

/* One trace in progress: what every chunk needs, gathered so the helpers below share it. */
typedef struct mc_run {
    const ppb_config *cfg;
    ppb_ocl *ocl;
    const mc_shape *shape;
    mc_device *d;
    size_t local;      /* work-group size */
    long long chunk;   /* photons per launch */
    long long first;   /* first photon of the range */
    ppb_mc_params p;   /* first and count change per launch */
    int nch;           /* channels: 1 (mc.cl) or more (mc_rgb.cl, tallies one after another) */
    ppb_mc_tallies *t; /* the caller's tallies, t[0 .. nch - 1]: the device's are added to
                          them at the end */
    ppb_mc_tallies tmp[PPB_MC_MAX_CH]; /* host copy of the device's tallies, shaped like t */
} mc_run;

/* The kernel adds into the device tallies launch after launch, so they start at zero and stay
 * bound to the kernel for the whole trace. */
static int create_buffers(mc_run *r, ppb_err *err)
{
    size_t cb = cell_bytes(r->t) * (size_t)r->nch, tb = total_bytes(r->t) * (size_t)r->nch;
    mc_device *d = r->d;
    cl_int rc;
    d->cells = clCreateBuffer(r->ocl->context, CL_MEM_READ_WRITE, cb, NULL, &rc);
    if (ppb_cl_check(rc, "clCreateBuffer(mc cells)", err))
        return -1;
    d->totals = clCreateBuffer(r->ocl->context, CL_MEM_READ_WRITE, tb, NULL, &rc);
    if (ppb_cl_check(rc, "clCreateBuffer(mc totals)", err))
        return -1;
    const cl_ulong zero = 0;
    cl_command_queue q = r->ocl->queue;
    if (ppb_cl_check(clEnqueueFillBuffer(q, d->cells, &zero, sizeof zero, 0, cb, 0, NULL, NULL),
                     "clEnqueueFillBuffer(mc cells)", err) ||
        ppb_cl_check(clEnqueueFillBuffer(q, d->totals, &zero, sizeof zero, 0, tb, 0, NULL, NULL),
                     "clEnqueueFillBuffer(mc totals)", err))
        return -1;
    if (ppb_cl_check(clSetKernelArg(d->kernel, PPB_MC_ARG_CELLS, sizeof d->cells, &d->cells),
                     "clSetKernelArg(mc cells)", err) ||
        ppb_cl_check(clSetKernelArg(d->kernel, PPB_MC_ARG_TOTALS, sizeof d->totals, &d->totals),
                     "clSetKernelArg(mc totals)", err))
        return -1;
    return 0;
}

/* Work-group size 0 means ppbench picks (device_shape): 64 work-items on a GPU; 1 on a CPU,
 * where PoCL then compiles the work-item as it stands, its state in registers from step to
 * step, while a larger group runs its work-items in a loop that keeps every value carried
 * from one step to the next in per-work-item arrays, stored each step (a fifth of
 * the kernel's time at 64). Either keeps a group inside one batch. A size the user asked for
 * is never shrunk silently. */
static int pick_workgroup(const ppb_config *cfg, const ppb_ocl *ocl, const mc_shape *shape,
                          size_t *local, ppb_err *err)
{
    *local = cfg->mc.workgroup > 0 ? (size_t)cfg->mc.workgroup : shape->local;
    if (!cfg->mc.workgroup && *local > ocl->max_workgroup)
        *local = ocl->max_workgroup;
    if (*local > ocl->max_workgroup)
        return ppb_fail(err, "mc: workgroup %zu exceeds the device's maximum %zu", *local,
                        ocl->max_workgroup);
    return 0;
}

/* The host copy is allocated once per trace, not per noise check. Cells and totals need no
 * zeroing: every read overwrites them whole. */
static int alloc_host_copy(const ppb_mc_tallies *t, ppb_mc_tallies *tmp, ppb_err *err)
{
    *tmp = (ppb_mc_tallies){
        .fingerprint = t->fingerprint, .seed = t->seed, .batches = t->batches, .ncells = t->ncells};
    tmp->photons = calloc((size_t)t->batches, sizeof *tmp->photons);
    tmp->cells = malloc(cell_bytes(t));
    tmp->totals = malloc(total_bytes(t));
    if (!tmp->photons || !tmp->cells || !tmp->totals)
        return ppb_fail(err, "mc: out of memory for tallies");
    return 0;
}

/* Everything fixed for the whole trace, settled before the clock starts. */
static int prepare_run(mc_run *r, ppb_err *err)
{
    if (create_buffers(r, err) || pick_workgroup(r->cfg, r->ocl, r->shape, &r->local, err))
        return -1;
    r->chunk = r->cfg->mc.chunk > 0 ? r->cfg->mc.chunk : auto_chunk(r->shape);
    for (int c = 0; c < r->nch; c++)
        if (alloc_host_copy(&r->t[c], &r->tmp[c], err))
            return -1;
    r->p = make_params(r->cfg);
    return 0;
}

/* Reads the device tallies of photons [first, first + done) into r->tmp. The device counts no
 * photons, so the per-batch counts are rebuilt from the range (batch = index % batches). */
static int read_tallies(mc_run *r, long long done, ppb_err *err)
{
    for (int c = 0; c < r->nch; c++) {
        ppb_mc_tallies *tmp = &r->tmp[c];
        memset(tmp->photons, 0, (size_t)tmp->batches * sizeof *tmp->photons);
        ppb_mc_tallies_count_range(tmp, (uint64_t)r->first, (uint64_t)done);
        cl_command_queue q = r->ocl->queue;
        size_t cb = cell_bytes(tmp), tb = total_bytes(tmp);
        if (ppb_cl_check(clEnqueueReadBuffer(q, r->d->cells, CL_TRUE, cb * (size_t)c, cb,
                                             tmp->cells, 0, NULL, NULL),
                         "clEnqueueReadBuffer(mc cells)", err) ||
            ppb_cl_check(clEnqueueReadBuffer(q, r->d->totals, CL_TRUE, tb * (size_t)c, tb,
                                             tmp->totals, 0, NULL, NULL),
                         "clEnqueueReadBuffer(mc totals)", err))
            return -1;
    }
    return 0;
}

/* noise_rel at the x = 0 cells of S1 and S2 (reference: Metrics), the larger of the two,
 * for the tallies so far (t plus the device's, already read into tmp). */
static int noise_now(const ppb_config *cfg, const ppb_mc_tallies *t, ppb_mc_tallies *tmp,
                     double *noise, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    if (ppb_mc_tallies_add(tmp, t, err))
        return -1;
    ppb_layout lo = ppb_scene_layout(sc);
    ppb_result r;
    if (ppb_result_init(&r, "mc", &lo, err))
        return -1;
    ppb_mc_tallies_to_results(tmp, sc, &r, NULL);
    /* The Table 2 cells (reference: Metrics); no signal yet counts as not reached. */
    ppb_point pr[2], pt[2];
    double nr = ppb_noise_points(&r, pr, ppb_cell_points(&lo, PPB_CELL_R_X0, pr, 2));
    double nt = ppb_noise_points(&r, pt, ppb_cell_points(&lo, PPB_CELL_T_X0, pt, 2));
    *noise = (isnan(nr) || isnan(nt)) ? INFINITY : (nr > nt ? nr : nt);
    ppb_result_free(&r);
    return 0;
}

/* Whether the first done photons already meet cfg->mc.target_noise (every channel). */
static int noise_reached(mc_run *r, long long done, int *reached, ppb_err *err)
{
    if (read_tallies(r, done, err))
        return -1;
    *reached = 1;
    for (int c = 0; c < r->nch; c++) {
        double noise;
        if (noise_now(r->cfg, &r->t[c], &r->tmp[c], &noise, err))
            return -1;
        *reached = *reached && noise < r->cfg->mc.target_noise;
    }
    return 0;
}

/* Global size: batches x P work-items, P a multiple of the work-group size, so each work-group
 * stays inside one batch (see the kernel); about 64 photons per lane, as in auto_chunk. */
static size_t global_size(const mc_run *r, long long n)
{
    size_t nb = (size_t)r->t->batches;
    long long want = n / (r->shape->lanes * 64) + 1;
    size_t items = (size_t)(want < r->shape->items ? want : r->shape->items);
    size_t per_batch = (items + nb - 1) / nb;
    per_batch = (per_batch + r->local - 1) / r->local * r->local;
    return per_batch * nb;
}

/* Traces photons [first, first + n) and waits for them, so that progress, SIGINT and the noise
 * check between launches always see whole chunks. */
static int launch_chunk(mc_run *r, long long first, long long n, ppb_err *err)
{
    r->p.first = (ppb_u64)first;
    r->p.count = (ppb_u64)n;
    size_t global = global_size(r, n);
    cl_kernel k = r->d->kernel;
    cl_command_queue q = r->ocl->queue;
    if (ppb_cl_check(clSetKernelArg(k, PPB_MC_ARG_PARAMS, sizeof r->p, &r->p),
                     "clSetKernelArg(mc params)", err) ||
        ppb_cl_check(clEnqueueNDRangeKernel(q, k, 1, NULL, &global, &r->local, 0, NULL, NULL),
                     "clEnqueueNDRangeKernel(ppb_mc_trace_kernel)", err) ||
        ppb_cl_check(clFinish(q), "clFinish(mc)", err))
        return -1;
    return 0;
}

/* Launches chunk after chunk until count photons are traced, SIGINT/SIGTERM arrives or the
 * target noise is met. Stops fall only between chunks, so *done always counts a whole prefix
 * of the range. The last chunk skips the noise check: nothing would be left to save. */
static int trace_chunks(mc_run *r, long long count, ppb_progress *pr, long long *done,
                        ppb_mc_trace_info *info, ppb_err *err)
{
    while (*done < count) {
        if (ppb_interrupted()) {
            info->interrupted = 1;
            return 0;
        }
        long long n = count - *done < r->chunk ? count - *done : r->chunk;
        if (launch_chunk(r, r->first + *done, n, err))
            return -1;
        *done += n;
        ppb_progress_update(pr, (double)*done);
        int reached = 0;
        if (r->cfg->mc.target_noise > 0 && *done < count && noise_reached(r, *done, &reached, err))
            return -1;
        if (reached) {
            info->reached_noise = 1;
            return 0;
        }
    }
    return 0;
}

/* The trace proper, timed for info->seconds and shown as progress; the setup and the final
 * read stay outside the clock, so perf measures the launches alone. */
static int trace_timed(mc_run *r, int quiet, long long count, long long *done,
                       ppb_mc_trace_info *info, ppb_err *err)
{
    ppb_progress pr;
    ppb_progress_begin(&pr, "mc", "photons", (double)count, quiet);
    double t0 = ppb_now();
    int status = trace_chunks(r, count, &pr, done, info, err);
    info->seconds = ppb_now() - t0;
    ppb_progress_end(&pr, (double)*done);
    return status;
}

/* The device's tallies reach t in one addition at the end, so a trace that fails on the way
 * leaves t as it was. */
static int trace_on_device(ppb_run_ctx *ctx, ppb_ocl *ocl, const mc_shape *shape, mc_device *d,
                           long long first, long long count, ppb_mc_tallies *t, int nch,
                           ppb_mc_trace_info *info, ppb_err *err)
{
    mc_run r = {
        .cfg = ctx->cfg, .ocl = ocl, .shape = shape, .d = d, .first = first, .t = t, .nch = nch};
    long long done = 0;
    int status = prepare_run(&r, err);
    if (status == 0)
        status = trace_timed(&r, ctx->quiet, count, &done, info, err);
    if (status == 0) {
        info->traced = done;
        status = read_tallies(&r, done, err);
        /* every channel's tallies are added only once all are read: t changes whole or not */
        for (int c = 0; c < nch && status == 0; c++)
            status = ppb_mc_tallies_add(&t[c], &r.tmp[c], err);
    }
    for (int c = 0; c < nch; c++)
        ppb_mc_tallies_free(&r.tmp[c]);
    return status;
}

/* ppb_mc_trace and ppb_mc_trace_channels: the one kernel (mc.cl, ch NULL) or the other
 * (mc_rgb.cl with ch as its extra argument). */
static int trace_kernel(ppb_run_ctx *ctx, const ppb_mc_rgb_params *ch, long long first,
                        long long count, ppb_mc_tallies *t, ppb_mc_trace_info *info, ppb_err *err)
{
    int nch = ch ? ch->nch : 1;
    ppb_mc_trace_info local_info;
    if (!info)
        info = &local_info;
    memset(info, 0, sizeof *info);
    if (nch < 1 || nch > PPB_MC_MAX_CH)
        return ppb_fail(err, "mc: %d channels (1 to %d)", nch, PPB_MC_MAX_CH);
    if (check_settings(ctx->cfg, first, count, t, nch, err))
        return -1;
    ppb_ocl *ocl;
    if (ppb_ctx_ocl(ctx, &ocl, err))
        return -1;
    int has64 = 0, hasfp64 = 0;
    if (device_has(ocl->device, "cl_khr_int64_base_atomics", err, &has64) ||
        device_has(ocl->device, "cl_khr_fp64", err, &hasfp64))
        return -1;
    if (!has64 || !hasfp64)
        return ppb_fail(err, "mc: device %s lacks %s, needed for the bit-reproducible tallies",
                        ocl->name, !has64 ? "cl_khr_int64_base_atomics" : "cl_khr_fp64");
    mc_shape shape;
    if (device_shape(ocl, &shape, err))
        return -1;
    char opts[96];
    int n = snprintf(opts, sizeof opts, "-D PPB_MC_LANES=%d -D PPB_MC_CPU_PREFETCH=%d", shape.lanes,
                     shape.cpu);
    if (ch)
        snprintf(opts + n, sizeof opts - (size_t)n, " -D PPB_MC_NCH=%d", nch);
    mc_device d = {0};
    int status = ppb_ocl_build(ocl, ch ? PPB_MC_RGB_KERNEL : PPB_MC_KERNEL, opts, &d.prog, err);
    if (status == 0)
        status = ppb_ocl_kernel(d.prog, ch ? "ppb_mc_rgb_kernel" : "ppb_mc_trace_kernel", &d.kernel,
                                err);
    if (status == 0 && ch)
        status = ppb_cl_check(clSetKernelArg(d.kernel, PPB_MC_RGB_ARG_CHANNELS, sizeof *ch, ch),
                              "clSetKernelArg(mc channels)", err);
    if (status == 0)
        status = trace_on_device(ctx, ocl, &shape, &d, first, count, t, nch, info, err);
    mc_device_release(&d);
    return status;
}

int ppb_mc_trace(ppb_run_ctx *ctx, long long first, long long count, ppb_mc_tallies *t,
                 ppb_mc_trace_info *info, ppb_err *err)
{
    return trace_kernel(ctx, NULL, first, count, t, info, err);
}

int ppb_mc_trace_channels(ppb_run_ctx *ctx, const ppb_mc_rgb_params *ch, long long first,
                          long long count, ppb_mc_tallies *t, ppb_mc_trace_info *info, ppb_err *err)
{
    return trace_kernel(ctx, ch, first, count, t, info, err);
}

/* The tallies live three times (host, its copy read back for noise checks, the device
 * buffer), each batches x 2 tallies x cells of 8 bytes per channel; checked before any work. */
static int check_memory(const ppb_config *cfg, int nch, ppb_err *err)
{
    double tally = (double)nch * cfg->mc.batches * PPB_MC_NTALLY *
                   (double)ppb_scene_layout(&cfg->scene).ncells * sizeof(uint64_t);
    char detail[128];
    if (nch > 1)
        snprintf(detail, sizeof detail, "tallies of %d channels x %d batches, %.3g GB x 3", nch,
                 cfg->mc.batches, tally / 1e9);
    else
        snprintf(detail, sizeof detail, "tallies of %d batches, %.3g GB x 3", cfg->mc.batches,
                 tally / 1e9);
    return ppb_memory_check(3.0 * tally, cfg->memory_limit, "mc", detail, err);
}

/* Said, not hidden: interactions past the event cap were rouletted (mc_params.h). */
static void note_capped(const ppb_config *cfg, const ppb_mc_tallies *t)
{
    uint64_t capped = 0;
    for (int b = 0; b < t->batches; b++)
        capped += t->totals[(size_t)b * PPB_MC_NTOT + PPB_MC_T_CAPPED];
    if (capped)
        fprintf(stderr,
                "%s: mc: note: %llu interactions past the event cap of %d scatterings per "
                "photon were Russian-rouletted (unbiased; it bounds the work per photon)\n",
                cfg->name, (unsigned long long)capped, PPB_MC_EVENT_CAP);
}

/* study-score's switch (docs/reference.md, Keys: shipped references): 1 when no reference may
 * be traced unasked. */
static int no_trace(void)
{
    const char *v = getenv("PPBENCH_MC_NO_TRACE");
    return v && strcmp(v, "1") == 0;
}

int ppb_method_mc(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    ppb_mc_tallies t;
    if (check_memory(cfg, 1, err))
        return -1;
    ppb_mc_trace_info info = {0};
    int status = 0;
    /* The cache's key holds the photons per launch under a target noise (mc_cache.h). */
    long long chunk = 0;
    if (ctx->ref_cache && cfg->mc.target_noise > 0 && ppb_mc_chunk(ctx, &chunk, err))
        return -1;
    ctx->mc_reference[0] = '\0';
    ppb_mc_cache_note_key(ctx, chunk);
    if (ctx->ref_cache && ppb_mc_cache_get(ctx, chunk, &t)) {
        /* The same reference was traced before (docs/external.md): no photon is traced now. */
        if (ctx->quiet < 2)
            fprintf(stderr, "%s: mc: %llu photons from the %s %s, 0 traced\n", cfg->name,
                    (unsigned long long)t.count,
                    ctx->mc_reference_shipped ? "shipped reference" : "reference cache",
                    ctx->mc_reference_shipped ? ctx->mc_reference : ctx->ref_cache);
    } else if (no_trace()) {
        /* study-score: a reference neither cached nor shipped is not traced unasked
         * (docs/reference.md, Keys: shipped references). */
        return ppb_fail(err,
                        "mc: no reference for this config in the cache (%s) nor the shipped "
                        "layer (%s), and PPBENCH_MC_NO_TRACE=1: nothing traced (set "
                        "PPBENCH_MC_NO_TRACE=0 to trace it)",
                        ctx->ref_cache ? ctx->ref_cache : "none", ppb_mc_shipped_dir());
    } else {
        if (ppb_mc_tallies_init(&t, &cfg->scene, (uint64_t)cfg->mc.seed, cfg->mc.batches, err))
            return -1;
        status = ppb_mc_trace(ctx, cfg->mc.first, cfg->mc.photons, &t, &info, err);
        if (status == 0 && !info.interrupted && ctx->ref_cache)
            ppb_mc_cache_put(ctx, chunk, &t, info.traced);
    }
    if (status == 0) {
        note_capped(cfg, &t);
        ppb_mc_tallies_to_results(&t, &cfg->scene, &out[0], &out[1]);
        status = ppb_mc_tallies_attach_totals(&t, &cfg->scene, &out[0], err);
        for (int i = 0; i < 2; i++) {
            out[i].partial = info.interrupted;
            out[i].photons = info.traced;
        }
    }
    ppb_mc_tallies_free(&t);
    return status;
}

/* Whether a and b trace the same photons (everything of [mc] but nothing else). */
static int same_mc_settings(const ppb_mc_settings *a, const ppb_mc_settings *b)
{
    return a->photons == b->photons && a->batches == b->batches && a->seed == b->seed &&
           a->workgroup == b->workgroup && a->chunk == b->chunk && a->first == b->first &&
           a->target_noise == b->target_noise;
}

int ppb_mc_rgb_params_of(const ppb_config *cfgs, int nch, ppb_mc_rgb_params *ch, ppb_err *err)
{
    if (nch < 1 || nch > PPB_MC_MAX_CH)
        return ppb_fail(err, "mc: %d channels in one run (1 to %d)", nch, PPB_MC_MAX_CH);
    memset(ch, 0, sizeof *ch);
    ch->nch = nch;
    ch->same_g = 1;
    const ppb_scene *s0 = &cfgs[0].scene;
    uint64_t fp0 = ppb_mc_scene_fingerprint(s0);
    for (int c = 0; c < nch; c++) {
        const ppb_scene *sc = &cfgs[c].scene;
        /* Channel c's scene with channel 0's coefficients must be channel 0's scene. */
        ppb_scene same = *sc;
        same.sigma_t = s0->sigma_t, same.sigma_t_right = s0->sigma_t_right;
        same.albedo = s0->albedo, same.albedo_right = s0->albedo_right, same.g = s0->g;
        if (ppb_mc_scene_fingerprint(&same) != fp0)
            return ppb_fail(err,
                            "mc: channel %d's experiment differs from channel 0's beyond the "
                            "medium's sigma_t, albedo and g (geometry, step, n, light or bins): "
                            "one path per photon serves every channel only in the same tube",
                            c);
        if (!same_mc_settings(&cfgs[c].mc, &cfgs[0].mc))
            return ppb_fail(err,
                            "mc: channel %d's [mc] settings differ from channel 0's: the "
                            "channels are traced by the same photons",
                            c);
        if (sc->sigma_t <= 0 || (sc->step == PPB_STEP_DENSITY && sc->sigma_t_right <= 0))
            return ppb_fail(err, "mc: channel %d: sigma_t must be positive", c);
        /* The float values mc.cl reads (its medium[] array), and the logarithm of the float
         * sigma_t for the density ratio sigma_k / sigma_h (mc_rgb.cl). */
        ppb_medium M = ppb_medium_of(sc);
        for (int side = 0; side < 2; side++) {
            double x = side ? M.step_x : M.step_x - 1.0;
            ch->sigma_t[c][side] = (float)ppb_medium_sigma_t(&M, x);
            ch->log_sigma_t[c][side] = (float)log((double)ch->sigma_t[c][side]);
            ch->albedo[c][side] = (float)ppb_medium_albedo(&M, x);
        }
        ch->g[c] = (float)sc->g;
        double g = fabs(ch->g[c]) < 1e-4f ? 0.0 : (double)ch->g[c]; /* as the sampler uses it */
        ch->log_1mg2[c] = (float)log(1.0 - g * g);
        ch->same_g = ch->same_g && ch->g[c] == ch->g[0];
    }
    return 0;
}

/* Every channel's single-channel reference from the cache or the shipped layer (mc_cache.h),
 * into t: 1 when all nch are there (ctx->mc_reference then names the last), else 0 with t
 * freed. */
static int cached_channels(ppb_run_ctx *ctx, const ppb_config *cfgs, int nch, ppb_mc_tallies *t,
                           ppb_err *err)
{
    if (!ctx->ref_cache)
        return 0;
    const ppb_config *own = ctx->cfg;
    int found = 0;
    for (; found < nch; found++) {
        long long chunk = 0;
        ctx->cfg = &cfgs[found];
        if (cfgs[found].mc.target_noise > 0 && ppb_mc_chunk(ctx, &chunk, err))
            break;
        if (!ppb_mc_cache_get(ctx, chunk, &t[found]))
            break;
        ppb_mc_cache_note_key(ctx, chunk);
        snprintf(ctx->mc_channel_reference[found], sizeof ctx->mc_channel_reference[found], "%s",
                 ctx->mc_reference);
        snprintf(ctx->mc_channel_shipped_key[found], sizeof ctx->mc_channel_shipped_key[found],
                 "%s", ctx->mc_shipped_key);
    }
    ctx->cfg = own;
    if (found == nch)
        return 1;
    for (int c = 0; c < found; c++)
        ppb_mc_tallies_free(&t[c]);
    for (int c = 0; c < 3; c++)
        ctx->mc_channel_reference[c][0] = ctx->mc_channel_shipped_key[c][0] = '\0';
    ctx->mc_reference[0] = '\0';
    ctx->mc_reference_shipped = 0;
    return 0;
}

int ppb_mc_run_channels(ppb_run_ctx *ctx, const ppb_config *cfgs, int nch, ppb_result *out,
                        ppb_err *err)
{
    ppb_mc_rgb_params ch;
    if (ppb_mc_rgb_params_of(cfgs, nch, &ch, err) || check_memory(&cfgs[0], nch, err))
        return -1;
    ctx->mc_reference[0] = '\0';
    ctx->mc_shipped_key[0] = '\0';
    ctx->mc_reference_shipped = 0;
    for (int c = 0; c < 3; c++)
        ctx->mc_channel_reference[c][0] = ctx->mc_channel_shipped_key[c][0] = '\0';
    ppb_mc_tallies t[PPB_MC_MAX_CH];
    memset(t, 0, sizeof t);
    ppb_mc_trace_info info = {0};
    int status = 0;
    if (cached_channels(ctx, cfgs, nch, t, err)) {
        /* Each channel's own reference was traced before: those, not a new trace. */
        if (ctx->quiet < 2)
            fprintf(stderr, "%s: mc: %d channels' references from the %s, 0 traced\n", cfgs[0].name,
                    nch, ctx->mc_reference_shipped ? "shipped references" : "reference cache");
    } else if (no_trace()) {
        return ppb_fail(err,
                        "mc: no reference for every channel in the cache (%s) nor the "
                        "shipped layer (%s), and PPBENCH_MC_NO_TRACE=1: nothing traced "
                        "(set PPBENCH_MC_NO_TRACE=0 to trace it)",
                        ctx->ref_cache ? ctx->ref_cache : "none", ppb_mc_shipped_dir());
    } else {
        /* Traced by hero sampling, and not stored (docs/methods.md says why). */
        for (int c = 0; c < nch && status == 0; c++)
            status = ppb_mc_tallies_init(&t[c], &cfgs[c].scene, (uint64_t)cfgs[c].mc.seed,
                                         cfgs[c].mc.batches, err);
        const ppb_config *own = ctx->cfg;
        ctx->cfg = &cfgs[0]; /* the trace's scene and settings; the media come from ch */
        if (status == 0)
            status = ppb_mc_trace_channels(ctx, &ch, cfgs[0].mc.first, cfgs[0].mc.photons, t, &info,
                                           err);
        ctx->cfg = own;
    }
    for (int c = 0; c < nch && status == 0; c++) {
        note_capped(&cfgs[c], &t[c]);
        ppb_mc_tallies_to_results(&t[c], &cfgs[c].scene, &out[2 * c], &out[2 * c + 1]);
        status = ppb_mc_tallies_attach_totals(&t[c], &cfgs[c].scene, &out[2 * c], err);
        for (int i = 2 * c; i < 2 * c + 2; i++) {
            out[i].partial = info.interrupted;
            out[i].photons = info.traced;
        }
    }
    for (int c = 0; c < nch; c++)
        ppb_mc_tallies_free(&t[c]);
    return status;
}

/* Expected scattering events per Monte Carlo photon: with implicit capture a photon's weight
 * after k events is albedo^k, rouletted below PPB_MC_ROULETTE_W, so about
 * ln(w) / ln(albedo) events; a walk leaves a medium of optical size L (the tube's smaller side,
 * the slab's thickness) after about 1 + L + L^2 events (diffusion); capped at PPB_MC_EVENT_CAP
 * (mc_params.h). The least of the three. */
double ppb_mc_events_per_photon(const ppb_config *cfg)
{
    const ppb_scene *sc = &cfg->scene;
    double a = sc->albedo;
    if (sc->step == PPB_STEP_ALBEDO && sc->albedo_right > a)
        a = sc->albedo_right;
    double by_weight = a <= 0.0 ? 1.0 : a >= 1.0 ? INFINITY : 1.0 + log(PPB_MC_ROULETTE_W) / log(a);
    double size = sc->geometry == PPB_GEOM_SLAB ? sc->height : fmin(sc->width, sc->height);
    double L = size * fmax(sc->sigma_t, sc->step == PPB_STEP_DENSITY ? sc->sigma_t_right : 0.0);
    double by_size = 1.0 + L + L * L;
    return fmin(fmin(by_weight, by_size), (double)PPB_MC_EVENT_CAP);
}

void ppb_mc_work(const ppb_config *cfg, const char *id, FILE *f)
{
    double e = ppb_mc_events_per_photon(cfg);
    fprintf(f, "%s: %s: work: %lld photons x about %.3g events = %.3g events\n", cfg->name, id,
            cfg->mc.photons, e, (double)cfg->mc.photons * e);
}
