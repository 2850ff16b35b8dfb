/* method_rte2d.c: `rte2d` (method_rte2d.h): OpenCL marches, host scattering and GMRES. */
#include "methods/rte2d/method_rte2d.h"

#include <cblas.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernels/ppb_bin_samples.h"
#include "base/atomic_file.h"
#include "base/clock.h"
#include "base/memory.h"
#include "base/progress.h"
#include "kernels/ppb_fresnel.h"
#include "methods/result_check.h"
#include "model/metrics.h"
#include "physics/gmres.h"
#include "physics/totals.h"
#include "methods/rte2d/rte2d_grid.h"
#include "methods/rte2d/rte2d_ims.h"

_Static_assert(sizeof(ppb_rte_params) ==
                   sizeof(ppb_medium) + sizeof(ppb_lit) + 15 * sizeof(double) + 24 * sizeof(int),
               "ppb_rte_params: the medium, doubles, an even number of ints, no padding");

/* Krylov vectors per GMRES cycle. */
#define RTE_RESTART 30

/* An exit march's sampling: n x n directions per bin, npts points per segment, and the
 * direction samples' cell integrals (ppb_rte_exit_coeffs). */
typedef struct rte_exit {
    int nsamp, npts, ndir;
    double *Fx; /* [ndir][nc] */
    double *bx; /* n > 1: [ndir][4] slots of the samples' mirrors (PPB_RTE_ARG_BND); else NULL */
    double *wd; /* [ndir][3]: each sample's direction (air side; ppb_bin_sample_dir) */
    ppb_rte_ims ims; /* delta-M's intensity correction of the sources (m = 0: none) */
} rte_exit;

typedef struct rte_solver {
    ppb_ocl *ocl;
    ppb_rte_grid G;
    cl_program prog;
    cl_kernel moc, exitk;
    /* The sweep's buffers (rte2d_params.h, PPB_MOC_ARG_*) and the exit march's. */
    cl_mem dirs, edges, sig, q, bin, xo, scr; /* xo: the sweep's result, the unknown's layout */
    cl_mem qg, lsc;                           /* linear source: gradients, the tracks' sums */
    cl_mem src, out, radb, bnd; /* exit: sources, radiance, n > 1: node field and walls */
    size_t nvec;                /* the unknown: nc (nf + nb) (rte2d_grid.h) */
    double *Q, *Qb, *J, *B;     /* [nc][nf] emission, beam emission, scatter; [nc][nb] inflow */
    double *Qg, *Qbg, *Jg;      /* linear source: their gradients [nc][nf][2] */
    double *rn;                 /* [nc][nnodes]: a field at the nodes, for the exit march */
    double absorbed_beam;       /* the beam's collisions times 1 - alpha (ppb_rte_beam_sources) */
    int sweeps;
    double t_sweeps;
    /* Delta-M's intensity correction (rte2d_ims.h): the exact medium's g and albedo and the
     * truncation f; f = 0: none. */
    double ims_g, ims_albedo, ims_f;
} rte_solver;

static void solver_free(rte_solver *s)
{
    cl_mem bufs[] = {s->dirs, s->edges, s->sig,  s->q,   s->bin, s->xo, s->scr,
                     s->src,  s->out,   s->radb, s->bnd, s->qg,  s->lsc};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++)
        if (bufs[i])
            clReleaseMemObject(bufs[i]);
    if (s->moc)
        clReleaseKernel(s->moc);
    if (s->exitk)
        clReleaseKernel(s->exitk);
    if (s->prog)
        clReleaseProgram(s->prog);
    free(s->Q);
    free(s->Qb);
    free(s->J);
    free(s->B);
    free(s->rn);
    free(s->Qg);
    free(s->Qbg);
    free(s->Jg);
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

static int set_arg(cl_kernel k, cl_uint i, size_t size, const void *v, ppb_err *err)
{
    return ppb_cl_check(clSetKernelArg(k, i, size, v), "clSetKernelArg(rte2d)", err);
}

static int set_args(cl_kernel k, const ppb_rte_params *P, cl_mem dirs, cl_mem src, cl_mem out,
                    cl_mem rad, cl_mem bnd, ppb_err *err)
{
    /* n = 1: the kernel reads neither; any buffer keeps the arguments set. */
    rad = rad ? rad : dirs;
    bnd = bnd ? bnd : dirs;
    return set_arg(k, PPB_RTE_ARG_RAD, sizeof(cl_mem), &rad, err) ||
           set_arg(k, PPB_RTE_ARG_BND, sizeof(cl_mem), &bnd, err) ||
           set_arg(k, PPB_RTE_ARG_PARAMS, sizeof *P, P, err) ||
           set_arg(k, PPB_RTE_ARG_DIRS, sizeof(cl_mem), &dirs, err) ||
           set_arg(k, PPB_RTE_ARG_SRC, sizeof(cl_mem), &src, err) ||
           set_arg(k, PPB_RTE_ARG_OUT, sizeof(cl_mem), &out, err);
}

/* The walls at n > 1: what enters cell c through edge e of a face is, summed over the cells b
 * that carry light out there, F_b times b's outgoing power there times the share refl[f][b][c]
 * of b's mirror image that c stands for (rte2d_grid.h), F_b b's cell-averaged reflectance at
 * that face: so what is reflected (here) and what is transmitted (ppb_rte_boundary_flux) add up
 * to what reached the wall. */
static void reflect_inflow(const ppb_rte_grid *G, const double *x, double *B)
{
    size_t stride = (size_t)G->nf + G->nb;
    int nc = G->nc;
    memset(B, 0, sizeof(double) * nc * G->nb);
    for (int face = 0; face < (G->P.med.tube ? 4 : 2); face++) {
        int e0 = ppb_moc_edge0(G->nfx, G->P.ny, face), ne = ppb_moc_nedge(G->nfx, G->P.ny, face);
        for (int b = 0; b < nc; b++) {
            const double *row = G->refl + ((size_t)face * nc + b) * nc;
            const double *out = x + b * stride + G->nf;
            double F = G->bnd[PPB_RTE_BND * b + 4 + face];
            for (int c = 0; c < nc; c++)
                if (row[c] != 0.0) {
                    double *in = B + (size_t)c * G->nb;
                    /* Per sr of c: the cells stand for mult of them each. */
                    double w = F * row[c] * G->mult[b] / G->mult[c];
                    for (int e = e0; e < e0 + ne; e++)
                        in[e] += w * out[e];
                }
        }
    }
}

/* y = T (sigma_s J(x) + beam) with the walls' reflection of x (n > 1): one conservative sweep
 * (rte2d.cl, ppb_rte_moc) of every transported cell. x NULL: the beam's first scattering alone;
 * beam 0: the scattered light of x alone. */
static int sweep(rte_solver *s, const double *x, int beam, double *y, ppb_err *err)
{
    if (ppb_interrupted())
        return ppb_fail(err, "rte2d: interrupted");
    double t0 = ppb_now();
    const ppb_rte_grid *G = &s->G;
    ppb_rte_params P = G->P;
    P.refl = P.refl && x != NULL;
    size_t nq = (size_t)G->nc * G->nf, nb = (size_t)G->nc * G->nb;
    if (x)
        ppb_rte_scatter(G, x, s->J, P.ls ? s->Jg : NULL);
    for (size_t i = 0; i < nq; i++) {
        double al_st = G->falb[(i % G->nf) % G->nfx] * G->fsig[(i % G->nf) % G->nfx];
        s->Q[i] = (x ? al_st * s->J[i] : 0.0) + (beam ? s->Qb[i] : 0.0);
        for (int d = 0; P.ls && d < 2; d++)
            s->Qg[2 * i + d] =
                (x ? al_st * s->Jg[2 * i + d] : 0.0) + (beam ? s->Qbg[2 * i + d] : 0.0);
    }
    if (P.refl)
        reflect_inflow(G, x, s->B);
    else
        memset(s->B, 0, sizeof(double) * nb);
    cl_command_queue qu = s->ocl->queue;
    size_t global = (size_t)G->nc;
    int nfx = G->nfx;
    cl_double2 dmin = {{G->dmin[0], G->dmin[1]}};
    cl_mem args[] = {s->dirs, s->edges, s->sig, s->q, s->bin, s->xo, s->scr};
    cl_mem ls_args[] = {s->qg, s->lsc};
    int rc =
        ppb_cl_check(
            clEnqueueWriteBuffer(qu, s->q, CL_TRUE, 0, nq * sizeof(double), s->Q, 0, NULL, NULL),
            "clEnqueueWriteBuffer(rte2d source)", err) ||
        ppb_cl_check(
            clEnqueueWriteBuffer(qu, s->bin, CL_TRUE, 0, nb * sizeof(double), s->B, 0, NULL, NULL),
            "clEnqueueWriteBuffer(rte2d inflow)", err) ||
        (P.ls && ppb_cl_check(clEnqueueWriteBuffer(qu, s->qg, CL_TRUE, 0, 2 * nq * sizeof(double),
                                                   s->Qg, 0, NULL, NULL),
                              "clEnqueueWriteBuffer(rte2d source gradients)", err)) ||
        set_arg(s->moc, PPB_MOC_ARG_PARAMS, sizeof P, &P, err) ||
        set_arg(s->moc, PPB_MOC_ARG_NFX, sizeof nfx, &nfx, err) ||
        set_arg(s->moc, PPB_MOC_ARG_DMIN, sizeof dmin, &dmin, err);
    for (cl_uint i = 0; !rc && i < sizeof args / sizeof args[0]; i++)
        rc = set_arg(s->moc, PPB_MOC_ARG_DIRS + i, sizeof(cl_mem), &args[i], err);
    for (cl_uint i = 0; !rc && i < sizeof ls_args / sizeof ls_args[0]; i++)
        rc = set_arg(s->moc, PPB_MOC_ARG_SRCG + i, sizeof(cl_mem), &ls_args[i], err);
    if (rc ||
        ppb_cl_check(clEnqueueNDRangeKernel(qu, s->moc, 1, NULL, &global, NULL, 0, NULL, NULL),
                     "clEnqueueNDRangeKernel(rte2d sweep)", err))
        return -1;
    /* y in the unknown's layout (rte2d_grid.h), as the kernel wrote it. */
    if (ppb_cl_check(
            clEnqueueReadBuffer(qu, s->xo, CL_TRUE, 0, s->nvec * sizeof(double), y, 0, NULL, NULL),
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
    if (sweep(s, x, 0, y, err))
        return -1;
    for (size_t i = 0; i < s->nvec; i++)
        y[i] = x[i] - y[i];
    return 0;
}

static int solver_init(rte_solver *s, ppb_ocl *ocl, const ppb_config *cfg, int moment,
                       const pp_phase_fn *ph, size_t src_planes, size_t out_cells, ppb_err *err)
{
    memset(s, 0, sizeof *s);
    s->ocl = ocl;
    const ppb_rte2d_settings *r = &cfg->rte2d;
    ppb_rte_grid *G = &s->G;
    if (ppb_rte_grid_make(&cfg->scene, r->spacing, r->directions, r->step, moment, ph, G, err))
        return -1;
    G->P.ls = ppb_rte_ls_applies(r->source, &cfg->scene);
    s->nvec = ppb_rte_nvec(G);
    size_t nq = (size_t)G->nc * G->nf, nb = (size_t)G->nc * G->nb;
    size_t nodes = (size_t)G->nc * G->nnodes;
    size_t planes = src_planes > (size_t)G->nc ? src_planes : (size_t)G->nc;
    s->Q = malloc(sizeof(double) * nq);
    s->Qb = malloc(sizeof(double) * nq);
    s->J = malloc(sizeof(double) * nq);
    s->B = malloc(sizeof(double) * nb);
    s->rn = malloc(sizeof(double) * nodes);
    size_t nls = G->P.ls ? 2 * nq : 0;
    if (nls) {
        s->Qg = malloc(sizeof(double) * nls);
        s->Qbg = malloc(sizeof(double) * nls);
        s->Jg = malloc(sizeof(double) * nls);
    }
    if (!s->Q || !s->Qb || !s->J || !s->B || !s->rn || (nls && (!s->Qg || !s->Qbg || !s->Jg)))
        return ppb_fail(err, "rte2d: out of memory");
    if (ppb_rte_beam_sources(G, s->Qb, s->Qbg, &s->absorbed_beam, err) ||
        ppb_ocl_build(ocl, "src/methods/rte2d/rte2d.cl", "", &s->prog, err) ||
        ppb_ocl_kernel(s->prog, "ppb_rte_moc", &s->moc, err) ||
        ppb_ocl_kernel(s->prog, "ppb_rte_exit", &s->exitk, err))
        return -1;
    cl_mem_flags ro = CL_MEM_READ_ONLY, rw = CL_MEM_READ_WRITE;
    struct {
        cl_mem *m;
        cl_mem_flags fl;
        size_t n;
        const double *host;
        const char *what;
    } want[] = {
        {&s->dirs, ro, 4 * (size_t)G->nc, G->dir4, "rte2d cells"},
        {&s->edges, ro, (size_t)G->nfx + 1 + G->P.ny + 1, G->fedge, "rte2d edges"},
        {&s->sig, ro, (size_t)G->nfx, G->fsig, "rte2d sigma_t"},
        {&s->q, ro, nq, NULL, "rte2d emission"},
        {&s->bin, ro, nb, NULL, "rte2d inflow"},
        {&s->xo, rw, s->nvec, NULL, "rte2d regions and outflow"},
        {&s->scr, rw, nb, NULL, "rte2d scratch"},
        {&s->src, ro, planes * G->nnodes, NULL, "rte2d exit source"},
        {&s->out, CL_MEM_WRITE_ONLY, out_cells, NULL, "rte2d exit output"},
        {&s->radb, ro, G->bnd ? nodes : 0, NULL, "rte2d field"},
        {&s->bnd, ro, G->bnd ? PPB_RTE_BND * (size_t)G->nc : 0, G->bnd, "rte2d walls"},
        {&s->qg, ro, nls ? nls : 1, NULL, "rte2d source gradients"},
        {&s->lsc, rw, nls ? PPB_MOC_LS_ACC * nq : 1, NULL, "rte2d linear-source sums"},
    };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++)
        if (!(*want[i].m = buffer(ocl, want[i].fl, want[i].n, want[i].host, want[i].what, err)))
            return -1;
    return 0;
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
    ex->ndir = ppb_bin_sample_count(nsurf, nbins, nsamp);
    double *w = malloc(sizeof(double) * 3 * ex->ndir);
    ex->Fx = malloc(sizeof(double) * (size_t)ex->ndir * s->G.nc);
    ex->bx = sc->n > 1.0 ? malloc(sizeof(double) * 4 * (size_t)ex->ndir) : NULL;
    ex->wd = malloc(sizeof(double) * 3 * (size_t)ex->ndir);
    if (!w || !ex->Fx || (sc->n > 1.0 && !ex->bx) || !ex->wd) {
        free(w);
        return ppb_fail(err, "rte2d: out of memory (exit source)");
    }
    for (int surf = 0; surf < nsurf; surf++)
        for (int bin = 0; bin < nbins; bin++)
            for (int a = 0; a < nsamp; a++)
                for (int b = 0; b < nsamp; b++) {
                    int d = ppb_bin_sample_index(surf, bin, a, b, nsamp, nbins);
                    /* The kernel weights it by the same function (ppb_exit_sample). */
                    ppb_bin_sample_dir(surf, bin, a, b, nsamp, sc->ntheta, sc->nphi, &w[3 * d],
                                       &w[3 * d + 1], &w[3 * d + 2]);
                    memcpy(ex->wd + 3 * d, w + 3 * d, 3 * sizeof(double));
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
    int rc = ppb_rte_exit_coeffs(&s->G, w, ex->ndir, ex->Fx, err);
    if (!rc && s->ims_f > 0.0)
        rc = ppb_rte_ims_make(&s->G, s->ims_g, s->ims_albedo, s->ims_f, w, ex->ndir, &ex->ims, err);
    free(w);
    return rc;
}

/* The exit march of sampling ex: the grid source for every exit direction sample, then every
 * (row, bin); radiance [lo->ncells] receives the bins. */
static int exit_march(rte_solver *s, const ppb_config *cfg, const rte_exit *ex, const double *x,
                      const ppb_layout *lo, double *radiance, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    /* The source at the nodes: each its dual cell's average (rte2d_grid.h). */
    ppb_rte_to_nodes(&s->G, x, s->rn);
    const double *rad = s->rn;
    int nbins = lo->nbins, ndir = ex->ndir, nn = s->G.nnodes, nc = s->G.nc;
    double *Jx = malloc(sizeof(double) * (size_t)ndir * nn);
    int rc = Jx ? 0 : ppb_fail(err, "rte2d: out of memory (exit source)");
    if (!rc) {
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, ndir, nn, nc, 1.0, ex->Fx, nc, rad,
                    nn, 0.0, Jx, nn);
        ppb_rte_ims_add(&ex->ims, ndir, nn, Jx);
        rc = ppb_cl_check(clEnqueueWriteBuffer(s->ocl->queue, s->src, CL_TRUE, 0,
                                               sizeof(double) * (size_t)ndir * nn, Jx, 0, NULL,
                                               NULL),
                          "clEnqueueWriteBuffer(rte2d exit source)", err);
    }
    free(Jx);
    cl_mem bx = NULL;
    if (!rc && ex->bx) {
        rc = ppb_cl_check(clEnqueueWriteBuffer(s->ocl->queue, s->radb, CL_TRUE, 0,
                                               sizeof(double) * s->G.nc * s->G.nnodes, rad, 0, NULL,
                                               NULL),
                          "clEnqueueWriteBuffer(rte2d field)", err);
        if (!rc && !(bx = buffer(s->ocl, CL_MEM_READ_ONLY, 4 * (size_t)ndir, ex->bx,
                                 "rte2d exit walls", err)))
            rc = -1;
    }
    cl_mem wd = NULL;
    if (!rc && !(wd = buffer(s->ocl, CL_MEM_READ_ONLY, 3 * (size_t)ndir, ex->wd,
                             "rte2d exit samples", err)))
        rc = -1;
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
        rc = set_args(s->exitk, &P, wd, s->src, s->out, s->radb, bx, err) ||
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
    if (wd)
        clReleaseMemObject(wd);
    return rc;
}

/* What a solve allocates, from the config alone (before the grid is built). The exit march's
 * source, a value per exit direction sample and grid node, is the largest array: one buffer on
 * the device (solver_init's "rte2d exit source") and its copy on the host (exit_march's Jx). Its
 * planes are surfaces x bins.theta x bins.phi x bins.samples_dir^2 (at least the cells), its
 * nodes those of rte2d.spacing over the cross-section (ppb_rte_nodes, exact); tube.segments_*
 * size only the exit output (segments x bins). study: the refinement study follows, keeping
 * GMRES's first cycle (one vector more than its restart) and its own three vectors. */
typedef struct rte_sizes {
    double nodes, planes; /* grid nodes; exit direction samples */
    double source;        /* bytes of the exit source */
    double largest;       /* bytes of the largest device buffer */
    double total;         /* bytes in all, host and device */
} rte_sizes;

static rte_sizes rte_sizes_of(const ppb_config *cfg, int study)
{
    const ppb_rte2d_settings *r = &cfg->rte2d;
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    int nsamp = cfg->samples_dir < 1 ? 1 : cfg->samples_dir;
    double cells = r->directions + sqrt(r->directions) + 2.0; /* ppb_rte_bytes' bound */
    rte_sizes z;
    z.nodes = ppb_rte_nodes(&cfg->scene, r->spacing);
    z.planes = fmax((double)lo.nsurf * lo.nbins * nsamp * nsamp, cells);
    z.source = 8.0 * z.planes * z.nodes;
    /* The field buffers: cells x regions and edges, the regions at most twice the nodes (a
     * column split at the step). */
    int ls = ppb_rte_ls_applies(r->source, &cfg->scene);
    z.largest = fmax(z.source, 8.0 * cells * 2.0 * z.nodes * (ls ? PPB_MOC_LS_ACC : 1));
    z.total = ppb_rte_bytes(&cfg->scene, r->spacing, r->directions, RTE_RESTART + 4 * study, ls) +
              2.0 * z.source + 8.0 * z.planes * cells + 16.0 * (double)lo.ncells;
    return z;
}

/* Whether cfg's largest buffer (device) or its total (host) is within limit bytes. */
static int rte_fits(const ppb_config *cfg, int study, int device, double limit)
{
    rte_sizes z = rte_sizes_of(cfg, study);
    return (device ? z.largest : z.total) <= limit;
}

/* "bins.samples_dir = K fits, rte2d.spacing = S fits": the nearest settings under limit, each
 * key changed alone (samples_dir down by one, spacing up by 25 % steps to its range's 10). */
static void rte_what_fits(const ppb_config *cfg, int study, int device, double limit, char *buf,
                          size_t cap)
{
    ppb_config *c = malloc(sizeof *c);
    snprintf(buf, cap, "nothing found");
    if (!c)
        return;
    *c = *cfg;
    size_t n = 0;
    buf[0] = 0;
    for (c->samples_dir = cfg->samples_dir - 1; c->samples_dir >= 1; c->samples_dir--)
        if (rte_fits(c, study, device, limit)) {
            n += snprintf(buf + n, cap - n, "bins.samples_dir = %d fits", c->samples_dir);
            break;
        }
    c->samples_dir = cfg->samples_dir;
    for (double s = cfg->rte2d.spacing * 1.25; n < cap && s <= 10.0; s *= 1.25) {
        c->rte2d.spacing = s;
        if (rte_fits(c, study, device, limit)) {
            snprintf(buf + n, cap - n, "%srte2d.spacing = %.3g fits", n ? ", " : "", s);
            break;
        }
    }
    if (!buf[0])
        snprintf(buf, cap, "no single key's change fits");
    free(c);
}

/* The host's bound (reference: Methods, `rte2d`, Refused): the total against [run]
 * memory_limit, refused naming the keys that size it. */
static int rte_memory_check(const ppb_config *cfg, int study, ppb_err *err)
{
    rte_sizes z = rte_sizes_of(cfg, study);
    double limit = ppb_memory_limit(cfg->memory_limit);
    if (z.total <= limit)
        return 0;
    char fits[160];
    rte_what_fits(cfg, study, 0, limit, fits, sizeof fits);
    return ppb_config_key_fail(
        cfg, "rte2d", "spacing", err,
        "rte2d needs about %.3g GB, above the memory limit of %.3g GB ([run] memory_limit%s): its "
        "exit source is %.3g GB on the host and again on the device (%.0f direction samples: "
        "surfaces x bins.theta x bins.phi x bins.samples_dir^2, x %.0f grid nodes: the tube at "
        "rte2d.spacing); lower bins.samples_dir or rte2d.directions, or raise rte2d.spacing (%s)",
        z.total / 1e9, limit / 1e9, cfg->memory_limit > 0.0 ? "" : " = 0: half the machine's",
        z.source / 1e9, z.planes, z.nodes, fits);
}

/* The device's bound, known once it is open: the largest buffer against its
 * CL_DEVICE_MAX_MEM_ALLOC_SIZE (max_alloc), before the grid is built or a kernel launched. */
static int rte_device_check(const ppb_config *cfg, int study, double max_alloc, const char *device,
                            ppb_err *err)
{
    rte_sizes z = rte_sizes_of(cfg, study);
    double limit = max_alloc;
    if (z.largest <= limit)
        return 0;
    char fits[160];
    rte_what_fits(cfg, study, 1, limit, fits, sizeof fits);
    return ppb_fail(err,
                    "rte2d: its exit source needs one buffer of %.3g GB (%.0f direction samples: "
                    "surfaces x bins.theta x bins.phi x bins.samples_dir^2, x %.0f grid nodes: the "
                    "tube at rte2d.spacing), above the %.3g GB the device %s allocates at once "
                    "(CL_DEVICE_MAX_MEM_ALLOC_SIZE): lower bins.samples_dir, or raise "
                    "rte2d.spacing (%s)",
                    z.largest / 1e9, z.planes, z.nodes, limit / 1e9, device, fits);
}

int ppb_rte2d_device_check(const ppb_config *cfg, double max_alloc, const char *device,
                           ppb_err *err)
{
    return rte_device_check(cfg, 0, max_alloc, device, err);
}

/* The refinement study (reference: rte2d_refinements.csv): after a converged solve, the exit
 * radiance after K refinements from I_pp (K - 1 plain steps I <- T S I + I_1, the exit march the
 * K-th, as `refinements = K` computes it) against the converged solve's, at the summary cells.
 * K runs over a geometric ladder and stops once every cell is under RTE_LADDER_FLOOR or at the
 * ladder's end: the study's question is how many refinements a case needs to reach 1 %, and the
 * first rung under 0.5 % answers it with the descent through 1 % shown (0.2 % took a rung more
 * in uniform_gm05_normal, two in uniform_g0_normal_n14, 13 and 21 sweeps, for no answer more).
 * An exit march at the bins' full sampling (4 x 4 directions, 4 points) costs about ten grid
 * sweeps, so the study marches RTE_LADDER_SAMPLES x RTE_LADDER_SAMPLES directions and
 * RTE_LADDER_SAMPLES points (at most the run's own), the converged field included: the
 * difference is smooth in angle and position, and this changed no RMS by more than the figures
 * in the reference (measured at the full sampling). The table waits for the output set
 * (ppb_rte2d_write_refinements): a method writes no files. */
static const int rte_ladder[] = {1, 2, 3, 5, 8, 13, 21, 34, 55, 89};
#define RTE_LADDER_N       ((int)(sizeof rte_ladder / sizeof rte_ladder[0]))
#define RTE_LADDER_FLOOR   5e-3
#define RTE_LADDER_SAMPLES 2
_Static_assert(RTE_LADDER_N <= PPB_RTE2D_RUNGS, "the study's record holds every rung");

/* The plain refinements from I_pp in residual form: the field after K - 1 of them is
 * I_pp + r_0 + .. + r_(K-2), r_j = (T S)^j r_0, r_0 = I_1 - (I - T S) I_pp the residual GMRES
 * started from (I <- T S I + I_1 adds r_j at step j). With GMRES's first cycle (gmres.h),
 * r_j = V c_j for j <= k by c_(j+1) = c_j - H c_j, since T S = I - A: those cost no sweep;
 * beyond, r_(j+1) = T S r_j costs one. Exact but for rounding (the study against separate
 * `refinements = K` runs: tests/test_rte2d.c). */
typedef struct rte_plain {
    const ppb_gmres_basis *kb; /* k = 0, V = NULL: no basis, every r_j by a sweep */
    int j;                     /* r_0 .. r_(j-1) summed */
    double *c, *csum, *hc;     /* [k + 1]: coefficients of r_j (j <= k), of the basis' sum,
                                  scratch */
    double *r, *acc;           /* [nvec]: r_j once past the basis, and the sum of those */
} rte_plain;

/* r <- T S r (+ the walls' B r at n > 1): one sweep. */
static int plain_ts(rte_solver *s, double *r, ppb_err *err)
{
    return sweep(s, r, 0, r, err);
}

static int plain_init(rte_plain *pl, rte_solver *s, const ppb_gmres_basis *kb, ppb_err *err)
{
    int nk = kb->V ? kb->k + 1 : 1;
    memset(pl, 0, sizeof *pl);
    pl->kb = kb;
    pl->c = calloc((size_t)nk, sizeof(double));
    pl->csum = calloc((size_t)nk, sizeof(double));
    pl->hc = calloc((size_t)nk, sizeof(double));
    pl->r = malloc(sizeof(double) * s->nvec);
    pl->acc = calloc(s->nvec, sizeof(double));
    if (!pl->c || !pl->csum || !pl->hc || !pl->r || !pl->acc)
        return ppb_fail(err, "rte2d: out of memory (refinement study)");
    pl->c[0] = kb->beta;
    return 0;
}

static void plain_free(rte_plain *pl)
{
    free(pl->c);
    free(pl->csum);
    free(pl->hc);
    free(pl->r);
    free(pl->acc);
}

/* Adds r_j, j = pl->j: from the basis while it lasts, else marched (r_0 without a basis:
 * T S I_pp + I_1 - I_pp). */
static int plain_add(rte_plain *pl, rte_solver *s, const double *ipp, const double *b, ppb_err *err)
{
    const ppb_gmres_basis *kb = pl->kb;
    int k = kb->V ? kb->k : -1, j = pl->j++;
    if (j <= k) {
        for (int i = 0; i <= j; i++)
            pl->csum[i] += pl->c[i];
        if (j < k) { /* c <- c - H c; c on rows 0 .. j, H upper Hessenberg */
            for (int i = 0; i <= j + 1; i++) {
                double hc = 0.0;
                for (int l = i > 0 ? i - 1 : 0; l <= j; l++)
                    hc += kb->H[(size_t)i * kb->k + l] * pl->c[l];
                pl->hc[i] = hc;
            }
            for (int i = 0; i <= j + 1; i++)
                pl->c[i] -= pl->hc[i];
        }
        return 0;
    }
    int rc;
    if (j == 0) {
        memcpy(pl->r, ipp, sizeof(double) * s->nvec);
        rc = plain_ts(s, pl->r, err);
        for (size_t i = 0; !rc && i < s->nvec; i++)
            pl->r[i] += b[i] - ipp[i];
    } else {
        if (j == k + 1) /* r_k from the basis */
            cblas_dgemv(CblasRowMajor, CblasTrans, k + 1, (int)s->nvec, 1.0, kb->V, (int)s->nvec,
                        pl->c, 1, 0.0, pl->r, 1);
        rc = plain_ts(s, pl->r, err);
    }
    for (size_t i = 0; !rc && i < s->nvec; i++)
        pl->acc[i] += pl->r[i];
    return rc;
}

/* rad = I_pp + the r summed. */
static void plain_field(const rte_plain *pl, size_t nvec, const double *ipp, double *rad)
{
    for (size_t i = 0; i < nvec; i++)
        rad[i] = ipp[i] + pl->acc[i];
    if (pl->kb->V)
        cblas_dgemv(CblasRowMajor, CblasTrans, pl->kb->k + 1, (int)nvec, 1.0, pl->kb->V, (int)nvec,
                    pl->csum, 1, 1.0, rad, 1);
}

/* The rung's rms_rel at every summary cell of r against conv into rms; returns the worst. */
static double rung_rms(const ppb_layout *lo, const ppb_result *r, const ppb_result *conv,
                       ppb_point *pts, int cap, double *rms)
{
    double worst = 0.0;
    for (int cell = 0; cell < PPB_NCELLS; cell++) {
        int np = ppb_cell_points(lo, cell, pts, cap);
        double e = np ? ppb_rms_points(r, conv, pts, np).rms_rel : NAN;
        rms[cell] = e;
        if (np && !(e < worst))
            worst = e;
    }
    return worst;
}

/* Records the ladder for the converged field conv into study; ipp (I_pp) and b (I_1) as the
 * solve had them, kb its first Arnoldi cycle. Costs the sweeps past the basis up to the last
 * rung and one exit march per rung and one more. */
static int record_refinements(rte_solver *s, const ppb_config *cfg, const ppb_layout *lo,
                              const double *conv, const double *ipp, const double *b,
                              const ppb_gmres_basis *kb, ppb_rte2d_study *study, ppb_err *err)
{
    int nsamp = cfg->samples_dir < 1 ? 1 : cfg->samples_dir;
    int npts = cfg->samples_seg < 1 ? 1 : cfg->samples_seg;
    nsamp = nsamp < RTE_LADDER_SAMPLES ? nsamp : RTE_LADDER_SAMPLES;
    npts = npts < RTE_LADDER_SAMPLES ? npts : RTE_LADDER_SAMPLES;
    rte_exit ex = {0, 0, 0, NULL, NULL, NULL, {0, NULL, NULL}};
    rte_plain pl = {0};
    ppb_result r, rc_conv;
    int ok_r = 0, ok_c = 0;
    double *rad = malloc(sizeof(double) * s->nvec);
    int cap = lo->nseg[PPB_S1] > lo->nseg[PPB_S3] ? lo->nseg[PPB_S1] : lo->nseg[PPB_S3];
    cap = cap > 2 ? cap : 2;
    ppb_point *pts = malloc(sizeof *pts * (size_t)cap);
    int rc = (rad && pts) ? 0 : ppb_fail(err, "rte2d: out of memory (refinement study)");
    if (!rc)
        rc = plain_init(&pl, s, kb, err);
    if (!rc && !(rc = ppb_result_init(&r, "rte2d", lo, err)))
        ok_r = 1;
    if (!rc && !(rc = ppb_result_init(&rc_conv, "rte2d", lo, err)))
        ok_c = 1;
    if (!rc)
        rc = exit_setup(s, cfg, lo, nsamp, npts, &ex, err);
    if (!rc)
        rc = exit_march(s, cfg, &ex, conv, lo, rc_conv.radiance, err);
    for (int rung = 0; !rc && rung < RTE_LADDER_N; rung++) {
        while (!rc && pl.j < rte_ladder[rung] - 1)
            rc = plain_add(&pl, s, ipp, b, err);
        if (!rc) {
            plain_field(&pl, s->nvec, ipp, rad);
            rc = exit_march(s, cfg, &ex, rad, lo, r.radiance, err);
        }
        if (rc)
            break;
        study->K[rung] = rte_ladder[rung];
        study->n = rung + 1;
        if (rung_rms(lo, &r, &rc_conv, pts, cap, study->rms[rung]) < RTE_LADDER_FLOOR)
            break;
    }
    if (ok_r)
        ppb_result_free(&r);
    if (ok_c)
        ppb_result_free(&rc_conv);
    plain_free(&pl);
    free(ex.Fx);
    free(ex.bx);
    free(ex.wd);
    ppb_rte_ims_free(&ex.ims);
    free(rad);
    free(pts);
    return rc;
}

/* The study as the result's extra output (model/result.h). */
static int write_study(const void *study, const char *dir, ppb_err *err)
{
    return ppb_rte2d_write_refinements(study, dir, err);
}

int ppb_rte2d_write_refinements(const ppb_rte2d_study *study, const char *dir, ppb_err *err)
{
    if (!study || study->n == 0)
        return 0;
    ppb_afile af;
    if (ppb_afile_open_csv(&af, dir, "rte2d_refinements.csv", "K,cell,rms_rel", err))
        return -1;
    for (int i = 0; i < study->n; i++)
        for (int cell = 0; cell < PPB_NCELLS; cell++)
            if (!isnan(study->rms[i][cell]))
                fprintf(af.f, "%d,%s,%.6g\n", study->K[i], ppb_cell_name(cell),
                        study->rms[i][cell]);
    return ppb_afile_commit(&af, err);
}

/* The field rad from I_1 (b) and I_pp: GMRES to the tolerance, or K - 1 plain refinements
 * I <- T S I + I_1 when `refinements = K` > 0 (the exit march is the K-th). ipp (not NULL)
 * keeps I_pp and kb the first Arnoldi cycle, for the refinement study. */
static int solve_field(rte_solver *s, const ppb_config *cfg, double *rad, double *b, double *ipp,
                       ppb_gmres_basis *kb, ppb_rte2d_stats *st, ppb_err *err)
{
    int K = cfg->rte2d.refinements;
    /* I_1: the beam's first scattering swept through every region; I_pp: the start. */
    int rc = sweep(s, NULL, 1, b, err);
    if (!rc)
        rc = ppb_rte_initial_pp(&s->G, &cfg->scene, s->rn, err);
    if (!rc)
        ppb_rte_from_nodes(&s->G, s->rn, rad);
    if (!rc && ipp)
        memcpy(ipp, rad, sizeof(double) * s->nvec);
    if (!rc && K == 0) {
        ppb_gmres_opts o = {RTE_RESTART, 2000, cfg->rte2d.tol, kb};
        ppb_gmres_info info;
        rc = ppb_gmres(s->nvec, matvec, s, b, rad, &o, &info, err);
        st->resid = info.resid;
        st->converged = info.converged;
        if (!rc && !info.converged)
            fprintf(stderr, "%s: rte2d: not converged after %d sweeps (residual %.3g)\n", cfg->name,
                    info.iters, info.resid);
    }
    for (int k = 1; !rc && k < K; k++) {
        rc = sweep(s, rad, 0, rad, err);
        for (size_t i = 0; !rc && i < s->nvec; i++)
            rad[i] += b[i];
    }
    return rc;
}

/* Under delta-M the scaled beam (sigma_t') carries, besides the unscattered light, the light
 * scattered only within the truncated peak, which the scaled problem counts as unscattered
 * (reference: Methods, `rte2d`, delta-M). It leaves through the faces the scaled beam reaches,
 * scattered: the totals give each face its share, (scaled less exact) ballistic per face, and
 * `ballistic` is the exact unscattered light, as every other method reports it. The sum, and so
 * the balance, is unchanged. */
static void delta_m_totals(const ppb_scene *scaled, const ppb_scene *exact, ppb_totals *t)
{
    double bs[PPB_NSURF], be[PPB_NSURF];
    ppb_ballistic_faces(scaled, bs);
    ppb_ballistic_faces(exact, be);
    t->R += bs[PPB_S1] - be[PPB_S1];
    t->T += bs[PPB_S2] - be[PPB_S2];
    t->sides += bs[PPB_S3] + bs[PPB_S4] - be[PPB_S3] - be[PPB_S4];
    t->ballistic = be[PPB_S1] + be[PPB_S2] + be[PPB_S3] + be[PPB_S4];
}

/* Absorption, the radiance check and the totals of the converged field rad, whose exit march
 * out holds; exact is the unscaled scene (delta-M: st->delta_f > 0) or cfg's own. */
static int finish_result(rte_solver *s, const ppb_config *cfg, const ppb_scene *exact,
                         const double *rad, ppb_result *out, ppb_rte2d_stats *st, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    const ppb_layout *lo = &out->layout;
    double in = ppb_scene_power_in(sc);
    st->absorbed_beam = s->absorbed_beam / in;
    st->absorbed_scattered = ppb_rte_absorbed_scattered(&s->G, rad) / in;
    if (ppb_radiance_check(cfg->name, out, NULL, err))
        return -1;
    memset(out->se, 0, lo->ncells * sizeof *out->se);
    ppb_bin_totals(sc, lo, out->radiance, &out->totals);
    /* R, T, sides from the cell field at the boundaries (rte2d_grid.h), as ppslab. */
    double fl[4];
    ppb_rte_boundary_flux(&s->G, rad, fl);
    out->totals.R = fl[PPB_S1] / in;
    out->totals.T = fl[PPB_S2] / in;
    out->totals.sides = (fl[PPB_S3] + fl[PPB_S4]) / in;
    out->totals.absorbed = st->absorbed_beam + st->absorbed_scattered;
    out->totals.absorbed_tracked = 1;
    if (st->delta_f > 0.0)
        delta_m_totals(sc, exact, &out->totals);
    return ppb_totals_check(cfg->name, out, err);
}

static void print_run(const ppb_config *cfg, const ppb_rte2d_stats *st,
                      const ppb_rte2d_study *study)
{
    char clip[64] = "";
    if (st->clipped > 0.0) /* the series' negative lobes (phase.h): said, not silent */
        snprintf(clip, sizeof clip, " (negative phase set to 0: %.2g of a row)", st->clipped);
    fprintf(stderr,
            "%s: rte2d: %d nodes x %d cells, %d sweeps (%.2f s each), residual %.2g, "
            "refinement study to K = %d (%d sweeps, %.1f s), delta-M f %.3g%s, %.1f s\n",
            cfg->name, st->nodes, st->cells, st->sweeps,
            st->sweeps ? st->t_sweeps / st->sweeps : 0.0, st->resid,
            st->record_rungs ? study->K[st->record_rungs - 1] : 0, st->record_sweeps, st->t_record,
            st->delta_f, clip, st->t_total);
}

/* The solve of a converged or K-step run on the config cfg (under delta-M the scaled one), the
 * cells integrating ph (NULL: HG of cfg's g), the beam's first scattering along the exit rays
 * with phase g_ss and weight ss_w. */
static int rte2d_solve(ppb_run_ctx *ctx, const ppb_config *cfg, const pp_phase_fn *ph, double g_ss,
                       double ss_w, ppb_result *out, ppb_rte2d_stats *stats, ppb_err *err);

int ppb_rte2d_run(ppb_run_ctx *ctx, ppb_result *out, ppb_rte2d_stats *stats, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    if (!cfg->rte2d.delta_m)
        return rte2d_solve(ctx, cfg, NULL, cfg->scene.g, 1.0, out, stats, err);
    /* Delta-M (ppb_rte_delta_m): the whole solve on the scaled medium, so the grid, the beam's
     * collisions (attenuated with sigma_t'), I_pp, the walls and the ballistic total are the
     * scaled problem's and its balance closes; the exit rays' first scattering then takes the
     * exact phase, p_g / (1 - f) times sigma_s' = sigma_s p_g (TMS). */
    ppb_config *dc = malloc(sizeof *dc);
    if (!dc)
        return ppb_fail(err, "rte2d: out of memory");
    *dc = *cfg;
    pp_phase_fn ph;
    double f;
    if (cfg->rte2d.delta_m == PPB_RTE_DELTA_M_LEGENDRE) {
        /* the retained function the truncated Legendre series, L = sqrt(2N) unless given */
        int L = cfg->rte2d.delta_m_order > 0 ? cfg->rte2d.delta_m_order
                                             : (int)lround(sqrt(2.0 * cfg->rte2d.directions));
        f = ppb_rte_delta_m_series(&cfg->scene, L, &dc->scene, &ph);
    } else {
        f = ppb_rte_delta_m(&cfg->scene, cfg->rte2d.directions, cfg->rte2d.delta_m_order,
                            &dc->scene);
        ph = (pp_phase_fn){dc->scene.g, 0, {0}};
    }
    ppb_rte2d_stats st;
    int rc = rte2d_solve(ctx, dc, &ph, cfg->scene.g, 1.0 / (1.0 - f), out, &st, err);
    if (stats)
        *stats = st;
    free(dc);
    return rc;
}

static int rte2d_solve(ppb_run_ctx *ctx, const ppb_config *cfg, const pp_phase_fn *ph, double g_ss,
                       double ss_w, ppb_result *out, ppb_rte2d_stats *stats, ppb_err *err)
{
    double t0 = ppb_now();
    const ppb_layout *lo = &out->layout;
    ppb_rte2d_stats st;
    memset(&st, 0, sizeof st);
    st.delta_f = ss_w > 1.0 ? 1.0 - 1.0 / ss_w : 0.0;
    /* The study follows a converged solve where the run writes extra outputs: the result
     * carries it (ppb_result.extra), a sweep point makes none. */
    ppb_rte2d_study *study = NULL;
    if (cfg->rte2d.refinements == 0 && ctx->extras) {
        if (!(study = calloc(1, sizeof *study)))
            return ppb_fail(err, "rte2d: out of memory (refinement study)");
        out->extra = (ppb_result_extra){study, write_study, free};
    }
    ppb_ocl *ocl;
    if (rte_memory_check(cfg, study != NULL, err) || ppb_ctx_ocl(ctx, &ocl, err) ||
        rte_device_check(cfg, study != NULL, (double)ocl->max_alloc, ocl->name, err))
        return -1;
    int nsamp = cfg->samples_dir < 1 ? 1 : cfg->samples_dir;
    size_t planes = (size_t)ppb_bin_sample_count(lo->nsurf, lo->nbins, nsamp);
    rte_solver s;
    rte_exit ex = {0, 0, 0, NULL, NULL, NULL, {0, NULL, NULL}};
    ppb_gmres_basis kb = {0, 0.0, NULL, NULL};
    /* The first-moment correction: `[rte2d] moment`, decided with the cells (ppb_rte_grid_make). */
    int moment = cfg->rte2d.moment;
    int rc0 = solver_init(&s, ocl, cfg, moment, ph, planes, lo->ncells, err);
    if (!rc0 && cfg->rte2d.ims && st.delta_f > 0.0) {
        s.ims_g = g_ss;
        s.ims_albedo = ctx->cfg->scene.albedo;
        s.ims_f = st.delta_f;
    }
    if (rc0 ||
        exit_setup(&s, cfg, lo, nsamp, cfg->samples_seg < 1 ? 1 : cfg->samples_seg, &ex, err)) {
        free(ex.Fx);
        free(ex.bx);
        free(ex.wd);
        ppb_rte_ims_free(&ex.ims);
        solver_free(&s);
        return -1;
    }
    s.G.P.ss_g = g_ss;
    s.G.P.ss_w = ss_w;
    double *rad = malloc(sizeof(double) * s.nvec), *b = malloc(sizeof(double) * s.nvec);
    double *ipp = study ? malloc(sizeof(double) * s.nvec) : NULL; /* kept for the ladder */
    int rc = (rad && b && (!study || ipp)) ? 0 : ppb_fail(err, "rte2d: out of memory");
    if (!rc)
        rc = solve_field(&s, cfg, rad, b, ipp, study ? &kb : NULL, &st, err);
    double te = ppb_now();
    if (!rc)
        rc = exit_march(&s, cfg, &ex, rad, lo, out->radiance, err);
    st.t_exit = ppb_now() - te;
    if (!rc)
        rc = finish_result(&s, cfg, &ctx->cfg->scene, rad, out, &st, err);
    st.nodes = s.G.nnodes;
    st.cells = s.G.nc;
    st.clipped = s.G.clipped;
    st.sweeps = s.sweeps;
    st.t_sweeps = s.t_sweeps;
    double tr = ppb_now();
    if (!rc && study) {
        rc = record_refinements(&s, cfg, lo, rad, ipp, b, &kb, study, err);
        if (rc)
            study->n = 0;
        st.record_rungs = study->n;
        st.record_sweeps = s.sweeps - st.sweeps;
        st.t_record = ppb_now() - tr;
    }
    st.t_total = ppb_now() - t0;
    if (!rc && !ctx->quiet)
        print_run(cfg, &st, study);
    free(kb.V);
    free(kb.H);
    free(ipp);
    free(ex.Fx);
    free(ex.bx);
    free(ex.wd);
    ppb_rte_ims_free(&ex.ims);
    free(rad);
    free(b);
    solver_free(&s);
    if (stats)
        *stats = st;
    return rc;
}

int ppb_rte2d_check(const ppb_config *cfg, ppb_err *err)
{
    if (ppb_scene_lit_line(&cfg->scene))
        return ppb_config_key_fail(cfg, "light", "width", err,
                                   "rte2d: a line searchlight (width = 0) is refused: the beam's "
                                   "first scattering is integrated over cells, where a line is a "
                                   "delta; use a strip (width > 0)");
    /* Every run needs the solve and the exit march (the refinement study's vectors, which a
     * converged `run` adds, are checked again when it runs). */
    return rte_memory_check(cfg, 0, err);
}

int ppb_method_rte2d(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return ppb_rte2d_run(ctx, out, NULL, err);
}
