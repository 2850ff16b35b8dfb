/* method_rte2d.c: `rte2d` (method_rte2d.h): OpenCL marches, host scattering and GMRES. */
#include "methods/method_rte2d.h"

#include <cblas.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"
#include "base/clock.h"
#include "base/memory.h"
#include "base/progress.h"
#include "kernels/march_params.h"
#include "kernels/ppb_fresnel.h"
#include "methods/march.h"
#include "methods/result_check.h"
#include "model/metrics.h"
#include "physics/gmres.h"
#include "physics/rte2d_grid.h"

_Static_assert(sizeof(ppb_rte_params) == 22 * sizeof(double) + 24 * sizeof(int),
               "ppb_rte_params: doubles first, an even number of ints, no padding");

/* Krylov vectors per GMRES cycle. */
#define RTE_RESTART 30

/* An exit march's sampling: n x n directions per bin, npts points per segment, and the
 * direction samples' cell integrals (ppb_rte_exit_coeffs). */
typedef struct rte_exit {
    int nsamp, npts, ndir;
    double *Fx; /* [ndir][nc] */
    double *bx; /* n > 1: [ndir][4] slots of the samples' mirrors (PPB_RTE_ARG_BND); else NULL */
} rte_exit;

typedef struct rte_solver {
    ppb_ocl *ocl;
    ppb_rte_grid G;
    cl_program prog;
    cl_kernel sweep, exitk;
    cl_mem dirs, src, out;
    cl_mem radb, bnd; /* n > 1: the field the walls reflect, the cells' walls (else NULL) */
    size_t nvec;      /* nc x nnodes */
    double *J;        /* [nc][nnodes] scratch */
    int sweeps;
    double t_sweeps;
} rte_solver;

static void solver_free(rte_solver *s)
{
    cl_mem bufs[] = {s->dirs, s->src, s->out, s->radb, s->bnd};
    for (size_t i = 0; i < 5; i++)
        if (bufs[i])
            clReleaseMemObject(bufs[i]);
    if (s->sweep)
        clReleaseKernel(s->sweep);
    if (s->exitk)
        clReleaseKernel(s->exitk);
    if (s->prog)
        clReleaseProgram(s->prog);
    free(s->J);
    ppb_rte_grid_free(&s->G);
    memset(s, 0, sizeof *s);
}

static cl_mem buffer(ppb_ocl *ocl, cl_mem_flags flags, size_t n, const double *host,
                     const char *what, ppb_err *err)
{
    cl_int rc;
    cl_mem m = clCreateBuffer(ocl->context, flags | (host ? CL_MEM_COPY_HOST_PTR : 0),
                              (n ? n : 1) * sizeof(double), (void *)host, &rc);
    if (rc != CL_SUCCESS) {
        ppb_fail(err, "OpenCL: clCreateBuffer(%s, %zu doubles) failed: %s", what, n,
                 ppb_cl_errname(rc));
        return NULL;
    }
    return m;
}

static int set_args(cl_kernel k, const ppb_rte_params *P, cl_mem dirs, cl_mem src, cl_mem out,
                    cl_mem rad, cl_mem bnd, ppb_err *err)
{
    /* n = 1: the kernels read neither; any buffer keeps the arguments set. */
    rad = rad ? rad : dirs;
    bnd = bnd ? bnd : dirs;
    if (ppb_cl_check(clSetKernelArg(k, PPB_RTE_ARG_RAD, sizeof(cl_mem), &rad),
                     "clSetKernelArg(rte2d)", err) ||
        ppb_cl_check(clSetKernelArg(k, PPB_RTE_ARG_BND, sizeof(cl_mem), &bnd),
                     "clSetKernelArg(rte2d)", err))
        return -1;
    if (ppb_cl_check(clSetKernelArg(k, PPB_RTE_ARG_PARAMS, sizeof *P, P), "clSetKernelArg(rte2d)",
                     err) ||
        ppb_cl_check(clSetKernelArg(k, PPB_RTE_ARG_DIRS, sizeof(cl_mem), &dirs),
                     "clSetKernelArg(rte2d)", err) ||
        ppb_cl_check(clSetKernelArg(k, PPB_RTE_ARG_SRC, sizeof(cl_mem), &src),
                     "clSetKernelArg(rte2d)", err) ||
        ppb_cl_check(clSetKernelArg(k, PPB_RTE_ARG_OUT, sizeof(cl_mem), &out),
                     "clSetKernelArg(rte2d)", err))
        return -1;
    return 0;
}

/* out = T (sigma_s J + beam) (+ B x at n > 1: the walls' reflection of the field x that J was
 * scattered from): one march from every node in every transported cell. J NULL: the beam's
 * first scattering alone; beam 0: the grid source alone. */
static int sweep(rte_solver *s, const double *J, int beam, const double *x, double *out,
                 ppb_err *err)
{
    if (ppb_interrupted())
        return ppb_fail(err, "rte2d: interrupted");
    double t0 = ppb_now();
    ppb_rte_params P = s->G.P;
    P.beam = beam;
    P.diffuse = J != NULL;
    P.refl = P.refl && x != NULL;
    cl_command_queue q = s->ocl->queue;
    size_t bytes = s->nvec * sizeof(double), global = s->nvec;
    if (J && ppb_cl_check(clEnqueueWriteBuffer(q, s->src, CL_TRUE, 0, bytes, J, 0, NULL, NULL),
                          "clEnqueueWriteBuffer(rte2d source)", err))
        return -1;
    if (P.refl &&
        ppb_cl_check(clEnqueueWriteBuffer(q, s->radb, CL_TRUE, 0, bytes, x, 0, NULL, NULL),
                     "clEnqueueWriteBuffer(rte2d field)", err))
        return -1;
    if (set_args(s->sweep, &P, s->dirs, s->src, s->out, s->radb, s->bnd, err) ||
        ppb_cl_check(clEnqueueNDRangeKernel(q, s->sweep, 1, NULL, &global, NULL, 0, NULL, NULL),
                     "clEnqueueNDRangeKernel(rte2d sweep)", err) ||
        ppb_cl_check(clEnqueueReadBuffer(q, s->out, CL_TRUE, 0, bytes, out, 0, NULL, NULL),
                     "clEnqueueReadBuffer(rte2d sweep)", err))
        return -1;
    s->sweeps++;
    s->t_sweeps += ppb_now() - t0;
    return 0;
}

/* y = (I - T S) x, the operator GMRES inverts. */
static int matvec(void *ctx, const double *x, double *y, ppb_err *err)
{
    rte_solver *s = ctx;
    ppb_rte_scatter(&s->G, x, s->J);
    if (sweep(s, s->J, 0, x, y, err))
        return -1;
    for (size_t i = 0; i < s->nvec; i++)
        y[i] = x[i] - y[i];
    return 0;
}

static int solver_init(rte_solver *s, ppb_ocl *ocl, const ppb_config *cfg, size_t src_planes,
                       size_t out_cells, ppb_err *err)
{
    memset(s, 0, sizeof *s);
    s->ocl = ocl;
    const ppb_rte2d_settings *r = &cfg->rte2d;
    if (ppb_rte_grid_make(&cfg->scene, r->spacing, r->directions, r->step, &s->G, err))
        return -1;
    s->nvec = (size_t)s->G.nc * s->G.nnodes;
    size_t planes = src_planes > (size_t)s->G.nc ? src_planes : (size_t)s->G.nc;
    size_t outn = out_cells > s->nvec ? out_cells : s->nvec;
    s->J = malloc(sizeof(double) * s->nvec);
    if (!s->J)
        return ppb_fail(err, "rte2d: out of memory");
    if (ppb_ocl_build(ocl, "rte2d.cl", "", &s->prog, err) ||
        ppb_ocl_kernel(s->prog, "ppb_rte_sweep", &s->sweep, err) ||
        ppb_ocl_kernel(s->prog, "ppb_rte_exit", &s->exitk, err))
        return -1;
    s->dirs = buffer(ocl, CL_MEM_READ_ONLY, 4 * (size_t)s->G.nc, s->G.dir4, "rte2d cells", err);
    if (s->dirs)
        s->src = buffer(ocl, CL_MEM_READ_ONLY, planes * s->G.nnodes, NULL, "rte2d source", err);
    if (s->src)
        s->out = buffer(ocl, CL_MEM_WRITE_ONLY, outn, NULL, "rte2d output", err);
    if (s->out && s->G.bnd) {
        s->radb = buffer(ocl, CL_MEM_READ_ONLY, s->nvec, NULL, "rte2d field", err);
        if (s->radb)
            s->bnd = buffer(ocl, CL_MEM_READ_ONLY, PPB_RTE_BND * (size_t)s->G.nc, s->G.bnd,
                            "rte2d walls", err);
        return s->bnd ? 0 : -1;
    }
    return s->out ? 0 : -1;
}

/* The exit directions' cell integrals of a sampling, once per solve (every exit march of that
 * sampling reuses them). */
static int exit_setup(rte_solver *s, const ppb_config *cfg, const ppb_layout *lo, int nsamp,
                      int npts, rte_exit *ex, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    int nsurf = lo->nsurf, nbins = lo->nbins;
    ex->nsamp = nsamp;
    ex->npts = npts;
    ex->ndir = ppb_march_ndir(nsurf, nbins, nsamp);
    double *w = malloc(sizeof(double) * 3 * ex->ndir);
    ex->Fx = malloc(sizeof(double) * (size_t)ex->ndir * s->G.nc);
    ex->bx = sc->n > 1.0 ? malloc(sizeof(double) * 4 * (size_t)ex->ndir) : NULL;
    if (!w || !ex->Fx || (sc->n > 1.0 && !ex->bx)) {
        free(w);
        return ppb_fail(err, "rte2d: out of memory (exit source)");
    }
    for (int surf = 0; surf < nsurf; surf++)
        for (int bin = 0; bin < nbins; bin++)
            for (int a = 0; a < nsamp; a++)
                for (int b = 0; b < nsamp; b++) {
                    int d = ppb_march_dir_index(surf, bin, a, b, nsamp, nbins);
                    ppb_march_dir(surf, bin, a, b, nsamp, sc->ntheta, sc->nphi, &w[3 * d],
                                  &w[3 * d + 1], &w[3 * d + 2]);
                    if (sc->n > 1.0) {
                        /* Inside along Snell's direction (the exit kernel maps it the same
                         * way); its mirrors in each face for the wall term. */
                        double *v = &w[3 * d];
                        ppb_inside_dir(surf, sc->n, v);
                        double my[3] = {v[0], -v[1], v[2]}, mx[3] = {-v[0], v[1], v[2]};
                        double *bx = ex->bx + 4 * d;
                        bx[PPB_S1] = bx[PPB_S2] = s->G.slot[pp_dirs_cell_of(&s->G.dirs, my)];
                        bx[PPB_S3] = bx[PPB_S4] = s->G.slot[pp_dirs_cell_of(&s->G.dirs, mx)];
                    }
                }
    int rc = ppb_rte_exit_coeffs(&s->G, sc->g, w, ex->ndir, ex->Fx, err);
    free(w);
    return rc;
}

/* The exit march of sampling ex: the grid source for every exit direction sample, then every
 * (row, bin); radiance [lo->ncells] receives the bins. */
static int exit_march(rte_solver *s, const ppb_config *cfg, const rte_exit *ex, const double *rad,
                      const ppb_layout *lo, double *radiance, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    int nbins = lo->nbins, ndir = ex->ndir, nn = s->G.nnodes, nc = s->G.nc;
    double *Jx = malloc(sizeof(double) * (size_t)ndir * nn);
    int rc = Jx ? 0 : ppb_fail(err, "rte2d: out of memory (exit source)");
    if (!rc) {
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, ndir, nn, nc, 1.0, ex->Fx, nc, rad,
                    nn, 0.0, Jx, nn);
        rc = ppb_cl_check(clEnqueueWriteBuffer(s->ocl->queue, s->src, CL_TRUE, 0,
                                               sizeof(double) * (size_t)ndir * nn, Jx, 0, NULL,
                                               NULL),
                          "clEnqueueWriteBuffer(rte2d exit source)", err);
    }
    free(Jx);
    cl_mem bx = NULL;
    if (!rc && ex->bx) {
        rc = ppb_cl_check(clEnqueueWriteBuffer(s->ocl->queue, s->radb, CL_TRUE, 0,
                                               sizeof(double) * s->nvec, rad, 0, NULL, NULL),
                          "clEnqueueWriteBuffer(rte2d field)", err);
        if (!rc && !(bx = buffer(s->ocl, CL_MEM_READ_ONLY, 4 * (size_t)ndir, ex->bx,
                                 "rte2d exit walls", err)))
            rc = -1;
    }
    ppb_rte_params P = s->G.P;
    P.beam = P.diffuse = 1;
    P.ntheta = sc->ntheta;
    P.nphi = sc->nphi;
    P.nsamp = ex->nsamp;
    P.npts = ex->npts;
    for (int k = 0; k < PPB_NSURF; k++) {
        P.nseg[k] = lo->nseg[k];
        P.offset[k] = lo->offset[k];
    }
    int rows = (int)(lo->ncells / (size_t)nbins);
    const int chunk = 16;
    for (int row0 = 0; !rc && row0 < rows; row0 += chunk) {
        if (ppb_interrupted()) {
            rc = ppb_fail(err, "rte2d: interrupted");
            break;
        }
        P.row0 = row0;
        size_t global = (size_t)(rows - row0 < chunk ? rows - row0 : chunk) * nbins;
        rc = set_args(s->exitk, &P, s->dirs, s->src, s->out, s->radb, bx, err) ||
             ppb_cl_check(clEnqueueNDRangeKernel(s->ocl->queue, s->exitk, 1, NULL, &global, NULL, 0,
                                                 NULL, NULL),
                          "clEnqueueNDRangeKernel(rte2d exit)", err) ||
             ppb_cl_check(clFinish(s->ocl->queue), "clFinish(rte2d exit)", err);
    }
    if (!rc)
        rc = ppb_cl_check(clEnqueueReadBuffer(s->ocl->queue, s->out, CL_TRUE, 0,
                                              lo->ncells * sizeof(double), radiance, 0, NULL, NULL),
                          "clEnqueueReadBuffer(rte2d radiance)", err);
    if (bx)
        clReleaseMemObject(bx);
    return rc;
}

static int rte_memory_check(const ppb_config *cfg, const ppb_layout *lo, ppb_err *err)
{
    const ppb_rte2d_settings *r = &cfg->rte2d;
    int nsamp = cfg->samples_dir < 1 ? 1 : cfg->samples_dir;
    double solve = ppb_rte_bytes(&cfg->scene, r->spacing, r->directions, RTE_RESTART);
    double nodes = solve / (8.0 * (r->directions + 10.0) * (RTE_RESTART + 8)); /* about */
    double exitb = 8.0 * ppb_march_ndir(lo->nsurf, lo->nbins, nsamp) * nodes * 2.0;
    char detail[160];
    snprintf(detail, sizeof detail, "solve %.3g GB, exit source %.3g GB x 2", solve / 1e9,
             exitb / 2e9);
    return ppb_memory_check(solve + exitb, cfg->memory_limit, "rte2d", detail, err);
}

/* The refinement study (reference: rte2d_refinements.csv): after a converged solve, the exit
 * radiance after K refinements from I_pp (K - 1 plain steps I <- T S I + I_1, the exit march the
 * K-th, as `refinements = K` computes it) against the converged solve's, at the summary cells.
 * K runs over a geometric ladder and stops once every cell is under RTE_LADDER_FLOOR or at the
 * ladder's end. An exit march at the bins' full sampling (4 x 4 directions, 4 points) costs
 * about ten grid sweeps, so the study marches RTE_LADDER_SAMPLES x RTE_LADDER_SAMPLES
 * directions and RTE_LADDER_SAMPLES points (at most the run's own), the converged field
 * included: the difference is smooth in angle and position, and this changed no RMS by more
 * than the figures in the reference (measured at the full sampling). The table waits for the
 * output set (ppb_rte2d_write_refinements): a method writes no files. */
static const int rte_ladder[] = {1, 2, 3, 5, 8, 13, 21, 34, 55, 89};
#define RTE_LADDER_N       ((int)(sizeof rte_ladder / sizeof rte_ladder[0]))
#define RTE_LADDER_FLOOR   2e-3
#define RTE_LADDER_SAMPLES 2

static struct {
    char name[sizeof(((ppb_config *)0)->name)];
    char out_dir[sizeof(((ppb_config *)0)->out_dir)];
    int n;                                /* ladder rungs recorded; 0: none (not converged mode) */
    int K[RTE_LADDER_N];                  /* refinements */
    double rms[RTE_LADDER_N][PPB_NCELLS]; /* rms_rel against the converged; NAN: no points */
} rte_record;

/* Records the ladder for the converged field conv; ipp (I_pp) and b (I_1) as the solve had
 * them. Costs the plain sweeps up to the last rung and one exit march per rung and one more. */
static int record_refinements(rte_solver *s, const ppb_config *cfg, const ppb_layout *lo,
                              const double *conv, const double *ipp, const double *b, ppb_err *err)
{
    int nsamp = cfg->samples_dir < 1 ? 1 : cfg->samples_dir;
    int npts = cfg->samples_seg < 1 ? 1 : cfg->samples_seg;
    nsamp = nsamp < RTE_LADDER_SAMPLES ? nsamp : RTE_LADDER_SAMPLES;
    npts = npts < RTE_LADDER_SAMPLES ? npts : RTE_LADDER_SAMPLES;
    rte_exit ex = {0, 0, 0, NULL, NULL};
    ppb_result r, rc_conv;
    int ok_r = 0, ok_c = 0;
    double *rad = malloc(sizeof(double) * s->nvec);
    int cap = lo->nseg[PPB_S1] > lo->nseg[PPB_S3] ? lo->nseg[PPB_S1] : lo->nseg[PPB_S3];
    cap = cap > 2 ? cap : 2;
    ppb_point *pts = malloc(sizeof *pts * (size_t)cap);
    int rc = (rad && pts) ? 0 : ppb_fail(err, "rte2d: out of memory (refinement study)");
    if (!rc && !(rc = ppb_result_init(&r, "rte2d", lo, err)))
        ok_r = 1;
    if (!rc && !(rc = ppb_result_init(&rc_conv, "rte2d", lo, err)))
        ok_c = 1;
    if (!rc)
        rc = exit_setup(s, cfg, lo, nsamp, npts, &ex, err);
    if (!rc)
        rc = exit_march(s, cfg, &ex, conv, lo, rc_conv.radiance, err);
    if (!rc)
        memcpy(rad, ipp, sizeof(double) * s->nvec);
    for (int rung = 0, k = 1; !rc && rung < RTE_LADDER_N; rung++) {
        for (; !rc && k < rte_ladder[rung]; k++) {
            ppb_rte_scatter(&s->G, rad, s->J);
            rc = sweep(s, s->J, 0, rad, rad, err);
            for (size_t i = 0; !rc && i < s->nvec; i++)
                rad[i] += b[i];
        }
        if (!rc)
            rc = exit_march(s, cfg, &ex, rad, lo, r.radiance, err);
        if (rc)
            break;
        double worst = 0.0;
        rte_record.K[rung] = rte_ladder[rung];
        for (int cell = 0; cell < PPB_NCELLS; cell++) {
            int np = ppb_cell_points(lo, cell, pts, cap);
            double e = np ? ppb_rms_points(&r, &rc_conv, pts, np).rms_rel : NAN;
            rte_record.rms[rung][cell] = e;
            if (np && !(e < worst))
                worst = e;
        }
        rte_record.n = rung + 1;
        if (worst < RTE_LADDER_FLOOR)
            break;
    }
    if (ok_r)
        ppb_result_free(&r);
    if (ok_c)
        ppb_result_free(&rc_conv);
    free(ex.Fx);
    free(ex.bx);
    free(rad);
    free(pts);
    return rc;
}

int ppb_rte2d_write_refinements(const ppb_config *cfg, const char *dir, ppb_err *err)
{
    if (rte_record.n == 0 || strcmp(rte_record.name, cfg->name) ||
        strcmp(rte_record.out_dir, cfg->out_dir))
        return 0;
    char path[PPB_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/rte2d_refinements.csv", dir);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    fprintf(af.f, "K,cell,rms_rel\n");
    for (int i = 0; i < rte_record.n; i++)
        for (int cell = 0; cell < PPB_NCELLS; cell++)
            if (!isnan(rte_record.rms[i][cell]))
                fprintf(af.f, "%d,%s,%.6g\n", rte_record.K[i], ppb_cell_name(cell),
                        rte_record.rms[i][cell]);
    return ppb_afile_commit(&af, err);
}

/* The method; record: run the refinement study after a converged solve. */
static int rte2d_solve(ppb_run_ctx *ctx, ppb_result *out, ppb_rte2d_stats *stats, int record,
                       ppb_err *err)
{
    double t0 = ppb_now();
    const ppb_config *cfg = ctx->cfg;
    const ppb_scene *sc = &cfg->scene;
    const ppb_layout *lo = &out->layout;
    ppb_rte2d_stats st;
    memset(&st, 0, sizeof st);
    rte_record.n = 0;
    ppb_ocl *ocl;
    if (rte_memory_check(cfg, lo, err) || ppb_ctx_ocl(ctx, &ocl, err))
        return -1;
    int nsamp = cfg->samples_dir < 1 ? 1 : cfg->samples_dir;
    size_t planes = (size_t)ppb_march_ndir(lo->nsurf, lo->nbins, nsamp);
    rte_solver s;
    rte_exit ex = {0, 0, 0, NULL, NULL};
    if (solver_init(&s, ocl, cfg, planes, lo->ncells, err) ||
        exit_setup(&s, cfg, lo, nsamp, cfg->samples_seg < 1 ? 1 : cfg->samples_seg, &ex, err)) {
        free(ex.Fx);
        free(ex.bx);
        solver_free(&s);
        return -1;
    }
    double *rad = malloc(sizeof(double) * s.nvec), *b = malloc(sizeof(double) * s.nvec);
    double *phi = malloc(sizeof(double) * s.G.nnodes);
    int K = cfg->rte2d.refinements;
    double *ipp =
        K == 0 && record ? malloc(sizeof(double) * s.nvec) : NULL; /* kept for the ladder */
    int rc = (rad && b && phi && (K || !record || ipp)) ? 0 : ppb_fail(err, "rte2d: out of memory");
    /* I_1: the exact first scattering marched to every node; I_pp: the start. */
    if (!rc)
        rc = sweep(&s, NULL, 1, NULL, b, err);
    if (!rc)
        rc = ppb_rte_initial_pp(&s.G, sc, rad, err);
    if (!rc && ipp)
        memcpy(ipp, rad, sizeof(double) * s.nvec);
    if (!rc && K == 0) {
        ppb_gmres_opts o = {RTE_RESTART, 2000, cfg->rte2d.tol};
        ppb_gmres_info info;
        rc = ppb_gmres(s.nvec, matvec, &s, b, rad, &o, &info, err);
        st.resid = info.resid;
        st.converged = info.converged;
        if (!rc && !info.converged)
            fprintf(stderr, "%s: rte2d: not converged after %d sweeps (residual %.3g)\n", cfg->name,
                    info.iters, info.resid);
    }
    /* K > 0: K - 1 plain refinements I <- T S I + I_1; the exit march is the K-th. */
    for (int k = 1; !rc && k < K; k++) {
        ppb_rte_scatter(&s.G, rad, s.J);
        rc = sweep(&s, s.J, 0, rad, rad, err);
        for (size_t i = 0; !rc && i < s.nvec; i++)
            rad[i] += b[i];
    }
    double te = ppb_now();
    if (!rc)
        rc = exit_march(&s, cfg, &ex, rad, lo, out->radiance, err);
    st.t_exit = ppb_now() - te;
    if (!rc) {
        ppb_rte_fluence(&s.G, rad, phi);
        double in = ppb_scene_power_in(sc);
        st.absorbed_beam = ppb_rte_absorbed_beam(sc) / in;
        st.absorbed_scattered = ppb_rte_absorbed_scattered(&s.G, phi) / in;
    }
    if (!rc)
        rc = ppb_radiance_check(cfg->name, out, NULL, err);
    if (!rc) {
        memset(out->se, 0, lo->ncells * sizeof *out->se);
        ppb_march_totals(sc, lo, out->radiance, &out->totals);
        /* R, T, sides from the cell field at the boundaries (rte2d_grid.h), as ppslab. */
        double in = ppb_scene_power_in(sc), fl[4];
        ppb_rte_boundary_flux(&s.G, rad, fl);
        out->totals.R = fl[PPB_S1] / in;
        out->totals.T = fl[PPB_S2] / in;
        out->totals.sides = (fl[PPB_S3] + fl[PPB_S4]) / in;
        out->totals.absorbed = st.absorbed_beam + st.absorbed_scattered;
        out->totals.absorbed_tracked = 1;
        rc = ppb_totals_check(cfg->name, out, err);
    }
    st.nodes = s.G.nnodes;
    st.cells = s.G.nc;
    st.sweeps = s.sweeps;
    st.t_sweeps = s.t_sweeps;
    double tr = ppb_now();
    if (!rc && ipp) {
        rc = record_refinements(&s, cfg, lo, rad, ipp, b, err);
        if (rc)
            rte_record.n = 0;
        snprintf(rte_record.name, sizeof rte_record.name, "%s", cfg->name);
        snprintf(rte_record.out_dir, sizeof rte_record.out_dir, "%s", cfg->out_dir);
        st.record_rungs = rte_record.n;
        st.record_sweeps = s.sweeps - st.sweeps;
        st.t_record = ppb_now() - tr;
    }
    st.t_total = ppb_now() - t0;
    if (!rc && !ctx->quiet)
        fprintf(stderr,
                "%s: rte2d: %d nodes x %d cells, %d sweeps (%.2f s each), residual %.2g, "
                "refinement study to K = %d (%.1f s), %.1f s\n",
                cfg->name, st.nodes, st.cells, st.sweeps, st.sweeps ? st.t_sweeps / st.sweeps : 0.0,
                st.resid, st.record_rungs ? rte_record.K[st.record_rungs - 1] : 0, st.t_record,
                st.t_total);
    free(ipp);
    free(ex.Fx);
    free(ex.bx);
    free(rad);
    free(b);
    free(phi);
    solver_free(&s);
    if (stats)
        *stats = st;
    return rc;
}

int ppb_rte2d_run(ppb_run_ctx *ctx, ppb_result *out, ppb_rte2d_stats *stats, ppb_err *err)
{
    return rte2d_solve(ctx, out, stats, 0, err);
}

int ppb_method_rte2d(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return rte2d_solve(ctx, out, NULL, 1, err);
}
