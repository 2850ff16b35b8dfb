#include "method_mc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "progress.h"

/* Host and kernel must agree on the parameter block passed by value (kernels/mc_params.h). */
_Static_assert(sizeof(ppb_mc_params) == 136, "ppb_mc_params layout changed: check mc.cl");

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
    ppb_mc_params p = {
        .seed = (ppb_u64)cfg->mc.seed,
        .ncells = (ppb_u64)lo.ncells,
        .batches = cfg->mc.batches,
        .tube = sc->geometry == PPB_GEOM_TUBE,
        .step = sc->step,
        .ntheta = sc->ntheta,
        .nphi = sc->nphi,
        .width = (float)sc->width,
        .height = (float)sc->height,
        .sigma_t = (float)sc->sigma_t,
        .sigma_t_right = (float)sc->sigma_t_right,
        .albedo = (float)sc->albedo,
        .albedo_right = (float)sc->albedo_right,
        .step_x = (float)sc->step_x,
        .g = (float)sc->g,
        .light_x = (float)wl[0],
        .light_y = (float)wl[1],
        .enter_x0 = (float)(-0.5 * sc->width),
        .enter_width = (float)ppb_scene_lit_width(sc),
    };
    for (int s = 0; s < PPB_NSURF; s++) {
        p.nseg[s] = lo.nseg[s];
        p.offset[s] = lo.offset[s];
    }
    return p;
}

static int check_settings(const ppb_config *cfg, long long first, long long count,
                          const ppb_mc_tallies *t, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    if (first < 0 || count < 0)
        return ppb_fail(err, "mc: photon range [%lld, +%lld) is negative", first, count);
    if (cfg->mc.batches != t->batches || (uint64_t)cfg->mc.seed != t->seed ||
        ppb_mc_scene_fingerprint(sc) != t->fingerprint)
        return ppb_fail(err, "mc: tallies were made for another scene, seed or batch count");
    if (sc->geometry == PPB_GEOM_SLAB && sc->step != PPB_STEP_NONE)
        return ppb_fail(err, "mc: steps are not defined in slab mode (SPEC.md section 2)");
    if (sc->theta_deg < 0 || sc->theta_deg >= 90)
        return ppb_fail(err, "mc: theta_deg must lie in [0, 90) (got %g)", sc->theta_deg);
    if (sc->sigma_t <= 0 || (sc->step == PPB_STEP_DENSITY && sc->sigma_t_right <= 0))
        return ppb_fail(err, "mc: sigma_t must be positive");
    /* Fixed-point headroom (kernels/mc_params.h): fewer than 2^31 photons per batch. */
    uint64_t per_batch = (uint64_t)count / (uint64_t)t->batches + 1;
    for (int b = 0; b < t->batches; b++)
        if (t->photons[b] + per_batch >= ((uint64_t)1 << 31))
            return ppb_fail(err, "mc: more than 2^31 photons per batch would overflow the "
                                 "fixed-point tallies; raise [mc] batches");
    return 0;
}

/* Reads the device tallies into tmp (zeroed arrays of t's shape). */
static int read_tallies(ppb_ocl *ocl, const mc_device *d, ppb_mc_tallies *tmp, ppb_err *err)
{
    size_t nb = (size_t)tmp->batches;
    size_t cell_bytes = nb * PPB_MC_NTALLY * tmp->ncells * sizeof(uint64_t);
    size_t tot_bytes = nb * PPB_MC_NTOT * sizeof(uint64_t);
    if (ppb_cl_check(clEnqueueReadBuffer(ocl->queue, d->cells, CL_TRUE, 0, cell_bytes, tmp->cells,
                                         0, NULL, NULL),
                     "clEnqueueReadBuffer(mc cells)", err) ||
        ppb_cl_check(clEnqueueReadBuffer(ocl->queue, d->totals, CL_TRUE, 0, tot_bytes, tmp->totals,
                                         0, NULL, NULL),
                     "clEnqueueReadBuffer(mc totals)", err))
        return -1;
    return 0;
}

/* noise_rel at the x = 0 cells of S1 and S2 (SPEC.md 5, Table 2 cells), the larger of the two,
 * for the tallies so far (t plus the device's). */
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
    int segs[2];
    ppb_mc_x0_segments(sc, segs);
    double nr = ppb_mc_noise_rel(&r, PPB_S1, segs, 2);
    double nt = ppb_mc_noise_rel(&r, PPB_S2, segs, 2);
    *noise = nr > nt ? nr : nt;
    ppb_result_free(&r);
    return 0;
}

/* How the kernel is laid out on a device: photons side by side per work-item (SIMD lanes on a
 * CPU, where nothing vectorises across work-items; 2 on a GPU, whose SIMD is the work-items)
 * and work-items per launch (enough to fill a GPU's compute units, 2048 resident threads each,
 * or to balance a CPU's cores). None of it changes a photon's path. */
typedef struct mc_shape {
    int lanes;
    long long items;
} mc_shape;

static int device_shape(const ppb_ocl *ocl, mc_shape *shape, ppb_err *err)
{
    cl_device_type type = 0;
    if (ppb_cl_check(clGetDeviceInfo(ocl->device, CL_DEVICE_TYPE, sizeof type, &type, NULL),
                     "clGetDeviceInfo(CL_DEVICE_TYPE)", err))
        return -1;
    long long units = ocl->compute_units ? (long long)ocl->compute_units : 1;
    int cpu = (type & CL_DEVICE_TYPE_CPU) != 0;
    shape->lanes = cpu ? 8 : 2;
    shape->items = units * (cpu ? 1024 : 2048);
    return 0;
}

/* Photons per launch: 64 per lane keeps the lanes busy to the end and the launch overhead
 * below a percent. Fixed by the device, never by timing, so a target-noise run stops at the
 * same photon count every time on the same device. */
static long long auto_chunk(const mc_shape *shape)
{
    return shape->items * shape->lanes * 64;
}

static int trace_on_device(ppb_run_ctx *ctx, ppb_ocl *ocl, const mc_shape *shape, mc_device *d,
                           long long first, long long count, ppb_mc_tallies *t,
                           ppb_mc_trace_info *info, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    size_t nb = (size_t)t->batches;
    size_t cell_bytes = nb * PPB_MC_NTALLY * t->ncells * sizeof(uint64_t);
    size_t tot_bytes = nb * PPB_MC_NTOT * sizeof(uint64_t);
    cl_int rc;
    d->cells = clCreateBuffer(ocl->context, CL_MEM_READ_WRITE, cell_bytes, NULL, &rc);
    if (ppb_cl_check(rc, "clCreateBuffer(mc cells)", err))
        return -1;
    d->totals = clCreateBuffer(ocl->context, CL_MEM_READ_WRITE, tot_bytes, NULL, &rc);
    if (ppb_cl_check(rc, "clCreateBuffer(mc totals)", err))
        return -1;
    const cl_ulong zero = 0;
    if (ppb_cl_check(clEnqueueFillBuffer(ocl->queue, d->cells, &zero, sizeof zero, 0, cell_bytes, 0,
                                         NULL, NULL),
                     "clEnqueueFillBuffer(mc cells)", err) ||
        ppb_cl_check(clEnqueueFillBuffer(ocl->queue, d->totals, &zero, sizeof zero, 0, tot_bytes, 0,
                                         NULL, NULL),
                     "clEnqueueFillBuffer(mc totals)", err))
        return -1;
    if (ppb_cl_check(clSetKernelArg(d->kernel, PPB_MC_ARG_CELLS, sizeof d->cells, &d->cells),
                     "clSetKernelArg(mc cells)", err) ||
        ppb_cl_check(clSetKernelArg(d->kernel, PPB_MC_ARG_TOTALS, sizeof d->totals, &d->totals),
                     "clSetKernelArg(mc totals)", err))
        return -1;

    /* Work-group size 0 means ppbench picks: 64 work-items keep a group inside one batch and
     * give PoCL's CPU driver enough groups to balance its cores (its own choice is slower),
     * and suit GPUs too. */
    size_t local = cfg->mc.workgroup > 0 ? (size_t)cfg->mc.workgroup : 64;
    if (!cfg->mc.workgroup && local > ocl->max_workgroup)
        local = ocl->max_workgroup;
    if (local > ocl->max_workgroup)
        return ppb_fail(err, "mc: workgroup %zu exceeds the device's maximum %zu", local,
                        ocl->max_workgroup);
    long long chunk = cfg->mc.chunk > 0 ? cfg->mc.chunk : auto_chunk(shape);

    ppb_mc_tallies tmp = {0};
    tmp.fingerprint = t->fingerprint, tmp.seed = t->seed, tmp.batches = t->batches;
    tmp.ncells = t->ncells;
    tmp.photons = calloc(nb, sizeof *tmp.photons);
    tmp.cells = malloc(cell_bytes);
    tmp.totals = malloc(tot_bytes);
    if (!tmp.photons || !tmp.cells || !tmp.totals) {
        ppb_mc_tallies_free(&tmp);
        return ppb_fail(err, "mc: out of memory for tallies");
    }

    ppb_mc_params p = make_params(cfg);
    ppb_progress pr;
    ppb_progress_begin(&pr, "mc", "photons", (double)count, ctx->quiet);
    double t0 = ppb_now();
    long long done = 0;
    int status = 0;
    while (done < count) {
        if (ppb_interrupted()) {
            info->interrupted = 1;
            break;
        }
        long long n = count - done < chunk ? count - done : chunk;
        p.first = (ppb_u64)(first + done);
        p.count = (ppb_u64)n;
        /* Global size: batches x P work-items, P a multiple of the work-group size, so each
         * work-group stays inside one batch (see the kernel). */
        size_t nb_sz = (size_t)t->batches;
        long long want = n / (shape->lanes * 64) + 1; /* about 64 photons per lane */
        size_t items = (size_t)(want < shape->items ? want : shape->items);
        size_t per_batch = (items + nb_sz - 1) / nb_sz;
        per_batch = (per_batch + local - 1) / local * local;
        size_t global = per_batch * nb_sz;
        if (ppb_cl_check(clSetKernelArg(d->kernel, PPB_MC_ARG_PARAMS, sizeof p, &p),
                         "clSetKernelArg(mc params)", err) ||
            ppb_cl_check(clEnqueueNDRangeKernel(ocl->queue, d->kernel, 1, NULL, &global, &local, 0,
                                                NULL, NULL),
                         "clEnqueueNDRangeKernel(ppb_mc_trace_kernel)", err) ||
            ppb_cl_check(clFinish(ocl->queue), "clFinish(mc)", err)) {
            status = -1;
            break;
        }
        done += n;
        ppb_progress_update(&pr, (double)done);
        if (cfg->mc.target_noise > 0 && done < count) {
            double noise;
            memset(tmp.photons, 0, nb * sizeof *tmp.photons);
            ppb_mc_tallies_count_range(&tmp, (uint64_t)first, (uint64_t)done);
            if (read_tallies(ocl, d, &tmp, err) || noise_now(cfg, t, &tmp, &noise, err)) {
                status = -1;
                break;
            }
            if (noise < cfg->mc.target_noise) {
                info->reached_noise = 1;
                break;
            }
        }
    }
    info->seconds = ppb_now() - t0;
    ppb_progress_end(&pr, (double)done);
    if (status == 0) {
        memset(tmp.photons, 0, nb * sizeof *tmp.photons);
        ppb_mc_tallies_count_range(&tmp, (uint64_t)first, (uint64_t)done);
        status = read_tallies(ocl, d, &tmp, err);
        if (status == 0)
            status = ppb_mc_tallies_add(t, &tmp, err);
        info->traced = done;
    }
    ppb_mc_tallies_free(&tmp);
    return status;
}

int ppb_mc_trace(ppb_run_ctx *ctx, long long first, long long count, ppb_mc_tallies *t,
                 ppb_mc_trace_info *info, ppb_err *err)
{
    ppb_mc_trace_info local_info;
    if (!info)
        info = &local_info;
    memset(info, 0, sizeof *info);
    if (check_settings(ctx->cfg, first, count, t, err))
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
    char opts[64];
    snprintf(opts, sizeof opts, "-D PPB_MC_LANES=%d", shape.lanes);
    mc_device d = {0};
    int status = ppb_ocl_build(ocl, "mc.cl", opts, &d.prog, err);
    if (status == 0)
        status = ppb_ocl_kernel(d.prog, "ppb_mc_trace_kernel", &d.kernel, err);
    if (status == 0)
        status = trace_on_device(ctx, ocl, &shape, &d, first, count, t, info, err);
    mc_device_release(&d);
    return status;
}

int ppb_method_mc(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    ppb_mc_tallies t;
    if (ppb_mc_tallies_init(&t, &cfg->scene, (uint64_t)cfg->mc.seed, cfg->mc.batches, err))
        return -1;
    ppb_mc_trace_info info;
    int status = ppb_mc_trace(ctx, cfg->mc.first, cfg->mc.photons, &t, &info, err);
    if (status == 0) {
        ppb_mc_tallies_to_results(&t, &cfg->scene, &out[0], &out[1]);
        for (int i = 0; i < 2; i++) {
            out[i].partial = info.interrupted;
            out[i].photons = info.traced;
        }
    }
    ppb_mc_tallies_free(&t);
    return status;
}
