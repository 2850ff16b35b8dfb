/* phase.c: HG cell-pair and point-cell integrals by order-adaptive product Gauss (phase.h). */
#include "phase.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PP_PI     3.14159265358979323846
#define PHASE_TOL 1e-8 /* target relative quadrature error of one pair */

double pp_hg(double g, double cos_theta)
{
    double den = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * PP_PI * den * sqrt(den));
}

/* Gauss order per axis for a cell of corner radius h whose nearest point lies theta_min from
 * the HG peak: Gauss-Legendre converges like rho^(-2q), rho the Bernstein ellipse parameter
 * fixed by the distance d = sqrt(D / |g|) of the nearest complex singularity. */
static int gauss_order(double g, double theta_min, double h)
{
    double ag = fabs(g);
    if (ag < 1e-14)
        return 1; /* isotropic: p is constant */
    double den = 1.0 + ag * ag - 2.0 * ag * cos(theta_min);
    double ratio = sqrt(den / ag) / h;
    double rho = ratio + sqrt(ratio * ratio + 1.0);
    int q = (int)ceil(log(1.0 / PHASE_TOL) / (2.0 * log(rho)));
    return q < 2 ? 2 : (q > PP_QMAX ? PP_QMAX : q);
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Angle between a and the peak seen from b: the forward direction for g >= 0, the backward one
 * for g < 0, where p peaks at cos = -1. */
static double peak_angle(double g, const double *a, const double *b)
{
    double c = dot3(a, b) * (g < 0 ? -1.0 : 1.0);
    return acos(c > 1.0 ? 1.0 : (c < -1.0 ? -1.0 : c));
}

/* Sum over node pairs of w_a w_b p(x_a . x_b). */
static double pair_sum(double g, const double *na, const double *nb, int nq)
{
    double c1 = (1.0 - g * g) / (4.0 * PP_PI), g2 = 1.0 + g * g, tg = 2.0 * g, sum = 0.0;
    for (int a = 0; a < nq; a++) {
        const double *x = na + 4 * a;
        double inner = 0.0;
        for (int b = 0; b < nq; b++) {
            const double *y = nb + 4 * b;
            double den = g2 - tg * (x[0] * y[0] + x[1] * y[1] + x[2] * y[2]);
            inner += y[3] / (den * sqrt(den));
        }
        sum += x[3] * inner;
    }
    return c1 * sum;
}

static double cell_radius(const pp_dirs *d, int cell)
{
    return d->radius[cell % d->n];
}
static double cell_half(const pp_dirs *d, int cell)
{
    return d->half[cell % d->n];
}

/* S between cells a and b (any hemispheres), a != b. */
static int pair_integral(pp_dirs *d, double g, int a, int b, double *out, ppb_err *err)
{
    double tmin =
        peak_angle(g, d->centre + 3 * a, d->centre + 3 * b) - cell_radius(d, a) - cell_radius(d, b);
    int q = gauss_order(g, tmin > 0 ? tmin : 0.0, fmax(cell_half(d, a), cell_half(d, b)));
    const double *na = pp_dirs_nodes(d, a, q, err), *nb = pp_dirs_nodes(d, b, q, err);
    if (!na || !nb)
        return -1;
    *out = pair_sum(g, na, nb, q * q);
    return 0;
}

static int check_g(double g, ppb_err *err)
{
    if (!(fabs(g) < 1.0))
        return ppb_fail(err, "HG phase function: g = %g, need |g| < 1", g);
    return 0;
}

/* Sets S(i, j) in a symmetric block and its images under the transpose and the z mirror. */
static void set_sym(const pp_dirs *d, double *S, int i, int j, double v)
{
    size_t n = (size_t)d->n;
    int mi = pp_dirs_zmirror(d, i), mj = pp_dirs_zmirror(d, j);
    S[i * n + j] = S[j * n + i] = S[mi * n + mj] = S[mj * n + mi] = v;
}

/* Self terms from conservation: what scatters out of cell i is all of |Omega_i|. */
static void conserve_rows(const pp_dirs *d, double *Sa, const double *Sb)
{
    size_t n = (size_t)d->n;
    for (size_t i = 0; i < n; i++) {
        double rest = 0.0;
        for (size_t j = 0; j < n; j++)
            rest += (j == i ? 0.0 : Sa[i * n + j]) + Sb[i * n + j];
        Sa[i * n + i] = d->solid - rest;
    }
}

int pp_phase_blocks(pp_dirs *d, double g, double *Sa, double *Sb, ppb_err *err)
{
    if (check_g(g, err) != 0)
        return -1;
    size_t n = (size_t)d->n;
    unsigned char *done = calloc(n * n, 1);
    if (!done)
        return ppb_fail(err, "phase matrix: out of memory");
    int rc = 0;
    for (int i = 0; rc == 0 && i < d->n; i++) {
        for (int j = i; rc == 0 && j < d->n; j++) {
            if (done[i * n + j])
                continue;
            double va = 0.0, vb = 0.0;
            if (j > i)
                rc |= pair_integral(d, g, i, j, &va, err);
            rc |= pair_integral(d, g, i, d->n + j, &vb, err);
            set_sym(d, Sa, i, j, va);
            set_sym(d, Sb, i, j, vb);
            int mi = pp_dirs_zmirror(d, i), mj = pp_dirs_zmirror(d, j);
            done[i * n + j] = done[j * n + i] = done[mi * n + mj] = done[mj * n + mi] = 1;
        }
    }
    free(done);
    if (rc == 0)
        conserve_rows(d, Sa, Sb);
    return rc;
}

int pp_phase_matrix(pp_dirs *d, double g, double *P, ppb_err *err)
{
    size_t n = (size_t)d->n, m = 2 * n;
    double *Sa = malloc(sizeof(double) * n * n), *Sb = malloc(sizeof(double) * n * n);
    int rc = (Sa && Sb) ? pp_phase_blocks(d, g, Sa, Sb, err)
                        : ppb_fail(err, "phase matrix: out of memory");
    for (size_t i = 0; rc == 0 && i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            P[i * m + j] = P[(n + i) * m + n + j] = Sa[i * n + j] / d->solid;
            P[i * m + n + j] = P[(n + i) * m + j] = Sb[i * n + j] / d->solid;
        }
    }
    free(Sa);
    free(Sb);
    return rc;
}

int pp_phase_row(pp_dirs *d, double g, const double w[3], double *F, ppb_err *err)
{
    if (check_g(g, err) != 0)
        return -1;
    int m = 2 * d->n, own = pp_dirs_cell_of(d, w);
    double point[4] = {w[0], w[1], w[2], 1.0}, rest = 0.0;
    for (int j = 0; j < m; j++) {
        if (j == own)
            continue;
        double tmin = peak_angle(g, w, d->centre + 3 * j) - cell_radius(d, j);
        int q = gauss_order(g, tmin > 0 ? tmin : 0.0, cell_half(d, j));
        const double *nj = pp_dirs_nodes(d, j, q, err);
        if (!nj)
            return -1;
        /* point-to-cell: one outer node of weight 1, q x q inner nodes */
        double c1 = (1.0 - g * g) / (4.0 * PP_PI), sum = 0.0;
        for (int b = 0; b < q * q; b++) {
            double den = 1.0 + g * g - 2.0 * g * dot3(point, nj + 4 * b);
            sum += nj[4 * b + 3] / (den * sqrt(den));
        }
        F[j] = c1 * sum;
        rest += F[j];
    }
    F[own] = 1.0 - rest;
    return 0;
}
