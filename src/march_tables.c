/* march_tables.c: builds the R and S tables and the beam coefficients (march_tables.h). */
#include "march_tables.h"

/* ppsolver.h first: cblas.h pulls in complex.h, whose macro I would break its prototypes. */
#include "ppsolver.h"

#include <cblas.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../kernels/march_params.h"

static int nsurfaces(const ppb_scene *sc)
{
    return sc->geometry == PPB_GEOM_TUBE ? 4 : 2;
}

/* Direction sample `dir` in the table order of ppb_march_dir_index. */
static void table_dir(const ppb_scene *sc, int nsamp, int dir, double w[3])
{
    int nbins = sc->ntheta * sc->nphi, per_bin = nsamp * nsamp;
    int surf = dir / (nbins * per_bin), bin = dir / per_bin % nbins, ab = dir % per_bin;
    ppb_march_dir(surf, bin, ab / nsamp, ab % nsamp, nsamp, sc->ntheta, sc->nphi, &w[0], &w[1],
                  &w[2]);
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
    int directions, modes, want_s, nalb, ncols, ntau[PPB_MARCH_MAX_COLS];
    double g, theta_deg, height, alb0, alb_h, sigma_t[PPB_MARCH_MAX_COLS];
} table_key;

/* Columns: the left medium's slab always; the right one's when a density step changes sigma_t
 * (SPEC.md section 1: the step is the vertical plane x = step_x, so each side is one column). */
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
    t->ndir = nsurfaces(sc) * sc->ntheta * sc->nphi * k->nsamp * k->nsamp;
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
    t->C = calloc((size_t)t->ncols * t->nalb * t->ndir, sizeof *t->C);
    if (!t->C)
        return ppb_fail(err, "march tables: out of memory");
    return 0;
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

/* Tables of one (column, albedo node) block: R and S point at its [ndir][ntau] rows. A is
 * [ndir][ne] (A_k(w)), r0 per direction. */
static void fill_node(int ndir, const ppb_march_col *col, double *R, double *S, const double *A,
                      const double *r0, int ne, const double *lambda, const double *tau_ref,
                      double lin, double *E, double *A2)
{
    int ntau = col->ntau;
    /* E[i][k] = e_k(tau_i) */
    for (int i = 0; i < ntau; i++)
        for (int k = 0; k < ne; k++)
            E[(size_t)i * ne + k] = exp(lambda[k] * (i * col->tau_h - tau_ref[k]));
    /* Paper Eq. 15: R[dir][i] = sum_k A[dir][k] e_k(tau_i), one matrix product. */
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, ndir, ntau, ne, 1.0, A, ne, E, ne, 0.0, R,
                ntau);
    /* alpha = 1: the diffusion mode's isotropic linear part lin tau. */
    if (lin != 0.0)
        for (int dir = 0; dir < ndir; dir++)
            for (int i = 0; i < ntau; i++)
                R[(size_t)dir * ntau + i] += lin * i * col->tau_h;
    if (!S)
        return;
    /* S = sum_k A_k/(lambda_k r0 - 1) [e_k(tau) - e_k(tau*) e^{-delta/r0}]: the first part is
     * a matrix product; modes within 1e-2 of the pole (where that split would cancel) are summed
     * term by term with the stable form instead. */
    const double near = 1e-2;
    for (int dir = 0; dir < ndir; dir++)
        for (int k = 0; k < ne; k++) {
            double den = lambda[k] * r0[dir] - 1.0;
            A2[(size_t)dir * ne + k] = fabs(den) < near ? 0.0 : A[(size_t)dir * ne + k] / den;
        }
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, ndir, ntau, ne, 1.0, A2, ne, E, ne, 0.0, S,
                ntau);
    for (int dir = 0; dir < ndir; dir++) {
        double r = r0[dir], *row = S + (size_t)dir * ntau;
        if (fabs(r) < 1e-12) {
            /* A horizontal ray keeps its tau: S = -R. */
            for (int i = 0; i < ntau; i++)
                row[i] = -R[(size_t)dir * ntau + i];
            continue; /* (the linear part included: R holds it) */
        }
        /* The far face of the column's own slab. */
        double tau_star = r > 0.0 ? col->tau0 : 0.0;
        int i_star = r > 0.0 ? ntau - 1 : 0;
        double c_far = 0.0;
        for (int k = 0; k < ne; k++)
            c_far += A2[(size_t)dir * ne + k] * E[(size_t)i_star * ne + k];
        for (int i = 0; i < ntau; i++) {
            double tau = i * col->tau_h, delta = tau_star - tau;
            double att = exp(-delta / r);
            /* The linear part's S solves r0 S' - S = lin tau: -lin (tau + r0), plus the
             * homogeneous term that zeroes it at tau*. */
            row[i] += -c_far * att - lin * (tau + r) + lin * (tau_star + r) * att;
            for (int k = 0; k < ne; k++) {
                double den = lambda[k] * r - 1.0;
                if (fabs(den) >= near)
                    continue;
                double e_tau = E[(size_t)i * ne + k], e_far = E[(size_t)i_star * ne + k];
                row[i] += A[(size_t)dir * ne + k] * s_term(lambda[k], r, delta, e_tau, e_far * att);
            }
        }
    }
}

int ppb_march_tables_pp(const ppb_scene *sc, const ppb_pp_settings *pp, int nsamp, int tau_per_mfp,
                        ppb_march_tables *t, ppb_err *err)
{
    table_key key = plan(sc, pp, nsamp, tau_per_mfp, 1);
    if (alloc_common(sc, &key, t, err))
        return -1;
    int nalb = t->nalb, ntau_max = 0;
    for (int c = 0; c < t->ncols; c++)
        ntau_max = t->col[c].ntau > ntau_max ? t->col[c].ntau : ntau_max;
    size_t tsize = (size_t)nalb * t->ndir * t->ntau;
    int want_s = key.want_s;
    t->R = calloc(tsize, sizeof *t->R);
    t->S = want_s ? calloc(tsize, sizeof *t->S) : NULL;
    double *r0 = malloc((size_t)t->ndir * sizeof *r0);
    double *wdir = malloc((size_t)t->ndir * 3 * sizeof *wdir);
    if (!t->R || (want_s && !t->S) || !r0 || !wdir) {
        free(r0);
        free(wdir);
        ppb_march_tables_free(t);
        return ppb_fail(err, "march tables: out of memory for %zu entries", tsize);
    }
    for (int dir = 0; dir < t->ndir; dir++) {
        table_dir(sc, nsamp, dir, wdir + 3 * dir);
        r0[dir] = wdir[3 * dir + 1];
    }
    double *A = NULL, *A2 = NULL, *E = NULL, *lambda = NULL, *tau_ref = NULL, *a = NULL;
    pp_solution *first = NULL; /* its phase matrix serves every column and albedo node */
    int rc = 0;
    size_t off = 0; /* of the current (column, albedo node) block in R and S */
    for (int c = 0; c < t->ncols && rc == 0; c++) {
        const ppb_march_col *col = &t->col[c];
        for (int node = 0; node < nalb && rc == 0; node++, off += (size_t)t->ndir * col->ntau) {
            double alb = t->alb0 + node * t->alb_h;
            double *C = t->C + ((size_t)c * nalb + node) * t->ndir;
            if (alb <= 0.0) {
                /* No scattering: no diffuse field; sigma_s = 0 zeroes the source anyway. */
                for (int dir = 0; dir < t->ndir; dir++)
                    C[dir] = beam_phase(sc, wdir + 3 * dir);
                continue;
            }
            pp_params prm = {.tau0 = col->tau0,
                             .albedo = alb,
                             .g = sc->g,
                             .mu0 = cos(sc->theta_deg * PPB_PI / 180.0),
                             .directions = pp->directions};
            pp_solution *sol = NULL;
            if (pp_solve_ex(&prm, first, &sol, NULL, err)) {
                rc = -1;
                break;
            }
            int nm = pp_nmodes(sol);
            int ne = pp->modes > 0 && pp->modes < nm ? pp->modes : nm;
            t->modes_kept = ne;
            if (A && nm != t->nmodes) {
                if (sol != first)
                    pp_free(sol);
                rc = ppb_fail(err, "march tables: the slab solutions disagree on the mode count");
                break;
            }
            t->nmodes = nm;
            if (!A) {
                A = malloc((size_t)t->ndir * nm * sizeof *A);
                A2 = want_s ? malloc((size_t)t->ndir * nm * sizeof *A2) : NULL;
                E = malloc((size_t)ntau_max * nm * sizeof *E);
                lambda = malloc((size_t)nm * sizeof *lambda);
                tau_ref = malloc((size_t)nm * sizeof *tau_ref);
                a = malloc((size_t)nm * sizeof *a);
                if (!A || (want_s && !A2) || !E || !lambda || !tau_ref || !a) {
                    if (sol != first)
                        pp_free(sol);
                    rc = ppb_fail(err, "march tables: out of memory for %d modes", nm);
                    break;
                }
            }
            pp_modes(sol, lambda, tau_ref);
            for (int dir = 0; dir < t->ndir; dir++) {
                double b;
                pp_source_coeffs(sol, wdir + 3 * dir, a, &b);
                /* The slab's J carries its albedo; the march multiplies by the local sigma_s. */
                for (int k = 0; k < ne; k++)
                    A[(size_t)dir * ne + k] = a[k] / alb;
                C[dir] = beam_phase(sc, wdir + 3 * dir) + b / alb;
            }
            double lin = pp_source_linear(sol) / alb;
            if (!first)
                first = sol;
            else
                pp_free(sol);
            fill_node(t->ndir, col, t->R + off, want_s ? t->S + off : NULL, A, r0, ne, lambda,
                      tau_ref, lin, E, A2);
        }
    }
    if (first)
        pp_free(first);
    free(A);
    free(A2);
    free(E);
    free(lambda);
    free(tau_ref);
    free(a);
    free(r0);
    free(wdir);
    if (rc)
        ppb_march_tables_free(t);
    return rc;
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
