/* march_tables.c: builds the R and S tables and the beam coefficients (march_tables.h). */
#include "kernels/ppb_bin_samples.h"
#include "physics/march_tables.h"

/* ppsolver.h first: cblas.h pulls in complex.h, whose macro I would break its prototypes. */
#include "physics/ppsolver.h"

#include <cblas.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/progress.h"
#include "kernels/march_params.h"
#include "kernels/ppb_fresnel.h"

/* Direction sample `dir` in the table order of ppb_bin_sample_index. At n > 1 the
 * tables hold nvar variants of every sample, variant v at dir + v ndir_base: the air-side sample
 * mapped inside by Snell (kernels/ppb_fresnel.h: ppb_inside_dir), mirrored in y when v & 1 and in
 * x when v & 2: the directions of the viewing ray's legs after its reflections (march.cl). */
static void table_dir(const ppb_scene *sc, int nsamp, int dir, double w[3])
{
    int surf, bin, a, b, nbins = ppb_bin_count(sc->ntheta, sc->nphi);
    int nbase =
        ppb_bin_sample_count(ppb_surface_count(sc->geometry == PPB_GEOM_TUBE), nbins, nsamp);
    int var = dir / nbase;
    ppb_bin_sample_split(dir % nbase, nsamp, nbins, &surf, &bin, &a, &b);
    ppb_bin_sample_dir(surf, bin, a, b, nsamp, sc->ntheta, sc->nphi, &w[0], &w[1], &w[2]);
    if (sc->n > 1.0) {
        ppb_inside_dir(surf, sc->n, w);
        if (var & 1)
            w[1] = -w[1];
        if (var & 2)
            w[0] = -w[0];
    }
}

/* Variants of each direction sample in the tables (table_dir): 1 at n = 1; at n > 1 2 in the
 * slab (legs mirrored in y), 4 in the tube (and in x). */
static int table_variants(const ppb_scene *sc)
{
    return sc->n > 1.0 ? (sc->geometry == PPB_GEOM_TUBE ? 4 : 2) : 1;
}

static double beam_phase(const ppb_scene *sc, const double w[3])
{
    double wl[3];
    ppb_scene_light_dir(sc, wl);
    return ppb_hg_phase(sc->g, w[0] * wl[0] + w[1] * wl[1] + w[2] * wl[2]);
}

/* What shapes a build: every input the tables depend on, and nothing else (the cache's key).
 * Zero-filled before it is set, so two keys compare with memcmp. */
typedef struct table_key {
    int with_modes, geometry, ntheta, nphi, nsamp, tau_per_mfp;
    int directions, modes, want_s, nalb, ncols, ntau[PPB_MARCH_MAX_COLS], delta_m, collars;
    double g, theta_deg, height, alb0, alb_h, sigma_t[PPB_MARCH_MAX_COLS], n;
} table_key;

/* Columns: the left medium's slab always; the right one's when a density step changes sigma_t
 * (reference: Medium; the step is the vertical plane x = step_x, so each side is one column). */
static int plan_columns(const ppb_scene *sc, double sigma_t[PPB_MARCH_MAX_COLS])
{
    sigma_t[0] = sc->sigma_t;
    if (sc->geometry == PPB_GEOM_TUBE && sc->step == PPB_STEP_DENSITY &&
        sc->sigma_t_right != sc->sigma_t) {
        sigma_t[1] = sc->sigma_t_right;
        return 2;
    }
    return 1;
}

static table_key plan(const ppb_scene *sc, const ppb_pp_settings *pp, int nsamp, int tau_per_mfp,
                      int with_modes)
{
    table_key k;
    memset(&k, 0, sizeof k);
    k.with_modes = with_modes;
    k.geometry = sc->geometry;
    k.ntheta = sc->ntheta;
    k.nphi = sc->nphi;
    k.nsamp = nsamp;
    k.g = sc->g;
    k.theta_deg = sc->theta_deg;
    k.height = sc->height;
    k.n = sc->n > 1.0 ? sc->n : 1.0;
    k.alb0 = sc->albedo;
    k.alb_h = 1.0;
    k.nalb = 1;
    if (!with_modes) {
        /* ss: no tables; one column whose tau0 only bounds the clamp of tau. */
        k.ncols = 1;
        k.sigma_t[0] = sc->sigma_t;
        k.ntau[0] = 2;
        return k;
    }
    k.tau_per_mfp = tau_per_mfp < 1 ? 1 : tau_per_mfp;
    k.directions = pp->directions;
    k.modes = pp->modes;
    k.delta_m = pp_delta_m_wanted(pp->delta_m, sc->g); /* auto and on alike where it applies */
    k.collars = pp->collars;
    k.want_s = pp->table == PPB_TABLE_S;
    double alo = sc->albedo, ahi = sc->albedo;
    if (sc->geometry == PPB_GEOM_TUBE && sc->step == PPB_STEP_ALBEDO) {
        alo = fmin(sc->albedo, sc->albedo_right);
        ahi = fmax(sc->albedo, sc->albedo_right);
    }
    /* One albedo throughout: one node is exact; otherwise pp->albedos nodes over the range. */
    k.nalb = ahi > alo ? (pp->albedos < 2 ? 2 : pp->albedos) : 1;
    k.alb0 = alo;
    k.alb_h = k.nalb > 1 ? (ahi - alo) / (k.nalb - 1) : 1.0;
    k.ncols = plan_columns(sc, k.sigma_t);
    for (int c = 0; c < k.ncols; c++) {
        int nint = (int)ceil(k.sigma_t[c] * sc->height * k.tau_per_mfp - 1e-9);
        k.ntau[c] = (nint < 1 ? 1 : nint) + 1;
    }
    return k;
}

static int alloc_common(const ppb_scene *sc, const table_key *k, ppb_march_tables *t, ppb_err *err)
{
    memset(t, 0, sizeof *t);
    t->nsamp = k->nsamp;
    t->nvar = k->with_modes ? table_variants(sc) : 1;
    t->ndir = t->nvar * ppb_bin_sample_count(ppb_surface_count(sc->geometry == PPB_GEOM_TUBE),
                                             ppb_bin_count(sc->ntheta, sc->nphi), k->nsamp);
    t->nalb = k->nalb;
    t->alb0 = k->alb0;
    t->alb_h = k->alb_h;
    t->ncols = k->ncols;
    for (int c = 0; c < k->ncols; c++) {
        ppb_march_col *col = &t->col[c];
        col->sigma_t = k->sigma_t[c];
        col->tau0 = k->sigma_t[c] * k->height;
        col->ntau = k->ntau[c];
        col->tau_h = col->tau0 / (col->ntau - 1);
        t->ntau += col->ntau;
    }
    /* At n > 1 the upward beam's coefficients follow the downward one's (march_tables.h). */
    t->C = calloc((size_t)(t->nvar > 1 ? 2 : 1) * t->ncols * t->nalb * t->ndir, sizeof *t->C);
    if (!t->C)
        return ppb_fail(err, "march tables: out of memory");
    return 0;
}

double ppb_march_tables_bytes(const ppb_scene *sc, const ppb_pp_settings *pp, int nsamp,
                              int tau_per_mfp, int with_modes, double *tables)
{
    table_key k = plan(sc, pp, nsamp, tau_per_mfp, with_modes);
    int nvar = with_modes ? table_variants(sc) : 1;
    double ndir = nvar * ppb_bin_sample_count(ppb_surface_count(sc->geometry == PPB_GEOM_TUBE),
                                              ppb_bin_count(sc->ntheta, sc->nphi), k.nsamp);
    double ntau = 0.0, ntau_max = 0.0;
    for (int c = 0; c < k.ncols; c++) {
        ntau += k.ntau[c];
        ntau_max = k.ntau[c] > ntau_max ? k.ntau[c] : ntau_max;
    }
    double d = sizeof(double), coef = (nvar > 1 ? 2 : 1) * k.ncols * k.nalb * ndir * d;
    if (!with_modes) {
        *tables = coef;
        return coef;
    }
    double n = pp->directions, m = 2.0 * n; /* solver cells per hemisphere, and modes */
    double tab = (k.want_s ? 2.0 : 1.0) * k.nalb * ndir * ntau * d;
    double scratch = (ndir * 4.0 + (k.want_s ? 2.0 : 1.0) * ndir * m + ntau_max * m) * d;
    *tables = tab + coef;
    return tab + coef + scratch + 24.0 * n * n * d;
}

double ppb_march_tables_work(const ppb_scene *sc, const ppb_pp_settings *pp, int nsamp,
                             int tau_per_mfp, double *solves, double *ndir)
{
    table_key k = plan(sc, pp, nsamp, tau_per_mfp, 1);
    *ndir = table_variants(sc) *
            (double)ppb_bin_sample_count(ppb_surface_count(sc->geometry == PPB_GEOM_TUBE),
                                         ppb_bin_count(sc->ntheta, sc->nphi), k.nsamp);
    double m = 2.0 * pp->directions, work = 0.0;
    *solves = 0.0;
    for (int c = 0; c < k.ncols; c++) {
        /* a block: its slab solve (eigenproblem and boundary systems, about 10 m^3), the mode
         * coefficients of every direction (m^2 each), R and S (ndir x ntau x m each) */
        work += k.nalb *
                (10.0 * m * m * m + *ndir * m * m + (k.want_s ? 3.0 : 1.0) * *ndir * k.ntau[c] * m);
        *solves += k.nalb;
    }
    return work;
}

int ppb_march_tables_ss(const ppb_scene *sc, int nsamp, ppb_march_tables *t, ppb_err *err)
{
    table_key k = plan(sc, NULL, nsamp, 0, 0);
    if (alloc_common(sc, &k, t, err))
        return -1;
    for (int dir = 0; dir < t->ndir; dir++) {
        double w[3];
        table_dir(sc, nsamp, dir, w);
        t->C[dir] = beam_phase(sc, w);
    }
    return 0;
}

void ppb_march_tables_free(ppb_march_tables *t)
{
    free(t->R);
    free(t->S);
    free(t->C);
    t->R = t->S = t->C = NULL;
}

/* One mode's S-table term s_k(tau) = -(delta/r0) e_k(tau) phi(z), z = (lambda - 1/r0) delta,
 * evaluated from e_k(tau) and e_k(tau*) e^{-delta/r0} (both <= 1) so nothing overflows and
 * nothing is divided by lambda r0 - 1. */
static double s_term(double lambda, double r0, double delta, double e_tau, double e_far_att)
{
    double z = (lambda - 1.0 / r0) * delta, scale = delta / r0;
    if (fabs(z) < 1e-300)
        return -scale * e_tau;
    if (z <= 0.0)
        return -scale * e_tau * expm1(z) / z;
    return -scale * e_far_att * (-expm1(-z)) / z;
}

/* One pp build in progress. The scratch is sized by the first slab solution's mode count and
 * reused by every (column, albedo node) block, and the first solution is kept because its phase
 * matrix serves every later solve (pp_solve_ex's share). */
typedef struct pp_build {
    const ppb_scene *sc;
    const ppb_pp_settings *pp;
    ppb_march_tables *t;
    int want_s, ntau_max;
    double *wdir;       /* [ndir][3] direction samples */
    double *r0;         /* [ndir] their slope w_y against the slab */
    pp_solution *first; /* NULL until a block with scattering is solved */
    double *A, *A2;     /* [ndir][ne]: A_k(w), and A_k / (lambda_k r0 - 1) for S (NULL without) */
    double *E;          /* [ntau_max][ne]: e_k at the tau nodes of the current column */
    double *lambda, *tau_ref, *a; /* [nmodes]: the modes, and pp_source_coeffs' output */
    int *pole;                    /* [nmodes]: s_row's modes near the pole */
} pp_build;

/* E[i][k] = e_k(tau_i) at the column's tau nodes: the factor both matrix products share. */
static void fill_exponentials(const pp_build *b, const ppb_march_col *col, int ne)
{
    for (int i = 0; i < col->ntau; i++)
        for (int k = 0; k < ne; k++)
            b->E[(size_t)i * ne + k] = exp(b->lambda[k] * (i * col->tau_h - b->tau_ref[k]));
}

/* Paper Eq. 15: R[dir][i] = sum_k A[dir][k] e_k(tau_i), one matrix product. */
static void fill_r(const pp_build *b, const ppb_march_col *col, double *R, int ne, double lin)
{
    int ndir = b->t->ndir, ntau = col->ntau;
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, ndir, ntau, ne, 1.0, b->A, ne, b->E, ne,
                0.0, R, ntau);
    /* alpha = 1: the diffusion mode's isotropic linear part lin tau. */
    if (lin != 0.0)
        for (int dir = 0; dir < ndir; dir++)
            for (int i = 0; i < ntau; i++)
                R[(size_t)dir * ntau + i] += lin * i * col->tau_h;
}

/* Modes within this distance of the pole lambda r0 = 1 leave the matrix product: there the
 * split of S into e_k(tau) and its far-face term would cancel, so they take s_term instead. */
#define S_NEAR_POLE 1e-2

/* Completes one direction's S row, which the matrix product of fill_s left holding
 * sum_k A2_k e_k(tau) over the modes away from the pole. */
static void s_row(const pp_build *b, const ppb_march_col *col, int dir, int ne, double lin,
                  const double *R_row, double *row)
{
    int ntau = col->ntau;
    double r = b->r0[dir];
    const double *A = b->A + (size_t)dir * ne, *A2 = b->A2 + (size_t)dir * ne, *E = b->E;
    if (fabs(r) < 1e-12) {
        /* A horizontal ray keeps its tau: S = -R (the linear part included: R holds it). */
        for (int i = 0; i < ntau; i++)
            row[i] = -R_row[i];
        return;
    }
    /* The far face of the column's own slab, where this member of S vanishes. */
    double tau_star = r > 0.0 ? col->tau0 : 0.0;
    int i_star = r > 0.0 ? ntau - 1 : 0;
    double c_far = 0.0;
    /* The modes near the pole, found once per direction (in mode order, as the sum takes
     * them): scanning all ne modes at every tau node cost ndir x ntau x ne tests a block, as
     * much as the matrix products themselves. */
    int npole = 0, *pole = b->pole;
    for (int k = 0; k < ne; k++) {
        c_far += A2[k] * E[(size_t)i_star * ne + k];
        if (fabs(b->lambda[k] * r - 1.0) < S_NEAR_POLE)
            pole[npole++] = k;
    }
    for (int i = 0; i < ntau; i++) {
        double tau = i * col->tau_h, delta = tau_star - tau;
        double att = exp(-delta / r);
        /* The linear part's S solves r0 S' - S = lin tau: -lin (tau + r0), plus the
         * homogeneous term that zeroes it at tau*. */
        row[i] += -c_far * att - lin * (tau + r) + lin * (tau_star + r) * att;
        for (int q = 0; q < npole; q++) {
            int k = pole[q];
            double e_tau = E[(size_t)i * ne + k], e_far = E[(size_t)i_star * ne + k];
            row[i] += A[k] * s_term(b->lambda[k], r, delta, e_tau, e_far * att);
        }
    }
}

/* S = sum_k A_k/(lambda_k r0 - 1) [e_k(tau) - e_k(tau*) e^{-delta/r0}]: the first part is a
 * matrix product over the modes away from the pole; s_row adds the rest. */
static void fill_s(const pp_build *b, const ppb_march_col *col, const double *R, double *S, int ne,
                   double lin)
{
    int ndir = b->t->ndir, ntau = col->ntau;
    for (int dir = 0; dir < ndir; dir++)
        for (int k = 0; k < ne; k++) {
            double den = b->lambda[k] * b->r0[dir] - 1.0;
            size_t dk = (size_t)dir * ne + k;
            b->A2[dk] = fabs(den) < S_NEAR_POLE ? 0.0 : b->A[dk] / den;
        }
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, ndir, ntau, ne, 1.0, b->A2, ne, b->E, ne,
                0.0, S, ntau);
    for (int dir = 0; dir < ndir && !ppb_interrupted(); dir++)
        s_row(b, col, dir, ne, lin, R + (size_t)dir * ntau, S + (size_t)dir * ntau);
}

/* Allocates R, S and the direction samples; on failure frees what it took and the tables. */
static int build_begin(pp_build *b, const table_key *key, ppb_err *err)
{
    ppb_march_tables *t = b->t;
    b->want_s = key->want_s;
    for (int c = 0; c < t->ncols; c++)
        b->ntau_max = t->col[c].ntau > b->ntau_max ? t->col[c].ntau : b->ntau_max;
    size_t tsize = (size_t)t->nalb * t->ndir * t->ntau;
    t->R = calloc(tsize, sizeof *t->R);
    t->S = b->want_s ? calloc(tsize, sizeof *t->S) : NULL;
    b->r0 = malloc((size_t)t->ndir * sizeof *b->r0);
    b->wdir = malloc((size_t)t->ndir * 3 * sizeof *b->wdir);
    if (!t->R || (b->want_s && !t->S) || !b->r0 || !b->wdir) {
        free(b->r0);
        free(b->wdir);
        ppb_march_tables_free(t);
        return ppb_fail(err, "march tables: out of memory for %zu entries", tsize);
    }
    for (int dir = 0; dir < t->ndir; dir++) {
        table_dir(b->sc, key->nsamp, dir, b->wdir + 3 * dir);
        b->r0[dir] = b->wdir[3 * dir + 1];
    }
    return 0;
}

/* Frees the scratch, and the tables too when the build failed. */
static int build_end(pp_build *b, int rc)
{
    if (b->first)
        pp_free(b->first);
    double *bufs[] = {b->A, b->A2, b->E, b->lambda, b->tau_ref, b->a, b->r0, b->wdir};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++)
        free(bufs[i]);
    free(b->pole);
    if (rc)
        ppb_march_tables_free(b->t);
    return rc;
}

/* The scratch is sized for the most modes a block of these directions can have (cap:
 * pp_mode_capacity), not the first block's count: an albedo range that reaches 1 holds a
 * conservative block with one mode fewer (the degenerate pair at lambda = 0 is one mode), and
 * each block uses its own count. Every block must have the same capacity. */
static int adopt_mode_count(pp_build *b, int nm, ppb_err *err)
{
    ppb_march_tables *t = b->t;
    if (b->A && nm != t->nmodes)
        return ppb_fail(err, "march tables: the slab solutions disagree on the mode capacity");
    t->nmodes = nm;
    if (b->A)
        return 0;
    b->A = malloc((size_t)t->ndir * nm * sizeof *b->A);
    b->A2 = b->want_s ? malloc((size_t)t->ndir * nm * sizeof *b->A2) : NULL;
    b->E = malloc((size_t)b->ntau_max * nm * sizeof *b->E);
    b->lambda = malloc((size_t)nm * sizeof *b->lambda);
    b->tau_ref = malloc((size_t)nm * sizeof *b->tau_ref);
    b->a = malloc((size_t)nm * sizeof *b->a);
    b->pole = malloc((size_t)nm * sizeof *b->pole);
    if (!b->A || (b->want_s && !b->A2) || !b->E || !b->lambda || !b->tau_ref || !b->a || !b->pole)
        return ppb_fail(err, "march tables: out of memory for %d modes", nm);
    return 0;
}

/* A_k(w) and C(w) of one block from the slab solution. The slab's J carries its albedo; the
 * march multiplies by the local sigma_s, hence the division by alb. */
static void block_coeffs(pp_build *b, const pp_solution *sol, double alb, int ne, double *C,
                         double *Cup)
{
    for (int dir = 0; dir < b->t->ndir && !ppb_interrupted(); dir++) {
        const double *w = b->wdir + 3 * dir;
        double bcoef;
        if (Cup) {
            /* n > 1: the solver's beams, D's series and 1 - F entry included (ppsolver.h). */
            double up;
            pp_source_beams(sol, w, b->a, &bcoef, &up);
            C[dir] = bcoef / alb;
            Cup[dir] = up / alb;
        } else {
            pp_source_coeffs(sol, w, b->a, &bcoef);
            C[dir] = beam_phase(b->sc, w) + bcoef / alb;
        }
        for (int k = 0; k < ne; k++)
            b->A[(size_t)dir * ne + k] = b->a[k] / alb;
    }
}

/* The slab solution of one block, sharing the first solution's phase matrix. */
static int solve_block(pp_build *b, double tau0, double alb, pp_solution **sol, ppb_err *err)
{
    const ppb_scene *sc = b->sc;
    pp_params prm = {.tau0 = tau0,
                     .albedo = alb,
                     .g = sc->g,
                     .mu0 = ppb_scene_cos_theta_l(sc),
                     .directions = b->pp->directions};
    /* delta-M changes the diffuse field only (ppsolver.h): J stays the source of the true
     * medium, attenuated by the true sigma_t along the march, with the exact beam */
    return pp_solve_collars(&prm, sc->n > 1.0 ? sc->n : 1.0, b->pp->delta_m, b->pp->collars,
                            b->first, sol, NULL, err);
}

/* The (column c, albedo node) block: C, and the R and S rows (layout: march_params.h). */
static int build_block(pp_build *b, int c, int node, ppb_err *err)
{
    ppb_march_tables *t = b->t;
    const ppb_march_col *col = &t->col[c];
    double alb = t->alb0 + node * t->alb_h;
    double *C = t->C + ppb_march_coef_offset(c, node, t->nalb, t->ndir);
    double *Cup = t->nvar > 1 ? C + (size_t)t->ncols * t->nalb * t->ndir : NULL;
    int ntau[PPB_MARCH_MAX_COLS];
    for (int k = 0; k < t->ncols; k++)
        ntau[k] = t->col[k].ntau;
    size_t off = (size_t)ppb_march_table_offset(ntau, c, node, t->nalb, t->ndir);
    if (alb <= 0.0) {
        /* No scattering: no diffuse field; sigma_s = 0 zeroes the source anyway. */
        for (int dir = 0; dir < t->ndir; dir++)
            C[dir] = beam_phase(b->sc, b->wdir + 3 * dir);
        return 0;
    }
    pp_solution *sol = NULL;
    if (solve_block(b, col->tau0, alb, &sol, err))
        return -1;
    int nm = pp_nmodes(sol);
    int ne = b->pp->modes > 0 && b->pp->modes < nm ? b->pp->modes : nm;
    t->modes_kept = ne;
    if (adopt_mode_count(b, pp_mode_capacity(sol), err)) {
        if (sol != b->first)
            pp_free(sol);
        return -1;
    }
    pp_modes(sol, b->lambda, b->tau_ref);
    /* One BLAS thread for the coefficients: a matrix-vector product per table direction (16400
     * a block at n > 1 in the tube), each too small to share, where every call woke and then
     * waited on OpenBLAS's other threads (sched_yield: on a loaded machine, minutes a build).
     * A product's elements are each one thread's dot product either way: the same bits. */
    int threads = openblas_get_num_threads();
    openblas_set_num_threads(1);
    block_coeffs(b, sol, alb, ne, C, Cup);
    openblas_set_num_threads(threads);
    double lin = pp_source_linear(sol) / alb;
    if (!b->first)
        b->first = sol;
    else
        pp_free(sol);
    if (ppb_interrupted()) /* block_coeffs stopped early: A is incomplete */
        return ppb_fail(err, "march tables: interrupted");
    fill_exponentials(b, col, ne);
    fill_r(b, col, t->R + off, ne, lin);
    if (b->want_s)
        fill_s(b, col, t->R + off, t->S + off, ne, lin);
    return 0;
}

int ppb_march_tables_pp(const ppb_scene *sc, const ppb_pp_settings *pp, int nsamp, int tau_per_mfp,
                        ppb_march_tables *t, ppb_err *err)
{
    table_key key = plan(sc, pp, nsamp, tau_per_mfp, 1);
    if (alloc_common(sc, &key, t, err))
        return -1;
    pp_build b = {.sc = sc, .pp = pp, .t = t};
    if (build_begin(&b, &key, err))
        return -1;
    int rc = 0;
    /* SIGINT or SIGTERM: checked between slab solves and within their direction loops. */
    for (int c = 0; c < t->ncols && rc == 0; c++)
        for (int node = 0; node < t->nalb && rc == 0; node++)
            rc = ppb_interrupted() ? ppb_fail(err, "march tables: interrupted")
                                   : build_block(&b, c, node, err);
    if (rc == 0 && ppb_interrupted()) /* fill_s stopped early */
        rc = ppb_fail(err, "march tables: interrupted");
    return build_end(&b, rc);
}

/* The cache (march_tables.h): one slot per kind, [0] ss, [1] pp. */
typedef struct cache_slot {
    int valid;
    table_key key;
    ppb_march_tables tab;
} cache_slot;

struct ppb_march_cache {
    cache_slot slot[2];
    long hits, builds;
};

ppb_march_cache *ppb_march_cache_new(void)
{
    return calloc(1, sizeof(ppb_march_cache));
}

void ppb_march_cache_free(ppb_march_cache *c)
{
    if (!c)
        return;
    for (int i = 0; i < 2; i++)
        if (c->slot[i].valid)
            ppb_march_tables_free(&c->slot[i].tab);
    free(c);
}

int ppb_march_cache_tables(ppb_march_cache *c, const ppb_scene *sc, const ppb_pp_settings *pp,
                           int nsamp, int tau_per_mfp, int with_modes, const ppb_march_tables **out,
                           ppb_err *err)
{
    with_modes = with_modes != 0;
    table_key key = plan(sc, pp, nsamp, tau_per_mfp, with_modes);
    cache_slot *s = &c->slot[with_modes];
    if (s->valid && memcmp(&s->key, &key, sizeof key) == 0) {
        c->hits++;
        *out = &s->tab;
        return 0;
    }
    if (s->valid)
        ppb_march_tables_free(&s->tab);
    s->valid = 0;
    int rc = with_modes ? ppb_march_tables_pp(sc, pp, nsamp, tau_per_mfp, &s->tab, err)
                        : ppb_march_tables_ss(sc, nsamp, &s->tab, err);
    if (rc)
        return -1;
    c->builds++;
    s->valid = 1;
    s->key = key;
    *out = &s->tab;
    return 0;
}

void ppb_march_cache_stats(const ppb_march_cache *c, long *hits, long *builds)
{
    *hits = c->hits;
    *builds = c->builds;
}
