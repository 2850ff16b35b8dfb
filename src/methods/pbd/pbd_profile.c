/* pbd_profile.c: the tabulated profile and its integrals (pbd_profile.h). */
#include "methods/pbd/pbd_profile.h"

#include <math.h>

#include "base/quadrature.h"
#include "kernels/ppb_conventions.h"

#define MAX_NODES 16
#define MAX_EDGES (PPB_PBD_NR + 66) /* a, the radii, b and 64 graded edges */

void ppb_pbd_profile_init(ppb_pbd_profile *p, const ppb_pbd_table *t, double sigma_t, double albedo)
{
    p->sigma_t = sigma_t;
    p->rho_eff = 0.0;
    for (int k = 0; k < PPB_PBD_NR; k++) {
        p->radius[k] = t->radius[k];
        p->p[k] = 0.0;
    }
    int off;
    double w[4];
    if (!ppb_pbd_cr_weights(t->rho, PPB_PBD_NRHO, albedo, &off, w))
        return; /* albedo outside [0, 1]: pbrt's Sr is 0 (config checks refuse it first) */
    for (int j = 0; j < 4; j++) {
        if (w[j] == 0.0)
            continue;
        p->rho_eff += w[j] * t->rho_eff[off + j];
        for (int k = 0; k < PPB_PBD_NR; k++)
            p->p[k] += w[j] * t->profile[(off + j) * PPB_PBD_NR + k];
    }
}

/* The spline P at optical radius s, 0 outside the table (pbrt's Sr skips the wavelength). */
static double spline(const ppb_pbd_profile *p, double s)
{
    int off;
    double w[4], sum = 0.0;
    if (!ppb_pbd_cr_weights(p->radius, PPB_PBD_NR, s, &off, w))
        return 0.0;
    for (int k = 0; k < 4; k++)
        if (w[k] != 0.0)
            sum += w[k] * p->p[off + k];
    return sum;
}

double ppb_pbd_sr(const ppb_pbd_profile *p, double r)
{
    double s = r * p->sigma_t, sr = spline(p, s);
    if (s != 0.0)
        sr /= 2.0 * PPB_PI * s;
    sr *= p->sigma_t * p->sigma_t;
    return sr > 0.0 ? sr : 0.0;
}

double ppb_pbd_plane(const ppb_pbd_profile *p, double h)
{
    enum { Q = 4 }; /* exact for the cubic */
    double x[Q], w[Q], s0 = h * p->sigma_t, sum = 0.0;
    ppb_gauss_legendre(Q, x, w);
    for (int k = 0; k + 1 < PPB_PBD_NR; k++) {
        double lo = fmax(s0, p->radius[k]), hi = p->radius[k + 1];
        if (!(hi > lo))
            continue;
        /* Where the spline dips below 0 (far out, where the wide intervals overshoot the
         * profile's decay, even between positive nodes) the clamp puts kinks in the interval:
         * 64 sub-panels everywhere (16k evaluations per call; still exact for the cubic). */
        const int sub = 64;
        double width = (hi - lo) / sub;
        for (int m = 0; m < sub; m++) {
            double half = 0.5 * width, mid = lo + (m + 0.5) * width;
            for (int j = 0; j < Q; j++)
                sum += half * w[j] * fmax(0.0, spline(p, mid + half * x[j]));
        }
    }
    return sum;
}

/* Panel edges over [a, b] (0 <= a < b) for an integrand h(sqrt(t^2 + d^2)) of a radial h with
 * kinks at the physical radii R_k: a, the t_k = sqrt(R_k^2 - d^2) inside, and b clipped where r
 * passes the table's last radius; the first panel halved toward a until it is narrower than
 * a quarter of sqrt(a^2 + d^2), the distance from a to the complex singularities t = +-i d
 * (nothing to grade at d = 0, where r = t is smooth; a floor of 1e-12 of the panel stops it
 * otherwise). Returns the number of edges (0: nothing in range). */
static int edges(const ppb_pbd_profile *p, double a, double b, double d, double *e)
{
    double rmax = p->radius[PPB_PBD_NR - 1] / p->sigma_t;
    if (!(d < rmax))
        return 0;
    b = fmin(b, sqrt(rmax * rmax - d * d));
    if (!(b > a))
        return 0;
    double tmp[MAX_EDGES];
    int n = 0;
    tmp[n++] = a;
    for (int k = 1; k < PPB_PBD_NR - 1; k++) {
        double R = p->radius[k] / p->sigma_t;
        if (R <= d)
            continue;
        double t = sqrt(R * R - d * d);
        if (t > a && t < b)
            tmp[n++] = t;
    }
    tmp[n++] = b;
    /* Grade the first panel: edges a + w / 2^m, widest first so that e stays ascending. */
    double near = sqrt(a * a + d * d), first = tmp[1] - a;
    double stop = near > 0.0 ? fmax(0.25 * near, 1e-12 * first) : first;
    int m = 0;
    e[m++] = a;
    double grade[64];
    int ng = 0;
    for (double w = 0.5 * first; w > stop * 0.5 && ng < 64; w *= 0.5)
        grade[ng++] = a + w;
    for (int i = ng - 1; i >= 0; i--)
        e[m++] = grade[i];
    for (int i = 1; i < n; i++)
        e[m++] = tmp[i];
    return m;
}

/* nodes-point Gauss-Legendre over each panel of e[0..ne-1] of f(t) = h(sqrt(t^2 + d2)). */
typedef double (*radial_fn)(const ppb_pbd_profile *p, double r, int nodes);

static double panels(const ppb_pbd_profile *p, const double *e, int ne, double d2, radial_fn f,
                     int inner_nodes, int nodes)
{
    double x[MAX_NODES], w[MAX_NODES], sum = 0.0;
    ppb_gauss_legendre(nodes, x, w);
    for (int i = 0; i + 1 < ne; i++) {
        double half = 0.5 * (e[i + 1] - e[i]), mid = 0.5 * (e[i + 1] + e[i]), s = 0.0;
        for (int j = 0; j < nodes; j++) {
            double t = mid + half * x[j];
            s += w[j] * f(p, sqrt(t * t + d2), inner_nodes);
        }
        sum += half * s;
    }
    return sum;
}

static double sr_fn(const ppb_pbd_profile *p, double r, int nodes)
{
    (void)nodes;
    return ppb_pbd_sr(p, r);
}

static int clamp_nodes(int nodes)
{
    return nodes < 2 ? 2 : nodes > MAX_NODES ? MAX_NODES : nodes;
}

double ppb_pbd_line(const ppb_pbd_profile *p, double rho, int nodes)
{
    double e[MAX_EDGES];
    int ne = edges(p, 0.0, INFINITY, rho, e);
    return 2.0 * panels(p, e, ne, rho * rho, sr_fn, 0, clamp_nodes(nodes)); /* even in z */
}

static double line_fn(const ppb_pbd_profile *p, double rho, int nodes)
{
    return ppb_pbd_line(p, rho, nodes);
}

/* int_a^b line(sqrt(u^2 + v^2)) du, 0 <= a < b. */
static double from_near(const ppb_pbd_profile *p, double a, double b, double v, int nodes)
{
    double e[MAX_EDGES];
    int ne = edges(p, a, b, v, e);
    return panels(p, e, ne, v * v, line_fn, nodes, nodes);
}

double ppb_pbd_strip(const ppb_pbd_profile *p, double ua, double ub, double v, int nodes)
{
    if (!(ub > ua) || !(p->sigma_t > 0.0))
        return 0.0;
    nodes = clamp_nodes(nodes);
    v = fabs(v);
    if (ua >= 0.0)
        return from_near(p, ua, ub, v, nodes);
    if (ub <= 0.0)
        return from_near(p, -ub, -ua, v, nodes);
    return from_near(p, 0.0, -ua, v, nodes) + from_near(p, 0.0, ub, v, nodes);
}
