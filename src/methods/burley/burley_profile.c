/* burley_profile.c: the normalized diffusion profile and its integrals (burley_profile.h). */
#include "methods/burley/burley_profile.h"

#include <math.h>

#include "base/bessel.h"
#include "base/quadrature.h"
#include "kernels/ppb_conventions.h"

double ppb_burley_shape_searchlight(double A)
{
    double c = fabs(A - 0.8);
    return 1.85 - A + 7.0 * c * c * c;
}

double ppb_burley_shape_diffuse(double A)
{
    return 1.9 - A + 3.5 * (A - 0.8) * (A - 0.8);
}

double ppb_burley_R(const ppb_burley *b, double r)
{
    return b->A * b->s * (exp(-b->s * r) + exp(-b->s * r / 3.0)) / (8.0 * PPB_PI * r);
}

double ppb_burley_cdf(const ppb_burley *b, double r)
{
    return 1.0 - 0.25 * exp(-b->s * r) - 0.75 * exp(-b->s * r / 3.0);
}

double ppb_burley_line(const ppb_burley *b, double rho)
{
    double x = b->s * rho;
    return b->A * b->s * (ppb_bessel_k0(x) + ppb_bessel_k0(x / 3.0)) / (4.0 * PPB_PI);
}

#define GL_ORDER 10

/* 10-point Gauss-Legendre of K0(s rho) + K0(s rho / 3), rho = sqrt(u^2 + v^2), over [lo, hi]. */
static double panel(double s, double v, double lo, double hi, const double *x, const double *w)
{
    double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo), sum = 0.0;
    for (int j = GL_ORDER - 1; j >= 0; j--) {
        double u = mid + half * x[j], rho = sqrt(u * u + v * v);
        if (rho == 0.0)
            continue; /* never a node: the nodes are interior */
        sum += w[j] * (ppb_bessel_k0(s * rho) + ppb_bessel_k0(s * rho / 3.0));
    }
    return half * sum;
}

/* int_a^b of the kernel sum over u, 0 <= a < b: the integrand falls with u, fastest near a. */
static double from_near(double s, double v, double a, double b, double hmax, const double *x,
                        const double *w)
{
    const double far = 100.0; /* s rho / 3 beyond which the profile is below e^-100 */
    double near = sqrt(a * a + v * v);
    if (s * near / 3.0 > far)
        return 0.0;
    double c = fmin(b, a + hmax), sum = 0.0;
    /* Panels halving toward a: the panel [a + w/2, a + w] lies w/2 or more from the
     * singularity at u = +-i v (complex), so 10 nodes converge fast; the last one, [a, a + w],
     * has w <= near / 4 (or 1e-14 of c - a when near = 0: the log singularity's panel is then
     * below 1e-13 of the integral). */
    double stop = near > 0.0 ? 0.25 * near : 1e-14 * (c - a), hi = c;
    while (hi - a > stop) {
        double lo = a + 0.5 * (hi - a);
        sum += panel(s, v, lo, hi, x, w);
        hi = lo;
    }
    sum += panel(s, v, a, hi, x, w);
    for (double lo = c; lo < b; lo += hmax) {
        double hi2 = fmin(b, lo + hmax);
        if (s * sqrt(lo * lo + v * v) / 3.0 > far)
            break;
        sum += panel(s, v, lo, hi2, x, w);
    }
    return sum;
}

double ppb_burley_strip(const ppb_burley *b, double ua, double ub, double v, int nodes_per_d)
{
    if (!(ub > ua) || !(b->A > 0.0))
        return 0.0;
    double x[GL_ORDER], w[GL_ORDER];
    ppb_gauss_legendre(GL_ORDER, x, w);
    nodes_per_d = nodes_per_d < 1 ? 1 : nodes_per_d;
    double hmax = (double)GL_ORDER / (nodes_per_d * b->s), sum;
    /* The integrand is even in u: fold [ua, ub] onto u >= 0, split at the nearest point. */
    if (ua >= 0.0)
        sum = from_near(b->s, v, ua, ub, hmax, x, w);
    else if (ub <= 0.0)
        sum = from_near(b->s, v, -ub, -ua, hmax, x, w);
    else
        sum = from_near(b->s, v, 0.0, -ua, hmax, x, w) + from_near(b->s, v, 0.0, ub, hmax, x, w);
    return b->A * b->s * sum / (4.0 * PPB_PI);
}
