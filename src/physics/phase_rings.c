/* phase_rings.c: cell-pair integrals by azimuthal convolution (phase_rings.h). */
#include "physics/phase_rings.h"

#include "kernels/ppb_conventions.h"

#include "base/quadrature.h"

#include <math.h>

#define PIECE_NODES 8    /* Gauss nodes per graded piece in D */
#define THETA_MAX   24   /* largest Gauss order in theta */
#define RINGS_TOL   1e-9 /* the theta rule's target relative error */

/* The cosine coefficient's context: f(D) = (A - B cos D)^(-3/2) times the trapezoid W. */
typedef struct conv {
    double A, B;                           /* p = norm / (A - B cos D)^(3/2) */
    double a0, a1, b0, b1;                 /* the two cells' azimuth ranges */
    double x[PIECE_NODES], w[PIECE_NODES]; /* the pieces' Gauss rule on [-1, 1] */
} conv;

static double trapezoid(const conv *c, double D)
{
    double lo = fmax(c->a0, c->b0 + D), hi = fmin(c->a1, c->b1 + D);
    return hi > lo ? hi - lo : 0.0;
}

static double integrand(const conv *c, double D)
{
    double den = c->A - c->B * cos(D);
    return trapezoid(c, D) / (den * sqrt(den));
}

/* Integral over [u, v] of W f, graded away from the peak at `peak` (outside (u, v)): pieces
 * of length max(w / 2, r) at distance r from it, so that the nearest complex singularity
 * (about w i from the peak) stays at least a piece's length away. */
static double graded(const conv *c, double u, double v, double peak, double w)
{
    int up = peak <= u; /* march away from the peak */
    double r = up ? u - peak : peak - v, end = up ? v - peak : peak - u, sum = 0.0;
    while (r < end) {
        double e = fmin(end, r + fmax(0.5 * w, r)), mid = 0.5 * (r + e), half = 0.5 * (e - r);
        for (int k = 0; k < PIECE_NODES; k++) {
            double dist = mid + half * c->x[k];
            sum += half * c->w[k] * integrand(c, up ? peak + dist : peak - dist);
        }
        r = e;
    }
    return sum;
}

/* Integral over [u, v] (no kink of W inside) of W f: split at the peaks and half-way between
 * them, each part graded from its nearer peak. */
static double linear_piece(const conv *c, double u, double v)
{
    if (!(v > u))
        return 0.0;
    if (c->B == 0.0) { /* constant f: one rule on the trapezoid's linear piece is exact */
        double den = c->A * sqrt(c->A);
        return 0.5 * (v - u) * (trapezoid(c, u) + trapezoid(c, v)) / den;
    }
    double off = c->B > 0.0 ? 0.0 : PPB_PI; /* the peaks: off + 2 pi k */
    /* the peak's half-width: A - |B| >= (1 - |g|)^2 > 0, floored where rounding takes it (g
     * within 1e-8 of 1), so that the grading always advances */
    double w = fmax(sqrt(2.0 * (c->A - fabs(c->B)) / fabs(c->B)), 1e-9);
    double sum = 0.0;
    /* between consecutive multiples off + pi k one end is a peak (k even), the other not */
    for (double k = 2.0 * floor((u - off) / (2.0 * PPB_PI)); off + PPB_PI * k < v; k += 1.0) {
        double left = off + PPB_PI * k, right = left + PPB_PI;
        double lo = fmax(u, left), hi = fmin(v, right);
        if (hi > lo)
            sum += graded(c, lo, hi, fmod(k, 2.0) == 0.0 ? left : right, w);
    }
    return sum;
}

/* Gauss nodes in theta (weight sin theta) over the cell's polar range, mu and sin theta per
 * node, weights rescaled to the exact mu width; signed mu for down cells. */
static void theta_nodes(const pp_dirs *d, int cell, int q, const double *gx, const double *gw,
                        double *mu, double *s, double *w)
{
    double mu_lo, mu_hi, p0, p1;
    pp_dirs_bounds(d, cell, &mu_lo, &mu_hi, &p0, &p1);
    int down = cell >= d->n;
    double top = down ? -mu_lo : mu_hi, bottom = down ? -mu_hi : mu_lo; /* up image */
    double t0 = acos(top), t1 = acos(bottom), sum = 0.0;
    for (int k = 0; k < q; k++) {
        double th = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * gx[k];
        mu[k] = (down ? -1.0 : 1.0) * cos(th), s[k] = sin(th);
        w[k] = 0.5 * (t1 - t0) * gw[k] * s[k];
        sum += w[k];
    }
    for (int k = 0; k < q; k++)
        w[k] *= (top - bottom) / sum;
}

/* Polar angle range (from +y) of a cell. */
static void polar_range(const pp_dirs *d, int cell, double *t0, double *t1)
{
    double mu_lo, mu_hi, p0, p1;
    pp_dirs_bounds(d, cell, &mu_lo, &mu_hi, &p0, &p1);
    *t0 = acos(mu_hi), *t1 = acos(mu_lo);
}

/* Theta order for the pair: Gauss in theta converges like rho^(-2q), rho from the distance of
 * p's complex singularity, at least the polar gap between the cells (any two directions are at
 * least their polar angles' difference apart). */
static int theta_order(const pp_dirs *d, double g, int a, int b)
{
    double ta0, ta1, tb0, tb1;
    polar_range(d, a, &ta0, &ta1);
    polar_range(d, b, &tb0, &tb1);
    double gap = fmax(0.0, fmax(ta0 - tb1, tb0 - ta1)), h = 0.5 * fmax(ta1 - ta0, tb1 - tb0);
    /* a backward peak (g < 0, integrated directly only off the antipodal partitions) gets no
     * such bound: the order as if the peak were inside */
    double ag = fabs(g), gap_peak = g >= 0.0 ? gap : 0.0;
    double ratio = sqrt(ppb_hg_base(ag, cos(gap_peak)) / ag) / h;
    double rho = ratio + sqrt(ratio * ratio + 1.0),
           q = ceil(log(1.0 / RINGS_TOL) / (2.0 * log(rho)));
    return q < 4 ? 4 : (q > THETA_MAX ? THETA_MAX : (int)q);
}

double pp_phase_pair_rings(const pp_dirs *d, double g, int a, int b)
{
    if (fabs(g) < 1e-14)
        return d->area[a % d->n] * d->area[b % d->n] / (4.0 * PPB_PI);
    int q = theta_order(d, g, a, b);
    double gx[THETA_MAX], gw[THETA_MAX], mua[THETA_MAX], sa[THETA_MAX], wa[THETA_MAX];
    double mub[THETA_MAX], sb[THETA_MAX], wb[THETA_MAX], mu_lo, mu_hi;
    ppb_gauss_legendre(q, gx, gw);
    theta_nodes(d, a, q, gx, gw, mua, sa, wa);
    theta_nodes(d, b, q, gx, gw, mub, sb, wb);
    conv c;
    ppb_gauss_legendre(PIECE_NODES, c.x, c.w);
    pp_dirs_bounds(d, a, &mu_lo, &mu_hi, &c.a0, &c.a1);
    pp_dirs_bounds(d, b, &mu_lo, &mu_hi, &c.b0, &c.b1);
    /* W's kinks: the trapezoid rises on [a0 - b1, e1], is flat to e2, falls to a1 - b0 */
    double e0 = c.a0 - c.b1, e3 = c.a1 - c.b0;
    double e1 = fmin(c.a0 - c.b0, c.a1 - c.b1), e2 = fmax(c.a0 - c.b0, c.a1 - c.b1);
    double sum = 0.0;
    for (int i = 0; i < q; i++) {
        for (int j = 0; j < q; j++) {
            c.A = ppb_hg_base(g, mua[i] * mub[j]); /* 1 + g^2 - 2 g mu mu' */
            c.B = 2.0 * g * sa[i] * sb[j];
            double v =
                linear_piece(&c, e0, e1) + linear_piece(&c, e1, e2) + linear_piece(&c, e2, e3);
            sum += wa[i] * wb[j] * v;
        }
    }
    return ppb_hg_norm(g) * sum;
}
