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

static int alloc_common(const ppb_scene *sc, int nsamp, int nalb, ppb_march_tables *t, ppb_err *err)
{
    memset(t, 0, sizeof *t);
    t->nsamp = nsamp;
    t->ndir = nsurfaces(sc) * sc->ntheta * sc->nphi * nsamp * nsamp;
    t->nalb = nalb;
    t->alb0 = sc->albedo;
    t->alb_h = 1.0;
    t->ntau = 2;
    t->tau0 = sc->sigma_t * sc->height;
    t->tau_h = t->tau0;
    t->C = calloc((size_t)nalb * t->ndir, sizeof *t->C);
    if (!t->C)
        return ppb_fail(err, "march tables: out of memory");
    return 0;
}

int ppb_march_tables_ss(const ppb_scene *sc, int nsamp, ppb_march_tables *t, ppb_err *err)
{
    if (alloc_common(sc, nsamp, 1, t, err))
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

/* Tables of one albedo node. A is [ndir][ne] (A_k(w)), r0 per direction. */
static void fill_node(ppb_march_tables *t, int node, const double *A, const double *r0, int ne,
                      const double *lambda, const double *tau_ref, double lin, int want_s,
                      double *E, double *A2)
{
    size_t off = (size_t)node * t->ndir * t->ntau;
    /* E[i][k] = e_k(tau_i) */
    for (int i = 0; i < t->ntau; i++)
        for (int k = 0; k < ne; k++)
            E[(size_t)i * ne + k] = exp(lambda[k] * (i * t->tau_h - tau_ref[k]));
    /* Paper Eq. 15: R[dir][i] = sum_k A[dir][k] e_k(tau_i), one matrix product. */
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, t->ndir, t->ntau, ne, 1.0, A, ne, E, ne,
                0.0, t->R + off, t->ntau);
    /* alpha = 1: the diffusion mode's isotropic linear part lin tau. */
    if (lin != 0.0)
        for (int dir = 0; dir < t->ndir; dir++)
            for (int i = 0; i < t->ntau; i++)
                t->R[off + (size_t)dir * t->ntau + i] += lin * i * t->tau_h;
    if (!want_s)
        return;
    /* S = sum_k A_k/(lambda_k r0 - 1) [e_k(tau) - e_k(tau*) e^{-delta/r0}]: the first part is
     * a matrix product; modes within 1e-2 of the pole (where that split would cancel) are summed
     * term by term with the stable form instead. */
    const double near = 1e-2;
    for (int dir = 0; dir < t->ndir; dir++)
        for (int k = 0; k < ne; k++) {
            double den = lambda[k] * r0[dir] - 1.0;
            A2[(size_t)dir * ne + k] = fabs(den) < near ? 0.0 : A[(size_t)dir * ne + k] / den;
        }
    double *S = t->S + off;
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, t->ndir, t->ntau, ne, 1.0, A2, ne, E, ne,
                0.0, S, t->ntau);
    for (int dir = 0; dir < t->ndir; dir++) {
        double r = r0[dir], *row = S + (size_t)dir * t->ntau;
        if (fabs(r) < 1e-12) {
            /* A horizontal ray keeps its tau: S = -R. */
            for (int i = 0; i < t->ntau; i++)
                row[i] = -t->R[off + (size_t)dir * t->ntau + i];
            continue; /* (the linear part included: R holds it) */
        }
        double tau_star = r > 0.0 ? t->tau0 : 0.0;
        int i_star = r > 0.0 ? t->ntau - 1 : 0;
        double c_far = 0.0;
        for (int k = 0; k < ne; k++)
            c_far += A2[(size_t)dir * ne + k] * E[(size_t)i_star * ne + k];
        for (int i = 0; i < t->ntau; i++) {
            double tau = i * t->tau_h, delta = tau_star - tau;
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
    double alo = sc->albedo, ahi = sc->albedo;
    if (sc->geometry == PPB_GEOM_TUBE && sc->step == PPB_STEP_ALBEDO) {
        alo = fmin(sc->albedo, sc->albedo_right);
        ahi = fmax(sc->albedo, sc->albedo_right);
    }
    /* One albedo throughout: one node is exact; otherwise pp->albedos nodes over the range. */
    int nalb = ahi > alo ? (pp->albedos < 2 ? 2 : pp->albedos) : 1;
    if (alloc_common(sc, nsamp, nalb, t, err))
        return -1;
    t->alb0 = alo;
    t->alb_h = nalb > 1 ? (ahi - alo) / (nalb - 1) : 1.0;
    int nint = (int)ceil(t->tau0 * (tau_per_mfp < 1 ? 1 : tau_per_mfp) - 1e-9);
    t->ntau = (nint < 1 ? 1 : nint) + 1;
    t->tau_h = t->tau0 / (t->ntau - 1);
    size_t tsize = (size_t)nalb * t->ndir * t->ntau;
    int want_s = pp->table == PPB_TABLE_S;
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
    pp_solution *first = NULL; /* its phase matrix serves every albedo node */
    int rc = 0;
    for (int node = 0; node < nalb && rc == 0; node++) {
        double alb = t->alb0 + node * t->alb_h;
        double *C = t->C + (size_t)node * t->ndir;
        if (alb <= 0.0) {
            /* No scattering: no diffuse field; sigma_s = 0 zeroes the source anyway. */
            for (int dir = 0; dir < t->ndir; dir++)
                C[dir] = beam_phase(sc, wdir + 3 * dir);
            continue;
        }
        pp_params prm = {.tau0 = t->tau0,
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
            E = malloc((size_t)t->ntau * nm * sizeof *E);
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
        fill_node(t, node, A, r0, ne, lambda, tau_ref, lin, want_s, E, A2);
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
