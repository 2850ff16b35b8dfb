#include "methods/mc3d/method_mc3d.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/clock.h"
#include "base/memory.h"
#include "base/progress.h"
#include "kernels/ppb_object.h"
#include "methods/mc3d/mc3d_params.h"
#include "methods/registry.h"

/* Host and kernel agree on the parameter block passed by value (mc3d_params.h). */
_Static_assert(sizeof(ppb_mc3d_params) == 5 * 8 + 26 * 8 + 8 * 4,
               "ppb_mc3d_params layout changed: check mc3d.cl");

/* mc3d takes the Monte Carlo's settings section, the tube reference's ([mc]: photons,
 * batches, seed, workgroup, chunk, first). */
static const char *mc_section(void)
{
    return ppb_method_reference()->section;
}

typedef struct mc3d_dev {
    cl_program prog;
    cl_kernel k;
    cl_mem buf[6]; /* sigma, albedo, faces, cells, pixels, totals */
} mc3d_dev;

static void dev_release(mc3d_dev *d)
{
    for (int i = 0; i < 6; i++)
        if (d->buf[i])
            clReleaseMemObject(d->buf[i]);
    if (d->k)
        clReleaseKernel(d->k);
    if (d->prog)
        clReleaseProgram(d->prog);
    memset(d, 0, sizeof *d);
}

/* The entry plane: e1, e2 span the grid box's projection across the light, org upstream of the
 * box by one voxel (docs/methods.md, mc3d). Returns the projection's area. */
static double entry_plane(const ppb_object *o, ppb_mc3d_params *p)
{
    const double *L = o->light_dir;
    int a = fabs(L[0]) <= fabs(L[1]) && fabs(L[0]) <= fabs(L[2]) ? 0
            : fabs(L[1]) <= fabs(L[2])                           ? 1
                                                                 : 2;
    double ea[3] = {0, 0, 0}, e1[3], e2[3];
    ea[a] = 1;
    e1[0] = L[1] * ea[2] - L[2] * ea[1], e1[1] = L[2] * ea[0] - L[0] * ea[2];
    e1[2] = L[0] * ea[1] - L[1] * ea[0];
    double l = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int k = 0; k < 3; k++)
        e1[k] /= l;
    e2[0] = L[1] * e1[2] - L[2] * e1[1], e2[1] = L[2] * e1[0] - L[0] * e1[2];
    e2[2] = L[0] * e1[1] - L[1] * e1[0];
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    double ext[3] = {o->nx * o->voxel, o->ny * o->voxel, o->nz * o->voxel};
    for (int c = 0; c < 8; c++) {
        double q[3] = {(c & 1) ? ext[0] : 0, (c & 2) ? ext[1] : 0, (c & 4) ? ext[2] : 0};
        double s[3] = {q[0] * e1[0] + q[1] * e1[1] + q[2] * e1[2],
                       q[0] * e2[0] + q[1] * e2[1] + q[2] * e2[2],
                       q[0] * L[0] + q[1] * L[1] + q[2] * L[2]};
        for (int k = 0; k < 3; k++)
            lo[k] = fmin(lo[k], s[k]), hi[k] = fmax(hi[k], s[k]);
    }
    for (int k = 0; k < 3; k++) {
        p->org[k] = lo[0] * e1[k] + lo[1] * e2[k] + (lo[2] - o->voxel) * L[k];
        p->e1[k] = (hi[0] - lo[0]) * e1[k];
        p->e2[k] = (hi[1] - lo[1]) * e2[k];
        p->light[k] = L[k];
    }
    return (hi[0] - lo[0]) * (hi[1] - lo[1]);
}

static int mk_buf(ppb_ocl *ocl, cl_mem_flags fl, size_t bytes, void *host, cl_mem *m,
                  const char *what, ppb_err *err)
{
    cl_int rc;
    *m = clCreateBuffer(ocl->context, fl | (host ? CL_MEM_COPY_HOST_PTR : 0), bytes ? bytes : 8,
                        host, &rc);
    char w[96];
    snprintf(w, sizeof w, "clCreateBuffer(mc3d %s)", what);
    if (ppb_cl_check(rc, w, err))
        return -1;
    if (!host) {
        unsigned long long zero = 0;
        return ppb_cl_check(clEnqueueFillBuffer(ocl->queue, *m, &zero, sizeof zero, 0,
                                                bytes ? bytes : 8, 0, NULL, NULL),
                            "clEnqueueFillBuffer(mc3d)", err);
    }
    return 0;
}

/* Mean and standard error over the batches of a fixed-point tally whose batch b holds
 * t[b * stride] from n_b photons: per-photon means x_b = t_b / (scale n_b). */
static void batch_stats(const uint64_t *t, size_t stride, const long long *nb, int batches,
                        long long n, double scale, double *mean, double *se)
{
    double sum = 0, s1 = 0, s2 = 0;
    int used = 0;
    for (int b = 0; b < batches; b++)
        sum += (double)t[(size_t)b * stride];
    *mean = n ? sum / scale / (double)n : 0;
    for (int b = 0; b < batches; b++)
        if (nb[b]) {
            double x = (double)t[(size_t)b * stride] / scale / (double)nb[b];
            s1 += x, s2 += x * x, used++;
        }
    if (used > 1) {
        double m = s1 / used, var = (s2 / used - m * m) * used / (used - 1);
        *se = sqrt(fmax(var, 0) / used);
    } else {
        *se = 0;
    }
}

int ppb_mc3d_trace(ppb_run_ctx *ctx, const ppb_object *o, const ppb_object_patches *pt,
                   ppb_object_result *out, ppb_mc3d_totals *tot, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    if (o->n != 1.0)
        return ppb_config_key_fail(cfg, "medium", "n", err,
                                   "mc3d: objects take n = 1 only (the paper's Fig. 9 setting; "
                                   "docs/reference.md, Objects), not %g",
                                   o->n);
    size_t nvox = (size_t)o->nx * (size_t)o->ny * (size_t)o->nz;
    int nbins = o->ntheta * o->nphi, B = cfg->mc.batches;
    size_t ncells = (size_t)pt->npatch * (size_t)nbins, npix = (size_t)o->img_w * o->img_h;
    double bytes =
        (double)nvox * (4 + 4 + 24) + 2.0 * B * PPB_MC3D_NTALLY * (double)(ncells + npix) * 8.0;
    char detail[160];
    snprintf(detail, sizeof detail, "%zu voxels, %d batches of %zu patch cells and %zu pixels",
             nvox, B, ncells, npix);
    if (ppb_memory_check(bytes, cfg->memory_limit, "mc3d", detail, err))
        return -1;
    /* The fixed-point bound of the cells (mc3d_params.h): fewer than 2^31 photons a batch; the
     * pixels' bound is checked on the batches' event counts after the trace. */
    if ((double)cfg->mc.photons / B > 2147483647.0)
        return ppb_config_key_fail(cfg, mc_section(), "photons", err,
                                   "mc3d: %lld photons in %d batches overflow a batch's "
                                   "fixed-point tallies (mc3d_params.h); raise [mc] batches",
                                   cfg->mc.photons, B);
    ppb_mc3d_params P;
    memset(&P, 0, sizeof P);
    P.seed = (ppb_u64)cfg->mc.seed, P.ncells = ncells, P.npix = npix;
    P.h = o->voxel, P.g = o->g;
    double area = entry_plane(o, &P);
    double c[3] = {-o->view_dir[0], -o->view_dir[1], -o->view_dir[2]};
    ppb_obj_camera cam = ppb_obj_camera_make(c, o->nx * o->voxel, o->ny * o->voxel,
                                             o->nz * o->voxel, o->img_w, o->img_h);
    for (int k = 0; k < 3; k++)
        P.cam_c[k] = cam.c[k], P.cam_r[k] = cam.r[k], P.cam_u[k] = cam.u[k];
    P.cam_r0 = cam.r0, P.cam_u1 = cam.u1, P.cam_pixel = cam.pixel;
    P.nx = o->nx, P.ny = o->ny, P.nz = o->nz, P.batches = B;
    P.ntheta = o->ntheta, P.nphi = o->nphi, P.img_w = o->img_w, P.img_h = o->img_h;

    float *sig = malloc(nvox * sizeof *sig), *alb = malloc(nvox * sizeof *alb);
    uint64_t *cells = malloc((size_t)B * PPB_MC3D_NTALLY * (ncells ? ncells : 1) * 8);
    uint64_t *pixels = malloc((size_t)B * PPB_MC3D_NTALLY * (npix ? npix : 1) * 8);
    uint64_t *totals = malloc((size_t)B * PPB_MC3D_NTOT * 8);
    long long *nb = calloc((size_t)B, sizeof *nb);
    mc3d_dev d = {0};
    int status = -1;
    if (!sig || !alb || !cells || !pixels || !totals || !nb) {
        ppb_fail(err, "mc3d: out of memory for %s", detail);
        goto done;
    }
    for (size_t v = 0; v < nvox; v++) {
        int m = o->mat[v];
        sig[v] = m ? (float)o->material[m].sigma_t : 0.0f;
        alb[v] = m ? (o->albedo_tex ? o->albedo_tex[v] : (float)o->material[m].albedo) : 0.0f;
    }
    ppb_ocl *ocl;
    if (ppb_ctx_ocl(ctx, &ocl, err) || ppb_ocl_build(ocl, PPB_MC3D_KERNEL, "", &d.prog, err) ||
        ppb_ocl_kernel(d.prog, "ppb_mc3d_kernel", &d.k, err))
        goto done;
    size_t tb[6] = {nvox * 4,
                    nvox * 4,
                    6 * nvox * sizeof(int),
                    (size_t)B * PPB_MC3D_NTALLY * ncells * 8,
                    (size_t)B * PPB_MC3D_NTALLY * npix * 8,
                    (size_t)B * PPB_MC3D_NTOT * 8};
    void *host[6] = {sig, alb, pt->face_patch, NULL, NULL, NULL};
    const char *names[6] = {"sigma", "albedo", "faces", "cells", "pixels", "totals"};
    for (int i = 0; i < 6; i++)
        if (mk_buf(ocl, i < 3 ? CL_MEM_READ_ONLY : CL_MEM_READ_WRITE, tb[i], host[i], &d.buf[i],
                   names[i], err) ||
            ppb_cl_check(clSetKernelArg(d.k, (cl_uint)(i + 1), sizeof(cl_mem), &d.buf[i]),
                         "clSetKernelArg(mc3d)", err))
            goto done;
    size_t local = cfg->mc.workgroup > 0 ? (size_t)cfg->mc.workgroup : 0;
    if (local > ocl->max_workgroup) {
        ppb_config_key_fail(cfg, mc_section(), "workgroup", err,
                            "mc3d: %zu exceeds the device's maximum work-group size %zu", local,
                            ocl->max_workgroup);
        goto done;
    }
    long long chunk = cfg->mc.chunk > 0 ? cfg->mc.chunk : 1 << 16;
    double t0 = ppb_now();
    char label[128];
    snprintf(label, sizeof label, "%s: mc3d", o->name);
    ppb_progress prog;
    ppb_progress_begin(&prog, label, "photons", (double)cfg->mc.photons, ctx->quiet);
    for (long long done_n = 0; done_n < cfg->mc.photons; done_n += chunk) {
        if (ppb_interrupted()) { /* between launches: nothing partial is written */
            ppb_fail(err, "mc3d: interrupted after %lld of %lld photons", done_n, cfg->mc.photons);
            goto done;
        }
        long long n = cfg->mc.photons - done_n < chunk ? cfg->mc.photons - done_n : chunk;
        P.first = (ppb_u64)(cfg->mc.first + done_n), P.count = (ppb_u64)n;
        size_t global = (size_t)n;
        if (local)
            global = (global + local - 1) / local * local;
        if (ppb_cl_check(clSetKernelArg(d.k, PPB_MC3D_ARG_PARAMS, sizeof P, &P),
                         "clSetKernelArg(mc3d params)", err) ||
            ppb_cl_check(clEnqueueNDRangeKernel(ocl->queue, d.k, 1, NULL, &global,
                                                local ? &local : NULL, 0, NULL, NULL),
                         "clEnqueueNDRangeKernel(ppb_mc3d_kernel)", err) ||
            ppb_cl_check(clFinish(ocl->queue), "clFinish(mc3d)", err))
            goto done;
        ppb_progress_update(&prog, (double)(done_n + n));
    }
    ppb_progress_end(&prog, (double)cfg->mc.photons);
    double secs = ppb_now() - t0;
    if (ppb_cl_check(
            clEnqueueReadBuffer(ocl->queue, d.buf[3], CL_TRUE, 0, tb[3], cells, 0, NULL, NULL),
            "clEnqueueReadBuffer(mc3d cells)", err) ||
        ppb_cl_check(
            clEnqueueReadBuffer(ocl->queue, d.buf[4], CL_TRUE, 0, tb[4], pixels, 0, NULL, NULL),
            "clEnqueueReadBuffer(mc3d pixels)", err) ||
        ppb_cl_check(
            clEnqueueReadBuffer(ocl->queue, d.buf[5], CL_TRUE, 0, tb[5], totals, 0, NULL, NULL),
            "clEnqueueReadBuffer(mc3d totals)", err))
        goto done;
    /* The pixels' fixed-point bound (mc3d_params.h): a batch's contributions, each at most its
     * weight (1, or the capped roulette's 8 x PPB_MC3D_CAP_WMAX) times the phase function's
     * peak, one per event, must stay below 2^64 / 2^24. */
    double pmax = ppb_hg_phase(o->g, o->g >= 0 ? 1.0 : -1.0);
    for (int b = 0; b < B; b++) {
        const uint64_t *tb_ = totals + (size_t)b * PPB_MC3D_NTOT;
        double wmax = tb_[PPB_MC3D_T_CAPPED] ? 8.0 * PPB_MC3D_CAP_WMAX : 1.0;
        if ((double)tb_[PPB_MC3D_T_EVENTS] * wmax * pmax >= 0x1p64 / PPB_MC3D_PIX_SCALE) {
            ppb_config_key_fail(cfg, mc_section(), "batches", err,
                                "mc3d: batch %d's %llu events may overflow its fixed-point "
                                "pixels (mc3d_params.h): raise [mc] batches",
                                b, (unsigned long long)tb_[PPB_MC3D_T_EVENTS]);
            goto done;
        }
    }
    /* Photon i is in batch i mod B. */
    long long N = cfg->mc.photons, first = cfg->mc.first;
    for (int b = 0; b < B; b++) {
        long long r0 = ((b - first % B) % B + B) % B; /* first offset i - first in batch b */
        nb[b] = r0 < N ? (N - r0 + B - 1) / B : 0;
    }
    /* Per photon launched, the power A / N (E_perp = 1, A the entry area): radiance of a patch
     * cell = power / (patch area x the bin's projected solid angle); a pixel = power / pixel
     * area (docs/reference.md, Objects). */
    double omega = ppb_obj_bin_proj_solid_angle(o->ntheta, o->nphi);
    for (int t = 0; t < 2; t++) {
        for (size_t cidx = 0; cidx < ncells; cidx++) {
            double m, s, norm = area / (pt->patch[cidx / (size_t)nbins].area * omega);
            batch_stats(cells + (size_t)t * ncells + cidx, PPB_MC3D_NTALLY * ncells, nb, B, N,
                        PPB_MC3D_SCALE, &m, &s);
            out[t].patch_rad[cidx] = m * norm, out[t].patch_se[cidx] = s * norm;
        }
        double pnorm = area / (cam.pixel * cam.pixel);
        for (size_t q = 0; q < npix; q++) {
            double m, s;
            batch_stats(pixels + (size_t)t * npix + q, PPB_MC3D_NTALLY * npix, nb, B, N,
                        PPB_MC3D_PIX_SCALE, &m, &s);
            out[t].img[q] = m * pnorm, out[t].img_se[q] = s * pnorm;
        }
        out[t].seconds = secs, out[t].photons = N;
    }
    if (tot) {
        memset(tot, 0, sizeof *tot);
        uint64_t sum[PPB_MC3D_NTOT] = {0};
        for (int b = 0; b < B; b++)
            for (int k = 0; k < PPB_MC3D_NTOT; k++)
                sum[k] += totals[(size_t)b * PPB_MC3D_NTOT + k];
        tot->launched = N, tot->hits = (long long)sum[PPB_MC3D_T_HITS];
        tot->events = (long long)sum[PPB_MC3D_T_EVENTS];
        tot->capped = (long long)sum[PPB_MC3D_T_CAPPED];
        double h = tot->hits ? (double)tot->hits * PPB_MC3D_SCALE : 1;
        tot->escaped = (double)sum[PPB_MC3D_T_ESCAPED] / h;
        tot->ballistic = (double)sum[PPB_MC3D_T_BALLISTIC] / h;
        tot->absorbed = (double)sum[PPB_MC3D_T_ABSORBED] / h;
        tot->rgain = (double)sum[PPB_MC3D_T_RGAIN] / h;
        tot->rloss = (double)sum[PPB_MC3D_T_RLOSS] / h;
        tot->proj_area = area;
        /* Standard errors per hit photon from the batches' per-photon means. */
        long long hb[1024];
        for (int b = 0; b < B && b < 1024; b++)
            hb[b] = (long long)totals[(size_t)b * PPB_MC3D_NTOT + PPB_MC3D_T_HITS];
        double m;
        batch_stats(totals + PPB_MC3D_T_ESCAPED, PPB_MC3D_NTOT, hb, B, tot->hits, PPB_MC3D_SCALE,
                    &m, &tot->escaped_se);
        batch_stats(totals + PPB_MC3D_T_ABSORBED, PPB_MC3D_NTOT, hb, B, tot->hits, PPB_MC3D_SCALE,
                    &m, &tot->absorbed_se);
    }
    status = 0;
done:
    dev_release(&d);
    free(sig), free(alb), free(cells), free(pixels), free(totals), free(nb);
    return status;
}

int ppb_object_method_mc3d(ppb_run_ctx *ctx, const ppb_object *o, const ppb_object_patches *p,
                           ppb_object_result *out, ppb_err *err)
{
    ppb_mc3d_totals t;
    if (ppb_mc3d_trace(ctx, o, p, out, &t, err))
        return -1;
    char *csv = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&csv, &len);
    if (!f)
        return ppb_fail(err, "mc3d: out of memory for its totals");
    fprintf(f, "launched,hits,escaped,escaped_se,ballistic,absorbed,absorbed_se,rgain,rloss,"
               "balance,events,capped,entry_area\n");
    fprintf(f, "%lld,%lld,%.9g,%.3g,%.9g,%.9g,%.3g,%.3g,%.3g,%.12g,%lld,%lld,%.9g\n", t.launched,
            t.hits, t.escaped, t.escaped_se, t.ballistic, t.absorbed, t.absorbed_se, t.rgain,
            t.rloss, t.escaped + t.absorbed + t.rloss - t.rgain, t.events, t.capped, t.proj_area);
    if (fclose(f) != 0) {
        free(csv);
        return ppb_fail(err, "mc3d: out of memory for its totals");
    }
    out[0].totals_csv = csv;
    if (!ctx->quiet)
        fprintf(stderr,
                "%s: mc3d: %lld photons, %lld reached the object; escaped %.6f + absorbed %.6f = "
                "%.6f; %.3g events/s\n",
                o->name, t.launched, t.hits, t.escaped, t.absorbed, t.escaped + t.absorbed,
                (double)t.events / fmax(out[0].seconds, 1e-9));
    return 0;
}
