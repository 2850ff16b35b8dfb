/* ppsolver.c: eigen solution, particular solution, boundary conditions and evaluation of the
 * plane-parallel slab (ppsolver.h; paper Eq. 8-12). Matrices are column-major for LAPACK. */
#include "physics/ppsolver.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/clock.h"
#include "base/memory.h"
#include "base/progress.h"
#include "base/quadrature.h"
#include "kernels/ppb_fresnel.h"
#include "model/config.h"
#include "physics/directions.h"
#include "physics/phase.h"

_Static_assert(PP_DELTA_M_OFF == (int)PPB_DELTA_M_OFF && PP_DELTA_M_ON == (int)PPB_DELTA_M_ON &&
                   PP_DELTA_M_AUTO == (int)PPB_DELTA_M_AUTO,
               "[pp] delta_m's values are the solver's");

#define RESONANCE_GAP    1e-7  /* |lambda mu0 - 1| below this moves mu0 */
#define CONSERVATIVE_EPS 1e-13 /* 1 - alpha below this is alpha = 1 */
#define FRESNEL_GAUSS    16    /* Gauss order of a cell's mean reflectance */

struct pp_solution {
    pp_params p; /* mu0 as used */
    pp_dirs dirs;
    int n, m; /* cells per hemisphere, 2n */
    int conservative;
    double *Sa, *Sb; /* phase blocks (phase.h), kept for pp_solve_ex sharing */
    int nmodes;
    double *lambda, *tau_ref; /* [nmodes] */
    double *V;                /* [nmodes][m]: mode vectors times their coefficients */
    double *Z;                /* [m]: particular solution, times exp(-tau/mu0) */
    double c_lin;             /* alpha = 1: coefficient of tau 1 */
    double wL[3];             /* beam direction of travel */
    double R, T, ballistic, absorbed;
    /* n > 1 only (fresnel = 0 at n = 1, and none of this is used) */
    int fresnel;
    double nrel;   /* n inside / outside */
    double mu_air; /* cos theta_L in air */
    double *Rc;    /* [n]: cell-averaged reflectance of up cell i (and its mirror) */
    double *Zu;    /* [m]: the upward beam's particular solution, times U */
    double D, U;   /* the beam's downward and upward series sums (ppsolver.h) */
    double Fb;     /* F of the unscattered beam at either face, from inside */
    double specular, ballistic_top;
    int delta_m; /* PP_DELTA_M_* as asked */
    int collars; /* the partition's collars per hemisphere, 0 = near-square cells */
    double fwd;  /* delta-M: the forward fraction F the cell matrix holds (0: off; ppsolver.h) */
};

/* Work space of one solve (N x N unless stated). */
typedef struct pp_work {
    double *t;       /* [n]: T = C^(1/2) diagonal */
    double *Hp, *Hm; /* H+ and H- */
    double *L;       /* Cholesky factor of H- */
    double *Y, *ev;  /* eigenvectors of L^T H+ L and eigenvalues lambda^2 */
    double *U, *Vd;  /* u = T L y and v = lambda T L^-T y per mode */
    double *F;       /* [m]: cell integrals of p(w . w_L) */
    double *h;       /* [n]: alpha = 1 diffusion mode's h+ */
} pp_work;

static double *dalloc(size_t count)
{
    return calloc(count ? count : 1, sizeof(double));
}

static int check_params(const pp_params *p, ppb_err *err)
{
    if (!(p->tau0 > 0 && p->tau0 <= 1e6))
        return ppb_fail(err, "pp solver: tau0 = %g, need 0 < tau0 <= 1e6", p->tau0);
    if (!(p->albedo >= 0 && p->albedo <= 1))
        return ppb_fail(err, "pp solver: albedo = %g, need 0 <= albedo <= 1", p->albedo);
    if (!(fabs(p->g) < 1))
        return ppb_fail(err, "pp solver: g = %g, need |g| < 1", p->g);
    if (!(p->mu0 > 0 && p->mu0 <= 1))
        return ppb_fail(err,
                        "pp solver: mu0 = cos(theta_L) = %g, need 0 < mu0 <= 1 (light "
                        "must enter the top face)",
                        p->mu0);
    if (p->directions < 2 || p->directions > PP_DIRS_MAX)
        return ppb_fail(err, "pp solver: directions = %d, need 2..%d cells per hemisphere",
                        p->directions, PP_DIRS_MAX);
    return 0;
}

static void work_free(pp_work *w)
{
    free(w->t), free(w->Hp), free(w->Hm), free(w->L), free(w->Y), free(w->ev);
    free(w->U), free(w->Vd), free(w->F), free(w->h);
}

static int work_alloc(pp_work *w, size_t n)
{
    memset(w, 0, sizeof *w);
    w->t = dalloc(n), w->ev = dalloc(n), w->F = dalloc(2 * n), w->h = dalloc(n);
    w->Hp = dalloc(n * n), w->Hm = dalloc(n * n), w->L = dalloc(n * n);
    w->Y = dalloc(n * n), w->U = dalloc(n * n), w->Vd = dalloc(n * n);
    return (w->t && w->ev && w->F && w->h && w->Hp && w->Hm && w->L && w->Y && w->U && w->Vd) ? 0
                                                                                              : -1;
}

void pp_free(pp_solution *s)
{
    if (!s)
        return;
    pp_dirs_free(&s->dirs);
    free(s->Sa), free(s->Sb), free(s->lambda), free(s->tau_ref), free(s->V), free(s->Z);
    free(s->Rc), free(s->Zu);
    free(s);
}

static int solution_alloc(pp_solution *s, ppb_err *err)
{
    size_t n = (size_t)s->n, m = (size_t)s->m;
    s->Sa = dalloc(n * n), s->Sb = dalloc(n * n), s->Z = dalloc(m);
    s->lambda = dalloc(m), s->tau_ref = dalloc(m), s->V = dalloc(m * m);
    if (!s->Sa || !s->Sb || !s->Z || !s->lambda || !s->tau_ref || !s->V)
        return ppb_fail(err, "pp solver: out of memory for %d directions", s->n);
    if (s->fresnel) {
        s->Rc = dalloc(n), s->Zu = dalloc(m);
        if (!s->Rc || !s->Zu)
            return ppb_fail(err, "pp solver: out of memory for %d directions", s->n);
    }
    return 0;
}

/* ---- eigen solution (paper Eq. 9-10, reduced by the up/down mirror) ---- */

/* H+- = T (|Omega| E - alpha (Sa +- Sb)) T with T = diag(1 / sqrt(|Omega| k_i)). */
static void build_h(const pp_solution *s, pp_work *w)
{
    size_t n = (size_t)s->n;
    double a = s->p.albedo;
    const double *area = s->dirs.area;
    for (size_t i = 0; i < n; i++)
        w->t[i] = 1.0 / sqrt(area[i] * s->dirs.k[i]);
    for (size_t j = 0; j < n; j++) {
        for (size_t i = 0; i < n; i++) {
            double e = i == j ? area[i] : 0.0, tt = w->t[i] * w->t[j];
            w->Hp[j * n + i] = (e - a * (s->Sa[j * n + i] + s->Sb[j * n + i])) * tt;
            w->Hm[j * n + i] = (e - a * (s->Sa[j * n + i] - s->Sb[j * n + i])) * tt;
        }
    }
}

/* lambda^2 and y from L^T H+ L y = lambda^2 y; then u = T L y, v = lambda T L^-T y. */
static int eigen_modes(const pp_solution *s, pp_work *w, ppb_err *err)
{
    int n = s->n;
    size_t nn = (size_t)n * n;
    memcpy(w->L, w->Hm, nn * sizeof(double));
    if (LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', n, w->L, n) != 0)
        return ppb_fail(err, "pp solver: H- not positive definite (albedo %g, g %g)", s->p.albedo,
                        s->p.g);
    for (int j = 0; j < n; j++) /* zero the upper triangle dpotrf left behind */
        for (int i = 0; i < j; i++)
            w->L[(size_t)j * n + i] = 0.0;
    memcpy(w->Y, w->Hp, nn * sizeof(double));
    cblas_dtrmm(CblasColMajor, CblasRight, CblasLower, CblasNoTrans, CblasNonUnit, n, n, 1.0, w->L,
                n, w->Y, n);
    cblas_dtrmm(CblasColMajor, CblasLeft, CblasLower, CblasTrans, CblasNonUnit, n, n, 1.0, w->L, n,
                w->Y, n);
    for (int j = 0; j < n; j++) /* symmetrise the rounding */
        for (int i = j + 1; i < n; i++)
            w->Y[(size_t)j * n + i] = w->Y[(size_t)i * n + j] =
                0.5 * (w->Y[(size_t)j * n + i] + w->Y[(size_t)i * n + j]);
    if (LAPACKE_dsyevd(LAPACK_COL_MAJOR, 'V', 'L', n, w->Y, n, w->ev) != 0)
        return ppb_fail(err, "pp solver: eigendecomposition failed (n = %d)", n);
    memcpy(w->U, w->Y, nn * sizeof(double));
    memcpy(w->Vd, w->Y, nn * sizeof(double));
    cblas_dtrmm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, n, n, 1.0, w->L,
                n, w->U, n);
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasTrans, CblasNonUnit, n, n, 1.0, w->L, n,
                w->Vd, n);
    for (int k = 0; k < n; k++) {
        w->ev[k] = fmax(w->ev[k], 0.0);
        double lam = sqrt(w->ev[k]);
        for (int i = 0; i < n; i++) {
            w->U[(size_t)k * n + i] *= w->t[i];
            w->Vd[(size_t)k * n + i] *= lam * w->t[i];
        }
    }
    return 0;
}

/* ---- refractive boundaries, n > 1 (ppsolver.h) ---- */

/* Air-side cosine of the inside cosine mu (>= the critical cosine), clamped at grazing. */
static double air_cos(double mu, double nrel)
{
    return sqrt(fmax(0.0, 1.0 - nrel * nrel * (1.0 - mu * mu)));
}

/* R = int F mu dmu / int mu dmu over [lo, hi] (ppsolver.h): F = 1 below the critical cosine
 * mu_c = sqrt(1 - 1/n^2); above it the substitution t = air-side cosine (mu dmu = t dt / n^2)
 * makes the integrand smooth (F(mu) = ppb_fresnel(t, n) by reciprocity), so Gauss-Legendre of
 * order FRESNEL_GAUSS is exact to rounding for practical purposes. */
double pp_fresnel_ring_mean(double lo, double hi, double nr)
{
    double mu_c = sqrt(1.0 - 1.0 / (nr * nr)), x[FRESNEL_GAUSS], wq[FRESNEL_GAUSS];
    ppb_gauss_legendre(FRESNEL_GAUSS, x, wq);
    double num = 0.0, den = 0.5 * (hi * hi - lo * lo);
    if (lo < mu_c) {
        double top = fmin(hi, mu_c);
        num += 0.5 * (top * top - lo * lo);
    }
    double a = fmax(lo, mu_c);
    if (hi > a) {
        double ta = air_cos(a, nr), tb = air_cos(hi, nr), half = 0.5 * (tb - ta);
        for (int j = 0; j < FRESNEL_GAUSS; j++) {
            double t = ta + half * (1.0 + x[j]);
            num += half * wq[j] * ppb_fresnel(t, nr) * t / (nr * nr);
        }
    }
    return fmin(1.0, num / den);
}

/* R_i of every direction cell: the mean over its mu range (the cells are mu rings x phi). */
static void cell_reflectance(pp_solution *s)
{
    for (int i = 0; i < s->n; i++) {
        double lo, hi, plo, phi;
        pp_dirs_bounds(&s->dirs, i, &lo, &hi, &plo, &phi);
        s->Rc[i] = pp_fresnel_ring_mean(lo, hi, s->nrel);
    }
}

/* The refracted beam and the sums of its internal reflections (after avoid_resonance has
 * fixed mu0 inside): E_in, D, U and F_b; the specular total. */
static void beam_series(pp_solution *s)
{
    double mu0 = s->p.mu0, e = exp(-s->p.tau0 / mu0);
    s->specular = ppb_fresnel(s->mu_air, s->nrel);
    s->Fb = ppb_fresnel(mu0, 1.0 / s->nrel);
    double e_in = (1.0 - s->specular) * s->mu_air / mu0;
    s->D = e_in / (1.0 - s->Fb * s->Fb * e * e);
    s->U = s->D * s->Fb * e;
}

/* Z (unit beam) -> D Z, and the upward beam's particular solution U x (Z mirrored). */
static void particular_series(pp_solution *s)
{
    int n = s->n;
    for (int i = 0; i < n; i++) {
        s->Zu[i] = s->U * s->Z[n + i];
        s->Zu[n + i] = s->U * s->Z[i];
    }
    for (int i = 0; i < s->m; i++)
        s->Z[i] *= s->D;
}

/* ---- the beam (paper Sec. 2.2 leaves it out; reference: Methods) ---- */

/* Moves mu0 off any 1/lambda by the discrete-ordinates perturbation (ppsolver.h). */
static void avoid_resonance(pp_solution *s, const pp_work *w)
{
    double mu0 = s->p.mu0;
    for (int k = 0; k < s->n; k++) {
        double lam = sqrt(w->ev[k]);
        if (fabs(lam * mu0 - 1.0) < RESONANCE_GAP) {
            double up = mu0 * (1.0 + 2.0 * RESONANCE_GAP);
            mu0 = up <= 1.0 ? up : mu0 * (1.0 - 2.0 * RESONANCE_GAP);
        }
    }
    s->p.mu0 = mu0;
    double st = sqrt(fmax(0.0, 1.0 - mu0 * mu0));
    s->wL[0] = st, s->wL[1] = -mu0, s->wL[2] = 0.0;
}

/* Z from (E - alpha P + K / mu0) Z = alpha q in the sum/difference form, through the
 * eigenbasis: (H+ H- - mu0^-2) dt = H+ (T r2) - (T r1) / mu0, d = T dt,
 * s = mu0 T (T r2 - H- dt), Z+- = (s +- d) / 2, with r1,2 = alpha (F+ +- F-). */
static void particular(pp_solution *s, pp_work *w)
{
    int n = s->n;
    double mu0 = s->p.mu0, a = s->p.albedo;
    double *tr1 = dalloc(n), *tr2 = dalloc(n), *x = dalloc(n), *y = dalloc(n);
    for (int i = 0; i < n; i++) {
        tr1[i] = w->t[i] * a * (w->F[i] + w->F[n + i]);
        tr2[i] = w->t[i] * a * (w->F[i] - w->F[n + i]);
        x[i] = -tr1[i] / mu0;
    }
    cblas_dsymv(CblasColMajor, CblasLower, n, 1.0, w->Hp, n, tr2, 1, 1.0, x, 1);
    cblas_dtrmv(CblasColMajor, CblasLower, CblasTrans, CblasNonUnit, n, w->L, n, x, 1);
    cblas_dgemv(CblasColMajor, CblasTrans, n, n, 1.0, w->Y, n, x, 1, 0.0, y, 1);
    for (int k = 0; k < n; k++)
        y[k] /= w->ev[k] - 1.0 / (mu0 * mu0);
    cblas_dgemv(CblasColMajor, CblasNoTrans, n, n, 1.0, w->Y, n, y, 1, 0.0, x, 1);
    cblas_dtrsv(CblasColMajor, CblasLower, CblasTrans, CblasNonUnit, n, w->L, n, x, 1);
    /* x = dt; y = T r2 - H- dt */
    memcpy(y, tr2, n * sizeof(double));
    cblas_dsymv(CblasColMajor, CblasLower, n, -1.0, w->Hm, n, x, 1, 1.0, y, 1);
    for (int i = 0; i < n; i++) {
        double d = w->t[i] * x[i], sum = mu0 * w->t[i] * y[i];
        s->Z[i] = 0.5 * (sum + d);
        s->Z[n + i] = 0.5 * (sum - d);
    }
    free(tr1), free(tr2), free(x), free(y);
}

/* ---- boundary conditions (paper Eq. 12) ---- */

/* alpha = 1: h+ = G-^-1 |Omega| k = T L^-T L^-1 T |Omega| k (diffusion mode tau 1 + (h+, -h+)). */
static void diffusion_mode(const pp_solution *s, pp_work *w)
{
    int n = s->n;
    for (int i = 0; i < n; i++)
        w->h[i] = w->t[i] * s->dirs.area[i] * s->dirs.k[i];
    cblas_dtrsv(CblasColMajor, CblasLower, CblasNoTrans, CblasNonUnit, n, w->L, n, w->h, 1);
    cblas_dtrsv(CblasColMajor, CblasLower, CblasTrans, CblasNonUnit, n, w->L, n, w->h, 1);
    for (int i = 0; i < n; i++)
        w->h[i] *= w->t[i];
}

/* Columns of the sum (X+ + X- E) and difference (X+ - X- E) systems; with X+- = (u +- v)/2
 * and E = exp(-lambda tau0). At alpha = 1 column 0 holds the constant and diffusion modes. */
static void bc_matrices(const pp_solution *s, const pp_work *w, double *Ms, double *Md)
{
    int n = s->n;
    for (int k = 0; k < n; k++) {
        double e = exp(-sqrt(w->ev[k]) * s->p.tau0);
        for (int i = 0; i < n; i++) {
            size_t ik = (size_t)k * n + i;
            double xp = 0.5 * (w->U[ik] + w->Vd[ik]), xm = 0.5 * (w->U[ik] - w->Vd[ik]);
            if (s->fresnel) { /* the outgoing cell minus R times its mirror */
                double R = s->Rc[i], xp0 = xp;
                xp = xp0 - R * xm, xm = xm - R * xp0;
            }
            Ms[ik] = xp + xm * e;
            Md[ik] = xp - xm * e;
            if (k == 0 && s->conservative) {
                Ms[ik] = 2.0;
                Md[ik] = s->p.tau0 + 2.0 * w->h[i];
                if (s->fresnel) {
                    double R = s->Rc[i];
                    Ms[ik] = 2.0 * (1.0 - R);
                    Md[ik] = s->p.tau0 * (1.0 - R) + 2.0 * w->h[i] * (1.0 + R);
                }
            }
        }
    }
}

/* Stores mode k (lambda >= 0 pair) with coefficients cp (grows to tau0) and cm (decays). */
static void store_pair(pp_solution *s, const pp_work *w, int k, double cp, double cm)
{
    int n = s->n, m = s->m;
    double lam = sqrt(w->ev[k]);
    int slot = s->conservative ? 2 * k - 1 : 2 * k; /* -lambda first: |lambda| ascending */
    double *vm = s->V + (size_t)slot * m, *vp = s->V + (size_t)(slot + 1) * m;
    for (int i = 0; i < n; i++) {
        size_t ik = (size_t)k * n + i;
        double xp = 0.5 * (w->U[ik] + w->Vd[ik]), xm = 0.5 * (w->U[ik] - w->Vd[ik]);
        vp[i] = cp * xp, vp[n + i] = cp * xm;
        vm[i] = cm * xm, vm[n + i] = cm * xp;
    }
    s->lambda[slot] = -lam, s->tau_ref[slot] = 0.0;
    s->lambda[slot + 1] = lam, s->tau_ref[slot + 1] = s->p.tau0;
}

static void store_modes(pp_solution *s, const pp_work *w, const double *sig, const double *del)
{
    int n = s->n;
    for (int k = 0; k < n; k++) {
        if (k == 0 && s->conservative) {
            double c0 = sig[0], cl = del[0];
            for (int i = 0; i < n; i++) {
                s->V[i] = c0 + cl * w->h[i];
                s->V[n + i] = c0 - cl * w->h[i];
            }
            s->lambda[0] = 0.0, s->tau_ref[0] = s->p.tau0;
            s->c_lin = cl;
            continue;
        }
        store_pair(s, w, k, 0.5 * (sig[k] + del[k]), 0.5 * (sig[k] - del[k]));
    }
}

/* Down cells empty at tau = 0, up cells empty at tau0: sum and difference systems. */
static int boundary(pp_solution *s, pp_work *w, ppb_err *err)
{
    int n = s->n;
    double *Ms = dalloc((size_t)n * n), *Md = dalloc((size_t)n * n);
    double *sig = dalloc(n), *del = dalloc(n);
    lapack_int *piv = calloc((size_t)n, sizeof(lapack_int));
    int rc = (Ms && Md && sig && del && piv) ? 0 : ppb_fail(err, "pp solver: out of memory");
    if (rc == 0) {
        if (s->conservative)
            diffusion_mode(s, w);
        bc_matrices(s, w, Ms, Md);
        double beam = exp(-s->p.tau0 / s->p.mu0);
        for (int i = 0; i < n; i++) {
            double r1 = -s->Z[n + i], r2 = -s->Z[i] * beam;
            if (s->fresnel) { /* down - R up at tau = 0, up - R down at tau0 */
                double R = s->Rc[i];
                double up0 = s->Z[i] + s->Zu[i] * beam, dn0 = s->Z[n + i] + s->Zu[n + i] * beam;
                double up1 = s->Z[i] * beam + s->Zu[i], dn1 = s->Z[n + i] * beam + s->Zu[n + i];
                r1 = -(dn0 - R * up0), r2 = -(up1 - R * dn1);
            }
            sig[i] = r1 + r2;
            del[i] = r2 - r1;
        }
        if (LAPACKE_dgesv(LAPACK_COL_MAJOR, n, 1, Md, n, piv, del, n) != 0)
            rc = ppb_fail(err, "pp solver: singular boundary system (difference part)");
    }
    if (rc == 0 && s->conservative) /* the diffusion mode's tau0 1 also enters the sum */
        for (int i = 0; i < n; i++)
            sig[i] -= del[0] * s->p.tau0 * (s->fresnel ? 1.0 - s->Rc[i] : 1.0);
    if (rc == 0 && LAPACKE_dgesv(LAPACK_COL_MAJOR, n, 1, Ms, n, piv, sig, n) != 0)
        rc = ppb_fail(err, "pp solver: singular boundary system (sum part)");
    if (rc == 0)
        store_modes(s, w, sig, del);
    free(Ms), free(Md), free(sig), free(del), free(piv);
    return rc;
}

/* ---- evaluation ---- */

/* integral_0^len exp(A + kappa s) ds / |mu| for a ray with A <= 0 and A + kappa len <= 0 (the
 * scaled modes guarantee both), kappa |mu| = kmu: expm1 where kappa len is small, the
 * difference of exponentials elsewhere, so nothing overflows or cancels. */
static double ray_integral(double A, double kappa, double kmu, double len, double amu)
{
    double x = kappa * len;
    if (fabs(x) < 0.5)
        return exp(A) * (x == 0.0 ? 1.0 : expm1(x) / x) * len / amu;
    return (exp(A + x) - exp(A)) / kmu;
}

/* Radiance contributed along w from depth tau by a source term exp(lambda (t - tref)). */
static double ray_term(const pp_solution *s, double tau, double mu, double lambda, double tref)
{
    double A = lambda * (tau - tref);
    if (mu == 0.0)
        return exp(A);
    if (mu > 0.0) /* from below: t = tau + s, s in [0, tau0 - tau] */
        return ray_integral(A, lambda - 1.0 / mu, lambda * mu - 1.0, s->p.tau0 - tau, mu);
    return ray_integral(A, -lambda + 1.0 / mu, lambda * mu - 1.0, tau, -mu); /* from above */
}

/* The alpha = 1 linear source t along w: integral of t exp(-s/|mu|) ds / |mu| over the ray. */
static double ray_linear(const pp_solution *s, double tau, double mu)
{
    if (mu == 0.0)
        return tau;
    double amu = fabs(mu), len = mu > 0 ? s->p.tau0 - tau : tau, x = len / amu;
    double first = -expm1(-x), second = amu * (first - x * exp(-x));
    return tau * first + (mu > 0 ? second : -second);
}

static void mode_values(const pp_solution *s, double tau, double *e)
{
    for (int k = 0; k < s->nmodes; k++)
        e[k] = exp(s->lambda[k] * (tau - s->tau_ref[k]));
}

void pp_cell_field(const pp_solution *s, double tau, double *field)
{
    int m = s->m;
    double *e = dalloc(s->nmodes), beam = exp(-tau / s->p.mu0);
    mode_values(s, tau, e);
    for (int i = 0; i < m; i++)
        field[i] = s->Z[i] * beam + s->c_lin * tau;
    if (s->fresnel) {
        double up = exp(-(s->p.tau0 - tau) / s->p.mu0);
        for (int i = 0; i < m; i++)
            field[i] += s->Zu[i] * up;
    }
    cblas_dgemv(CblasColMajor, CblasNoTrans, m, s->nmodes, 1.0, s->V, m, e, 1, 1.0, field, 1);
    free(e);
}

/* pp_source_coeffs plus, at n > 1, bu: the coefficient of exp(-(tau0 - tau)/mu0) (the
 * upward beam's diffuse part; 0 at n = 1). */
static void source_coeffs(const pp_solution *s, const double w[3], double *a, double *b, double *bu)
{
    int m = s->m;
    double *F = dalloc(m);
    pp_phase_row((pp_dirs *)&s->dirs, s->p.g, w, F, NULL);
    cblas_dgemv(CblasColMajor, CblasTrans, m, s->nmodes, s->p.albedo, s->V, m, F, 1, 0.0, a, 1);
    *b = s->p.albedo * cblas_ddot(m, F, 1, s->Z, 1);
    *bu = s->fresnel ? s->p.albedo * cblas_ddot(m, F, 1, s->Zu, 1) : 0.0;
    free(F);
}

void pp_source_coeffs(const pp_solution *s, const double w[3], double *a, double *b)
{
    double bu;
    source_coeffs(s, w, a, b, &bu);
}

/* The upward beam's single-scattering coefficient alpha U p(w . w_L mirrored) (n > 1). */
static double direct_up(const pp_solution *s, const double w[3])
{
    double c = w[0] * s->wL[0] - w[1] * s->wL[1] + w[2] * s->wL[2];
    return s->p.albedo * s->U * pp_hg(s->p.g, c);
}

void pp_source_beams(const pp_solution *s, const double w[3], double *a, double *down, double *up)
{
    double c = w[0] * s->wL[0] + w[1] * s->wL[1] + w[2] * s->wL[2];
    source_coeffs(s, w, a, down, up);
    *down += s->p.albedo * (s->fresnel ? s->D : 1.0) * pp_hg(s->p.g, c);
    if (s->fresnel)
        *up += direct_up(s, w);
}

double pp_source_linear(const pp_solution *s)
{
    return s->p.albedo * s->c_lin;
}

double pp_source_direct(const pp_solution *s, double tau, const double w[3])
{
    double c = w[0] * s->wL[0] + w[1] * s->wL[1] + w[2] * s->wL[2];
    if (s->fresnel)
        return s->p.albedo * s->D * pp_hg(s->p.g, c) * exp(-tau / s->p.mu0) +
               direct_up(s, w) * exp(-(s->p.tau0 - tau) / s->p.mu0);
    return s->p.albedo * pp_hg(s->p.g, c) * exp(-tau / s->p.mu0);
}

double pp_source(const pp_solution *s, double tau, const double w[3])
{
    double *a = dalloc(s->nmodes), *e = dalloc(s->nmodes), b, bu;
    source_coeffs(s, w, a, &b, &bu);
    mode_values(s, tau, e);
    double J = b * exp(-tau / s->p.mu0) + pp_source_linear(s) * tau + pp_source_direct(s, tau, w);
    if (s->fresnel)
        J += bu * exp(-(s->p.tau0 - tau) / s->p.mu0);
    for (int k = 0; k < s->nmodes; k++)
        J += a[k] * e[k];
    free(a), free(e);
    return J;
}

/* J integrated along w back to the face it comes from, without what that face reflects. */
static double ray_radiance(const pp_solution *s, double tau, const double w[3])
{
    double mu = w[1];
    if ((mu > 0 && tau >= s->p.tau0) || (mu < 0 && tau <= 0))
        return 0.0; /* the ray starts on the face it would come from */
    double *a = dalloc(s->nmodes), b, bu;
    source_coeffs(s, w, a, &b, &bu);
    double c = w[0] * s->wL[0] + w[1] * s->wL[1] + w[2] * s->wL[2];
    double beam = b + s->p.albedo * (s->fresnel ? s->D : 1.0) * pp_hg(s->p.g, c);
    double L = beam * ray_term(s, tau, mu, -1.0 / s->p.mu0, 0.0);
    if (s->fresnel)
        L += (bu + direct_up(s, w)) * ray_term(s, tau, mu, 1.0 / s->p.mu0, s->p.tau0);
    for (int k = 0; k < s->nmodes; k++)
        L += a[k] * ray_term(s, tau, mu, s->lambda[k], s->tau_ref[k]);
    if (s->conservative)
        L += pp_source_linear(s) * ray_linear(s, tau, mu);
    free(a);
    return L;
}

/* n > 1: the ray from a face also carries what the face reflects from the mirror direction
 * w_m (w.y -> -w.y). With A, B the face-to-face integrals along the up one of (w, w_m) to
 * tau = 0 and along the down one to tau0, e = exp(-tau0/|mu|) and F = F(|mu|) from inside:
 * L0 = A + e F L1, L1 = B + e F L0 (L0 up at tau = 0, L1 down at tau0), solved in closed
 * form; then L(tau, w) = ray(tau, w) + exp(-path/|mu|) F L(face, w_m). */
double pp_radiance(const pp_solution *s, double tau, const double w[3])
{
    double mu = w[1];
    if (!s->fresnel || mu == 0.0)
        return ray_radiance(s, tau, w);
    double wm[3] = {w[0], -w[1], w[2]}, amu = fabs(mu);
    const double *wu = mu > 0 ? w : wm, *wd = mu > 0 ? wm : w;
    double F = ppb_fresnel(amu, 1.0 / s->nrel), e = exp(-s->p.tau0 / amu);
    double A = ray_radiance(s, 0.0, wu), B = ray_radiance(s, s->p.tau0, wd);
    double L0 = (A + e * F * B) / (1.0 - e * e * F * F), L1 = B + e * F * L0;
    double path = mu > 0 ? s->p.tau0 - tau : tau;
    return ray_radiance(s, tau, w) + exp(-path / amu) * F * (mu > 0 ? L1 : L0);
}

double pp_exit_radiance(const pp_solution *s, const double w[3])
{
    double tau = w[1] > 0 ? 0.0 : s->p.tau0;
    if (!s->fresnel)
        return pp_radiance(s, tau, w);
    double nr = s->nrel, mu_a = fabs(w[1]);
    double mu_in = sqrt(1.0 - (1.0 - mu_a * mu_a) / (nr * nr));
    double wi[3] = {w[0] / nr, w[1] > 0 ? mu_in : -mu_in, w[2] / nr};
    return (1.0 - ppb_fresnel(mu_a, nr)) / (nr * nr) * pp_radiance(s, tau, wi);
}

/* integral_0^tau0 of exp(lambda (t - tref)) dt. */
static double depth_integral(double lambda, double tref, double tau0)
{
    double A = -lambda * tref, x = lambda * tau0;
    if (fabs(x) < 0.5)
        return exp(A) * (x == 0.0 ? 1.0 : expm1(x) / x) * tau0;
    return (exp(A + x) - exp(A)) / lambda;
}

/* R, T from the cell fluxes at the faces; absorbed = (1 - alpha) x (diffuse and direct
 * fluence integrated over depth), all over the incident mu0. */
static void compute_totals(pp_solution *s)
{
    int n = s->n, m = s->m;
    double *field = dalloc(m), mu0 = s->p.mu0, up = 0.0, down = 0.0;
    const double *area = s->dirs.area;
    pp_cell_field(s, 0.0, field);
    for (int i = 0; i < n; i++)
        up += area[i] * s->dirs.k[i] * field[i] * (s->fresnel ? 1.0 - s->Rc[i] : 1.0);
    pp_cell_field(s, s->p.tau0, field);
    for (int i = 0; i < n; i++)
        down += area[i] * s->dirs.k[i] * field[n + i] * (s->fresnel ? 1.0 - s->Rc[i] : 1.0);
    if (s->fresnel) { /* fractions of the power mu_air incident from air (ppsolver.h) */
        double e = exp(-s->p.tau0 / mu0), depth = mu0 * -expm1(-s->p.tau0 / mu0);
        double fluence = (s->D + s->U) * depth;
        for (int i = 0; i < m; i++)
            fluence += area[i % n] * (s->Z[i] + s->Zu[i]) * depth;
        for (int k = 0; k < s->nmodes; k++) {
            double sum = 0.0;
            for (int i = 0; i < m; i++)
                sum += area[i % n] * s->V[(size_t)k * m + i];
            fluence += sum * depth_integral(s->lambda[k], s->tau_ref[k], s->p.tau0);
        }
        double out = (1.0 - s->Fb) * mu0 / s->mu_air;
        s->ballistic_top = s->U * e * out;
        s->ballistic = s->D * e * out + s->ballistic_top;
        s->R = up / s->mu_air, s->T = down / s->mu_air;
        s->absorbed = s->conservative ? 0.0 : (1.0 - s->p.albedo) * fluence / s->mu_air;
        free(field);
        return;
    }
    s->ballistic = exp(-s->p.tau0 / mu0);
    double fluence = mu0 * -expm1(-s->p.tau0 / mu0); /* direct beam */
    for (int i = 0; i < m; i++)
        fluence += area[i % n] * s->Z[i] * mu0 * -expm1(-s->p.tau0 / mu0);
    for (int k = 0; k < s->nmodes; k++) {
        double sum = 0.0;
        for (int i = 0; i < m; i++)
            sum += area[i % n] * s->V[(size_t)k * m + i];
        fluence += sum * depth_integral(s->lambda[k], s->tau_ref[k], s->p.tau0);
    }
    s->R = up / mu0, s->T = down / mu0;
    s->absorbed = s->conservative ? 0.0 : (1.0 - s->p.albedo) * fluence / mu0;
    free(field);
}

/* ---- the solve ---- */

/* ---- delta-M: the forward fraction the cells leave unresolved (ppsolver.h) ---- */

/* The discrete slab's diffusion coefficient at albedo 1 for the phase blocks held:
 * D = 2 sum_i |Omega| k_i h_i / (4 pi), h = (E - (A - B))^-1 k over the up cells (the
 * conservative diffusion mode's h+, diffusion_mode()); 0 when G- is not positive definite. */
static double discrete_diffusion(const pp_solution *s)
{
    size_t n = (size_t)s->n;
    double *G = dalloc(n * n), *h = dalloc(n), D = 0.0;
    const double *area = s->dirs.area;
    if (G && h) {
        for (size_t j = 0; j < n; j++) {
            for (size_t i = 0; i < n; i++)
                G[j * n + i] = (i == j ? area[i] : 0.0) - (s->Sa[j * n + i] - s->Sb[j * n + i]);
            h[j] = area[j] * s->dirs.k[j];
        }
        if (LAPACKE_dposv(LAPACK_COL_MAJOR, 'L', (lapack_int)n, 1, G, (lapack_int)n, h,
                          (lapack_int)n) == 0)
            for (size_t i = 0; i < n; i++)
                D += 2.0 * area[i] * s->dirs.k[i] * h[i] / (4.0 * M_PI);
    }
    free(G), free(h);
    return D;
}

/* The same for isotropic scattering (A = B, h = k): the cells' own 1/3, D_0. */
static double isotropic_diffusion(const pp_solution *s)
{
    double D = 0.0;
    for (int i = 0; i < s->n; i++)
        D += 2.0 * s->dirs.area[i] * s->dirs.k[i] * s->dirs.k[i] / (4.0 * M_PI);
    return D;
}

int pp_collars_check(const ppb_config *cfg, const char *section, ppb_err *err)
{
    int most = pp_dirs_max_collars(cfg->pp.directions);
    if (cfg->pp.collars > most)
        return ppb_config_key_fail(cfg, section, "collars", err,
                                   "%d is more than the %d that [pp] directions = %d allows (two "
                                   "cells a collar at least)",
                                   cfg->pp.collars, most, cfg->pp.directions);
    /* The polar rings resolve a field symmetric about the normal; an oblique beam's is not, and
     * its exit radiance comes out blurred over the rings' long cells (measured on a g 0.9 slab at
     * 30 degrees: bins up to 81 % off, though the totals are right; docs/reference.md, Keys). */
    if (cfg->pp.collars > 0 && cfg->scene.theta_deg != 0.0)
        return ppb_config_key_fail(cfg, section, "collars", err,
                                   "%d (polar rings) needs normal light, [light] theta_deg = 0: "
                                   "the rings' cells reach a radian in azimuth, which an oblique "
                                   "beam's radiance needs resolved; use collars = 0",
                                   cfg->pp.collars);
    return 0;
}

int pp_delta_m_wanted(int delta_m, double g)
{
    return g > 0.0 &&
           (delta_m == PP_DELTA_M_ON || (delta_m == PP_DELTA_M_AUTO && g >= PP_DELTA_M_AUTO_G));
}

/* P -> F E + (1 - F) P with F = 1 - (1 - g) D_c / D_0 (ppsolver.h): rows still sum to 1, S
 * stays symmetric, and the discrete slab's diffusion coefficient becomes D_0 / (1 - g). */
static void delta_m_blocks(pp_solution *s)
{
    s->fwd = 0.0;
    if (!pp_delta_m_wanted(s->delta_m, s->p.g))
        return;
    double Dc = discrete_diffusion(s);
    double F = Dc > 0.0 ? 1.0 - (1.0 - s->p.g) * Dc / isotropic_diffusion(s) : 0.0;
    if (!(F > 0.0 && F < 1.0))
        return; /* nothing unresolved: the plain cell matrix */
    size_t n = (size_t)s->n;
    for (size_t k = 0; k < n * n; k++)
        s->Sa[k] *= 1.0 - F, s->Sb[k] *= 1.0 - F;
    for (size_t i = 0; i < n; i++)
        s->Sa[i * n + i] += F * s->dirs.area[i];
    s->fwd = F;
}

/* The blocks of g (shared, or integrated), then delta-M's forward fraction on them. */
static int phase_stage(pp_solution *s, const pp_solution *share, ppb_err *err)
{
    size_t nn = (size_t)s->n * s->n;
    /* the held blocks carry their delta-M: shared only between solves alike in it */
    if (share && share->n == s->n && share->p.g == s->p.g && share->collars == s->collars &&
        pp_delta_m_wanted(share->delta_m, share->p.g) == pp_delta_m_wanted(s->delta_m, s->p.g)) {
        s->fwd = share->fwd;
        memcpy(s->Sa, share->Sa, nn * sizeof(double));
        memcpy(s->Sb, share->Sb, nn * sizeof(double));
        return 0;
    }
    if (pp_phase_blocks(&s->dirs, s->p.g, s->Sa, s->Sb, err) != 0)
        return -1;
    delta_m_blocks(s);
    return 0;
}

static int solve_stages(pp_solution *s, const pp_solution *share, pp_work *w, pp_timing *t,
                        ppb_err *err)
{
    double t0 = ppb_now();
    if (phase_stage(s, share, err) != 0)
        return -1;
    double t1 = ppb_now();
    /* SIGINT/SIGTERM between the stages; LAPACK's eigen solve cannot be interrupted inside
     * (it grows as directions^3: 1.5 s at 1500), so it is checked before and after. */
    if (ppb_interrupted())
        return ppb_fail(err, "pp solver: interrupted");
    build_h(s, w);
    if (eigen_modes(s, w, err) != 0)
        return -1;
    if (ppb_interrupted())
        return ppb_fail(err, "pp solver: interrupted");
    avoid_resonance(s, w);
    if (s->fresnel)
        cell_reflectance(s), beam_series(s);
    double t2 = ppb_now();
    if (pp_phase_row(&s->dirs, s->p.g, s->wL, w->F, err) != 0)
        return -1;
    particular(s, w);
    if (s->fresnel)
        particular_series(s);
    if (boundary(s, w, err) != 0)
        return -1;
    compute_totals(s);
    double t3 = ppb_now();
    if (t)
        t->phase = t1 - t0, t->eigen = t2 - t1, t->boundary = t3 - t2;
    return 0;
}

int pp_solve_delta_m(const pp_params *p, double nrel, int delta_m, const pp_solution *share,
                     pp_solution **out, pp_timing *t, ppb_err *err)
{
    return pp_solve_collars(p, nrel, delta_m, 0, share, out, t, err);
}

int pp_solve_collars(const pp_params *p, double nrel, int delta_m, int collars,
                     const pp_solution *share, pp_solution **out, pp_timing *t, ppb_err *err)
{
    *out = NULL;
    if (check_params(p, err) != 0)
        return -1;
    if (collars < 0 || collars > pp_dirs_max_collars(p->directions))
        return ppb_fail(err, "pp solver: collars = %d, need 0..%d at directions = %d", collars,
                        pp_dirs_max_collars(p->directions), p->directions);
    if (!(nrel >= 1 && nrel <= 10))
        return ppb_fail(err, "pp solver: n = %g, need 1 <= n <= 10", nrel);
    pp_solution *s = calloc(1, sizeof *s);
    if (!s)
        return ppb_fail(err, "pp solver: out of memory");
    s->p = *p;
    s->delta_m = delta_m;
    s->collars = collars;
    s->n = p->directions, s->m = 2 * p->directions;
    s->conservative = 1.0 - p->albedo < CONSERVATIVE_EPS;
    if (nrel > 1.0) { /* the beam refracts; mu0 inside from here on */
        s->fresnel = 1, s->nrel = nrel, s->mu_air = p->mu0;
        s->p.mu0 = ppb_refract_cos(p->mu0, nrel);
    }
    if (s->conservative)
        s->p.albedo = 1.0;
    s->nmodes = s->conservative ? s->m - 1 : s->m;
    pp_work w;
    /* g < 0: the partition closed under w -> -w, where the backward matrix is the permuted
     * forward one (phase.h); the same partition as the default for odd N */
    /* at n > 1 a collar edge at the critical cosine (ppsolver.h) */
    double mu_snap = s->fresnel ? sqrt(1.0 - 1.0 / (nrel * nrel)) : 0.0;
    int rc = pp_dirs_make_collars(s->n, p->g < 0, mu_snap, s->collars, &s->dirs, err);
    if (rc == 0)
        rc = solution_alloc(s, err);
    if (rc == 0 && work_alloc(&w, (size_t)s->n) != 0)
        rc = ppb_fail(err, "pp solver: out of memory for %d directions", s->n);
    else if (rc == 0) {
        rc = solve_stages(s, share, &w, t, err);
        work_free(&w);
    }
    if (rc != 0) {
        pp_free(s);
        return -1;
    }
    *out = s;
    return 0;
}

int pp_solve_fresnel(const pp_params *p, double nrel, const pp_solution *share, pp_solution **out,
                     pp_timing *t, ppb_err *err)
{
    return pp_solve_delta_m(p, nrel, PP_DELTA_M_OFF, share, out, t, err);
}

int pp_solve_ex(const pp_params *p, const pp_solution *share, pp_solution **out, pp_timing *t,
                ppb_err *err)
{
    return pp_solve_fresnel(p, 1.0, share, out, t, err);
}

int pp_solve(const pp_params *p, pp_solution **out, ppb_err *err)
{
    return pp_solve_ex(p, NULL, out, NULL, err);
}

double pp_mu0(const pp_solution *s)
{
    return s->p.mu0;
}
int pp_nmodes(const pp_solution *s)
{
    return s->nmodes;
}

int pp_mode_capacity(const pp_solution *s)
{
    return s->m;
}

void pp_modes(const pp_solution *s, double *lambda, double *tau_ref)
{
    memcpy(lambda, s->lambda, (size_t)s->nmodes * sizeof(double));
    memcpy(tau_ref, s->tau_ref, (size_t)s->nmodes * sizeof(double));
}

void pp_totals(const pp_solution *s, double *R, double *T, double *ballistic)
{
    *R = s->R, *T = s->T, *ballistic = s->ballistic;
}

void pp_boundary_totals(const pp_solution *s, double *specular, double *ballistic_top)
{
    *specular = s->fresnel ? s->specular : 0.0;
    *ballistic_top = s->fresnel ? s->ballistic_top : 0.0;
}

double pp_absorbed(const pp_solution *s)
{
    return s->absorbed;
}

int pp_blas_reserve(ppb_err *err)
{
    if (ppb_memory_need(PPB_BLAS_BUFFER_BYTES,
                        "the linear-algebra library's (OpenBLAS) work buffer", err))
        return -1;
    /* dpotrf takes the buffer whatever the size (OpenBLAS's interface/lapack/potrf.c). */
    double one = 1.0;
    if (LAPACKE_dpotrf(LAPACK_ROW_MAJOR, 'L', 1, &one, 1) != 0)
        return ppb_fail(err, "LAPACKE_dpotrf of [1] failed");
    return 0;
}

void pp_blas_threads(char **argv)
{
    int have = openblas_get_num_threads();
    int want = ppb_memory_blas_threads(have);
    if (want != have)
        ppb_memory_blas_reexec(want, argv);
}

double pp_delta_m(const pp_solution *s)
{
    return s->fwd;
}
