/* burley_profile.c: the normalized diffusion profile and its integrals (burley_profile.h). */
#include "methods/burley/burley_profile.h"

#include <math.h>

#include "base/quadrature.h"
#include "kernels/ppb_conventions.h"

#define EULER_GAMMA 0.57721566490153286061

/* A&S 9.6.13: K0(x) = -(ln(x/2) + gamma) I0(x) + sum_{k>=1} H_k (x^2/4)^k / (k!)^2, H_k the
 * harmonic number; I0(x) = sum_k (x^2/4)^k / (k!)^2 (A&S 9.6.12). At x <= 2 the terms fall
 * below 1e-17 of the sum by k = 14; the cancellation costs at most one digit (at x = 2). */
static double k0_series(double x)
{
    double q = 0.25 * x * x, term = 1.0, i0 = 1.0, rest = 0.0, harmonic = 0.0;
    for (int k = 1; k < 40; k++) {
        term *= q / ((double)k * k);
        harmonic += 1.0 / k;
        i0 += term;
        rest += term * harmonic;
        if (term * harmonic < 1e-18 * rest)
            break;
    }
    return -(log(0.5 * x) + EULER_GAMMA) * i0 + rest;
}

/* A&S 9.6.24 with the trapezoidal rule: e^x K0(x) = int_0^inf exp(-x (cosh t - 1)) dt; the
 * integrand is analytic in |Im t| < pi/2, where it grows at most like e^x, so the rule's error
 * is about e^(x - pi^2/h) (Trefethen & Weideman 2014, Thm 5.1): below 1e-17 for x < 20 at
 * h = 1/8. */
static double k0_trapezoid(double x)
{
    const double h = 0.125;
    double sum = 0.5; /* t = 0 with the half weight */
    for (int k = 1; k < 100000; k++) {
        double term = exp(-x * (cosh(k * h) - 1.0));
        sum += term;
        if (term < 1e-18 * sum)
            break;
    }
    return exp(-x) * h * sum;
}

/* A&S 9.7.2 at nu = 0: K0(x) ~ sqrt(pi / 2x) e^-x sum_k a_k, a_0 = 1,
 * a_k = -a_{k-1} (2k - 1)^2 / (8 k x); summed while the terms fall (to k ~ 2x). */
static double k0_asymptotic(double x)
{
    double term = 1.0, sum = 1.0;
    for (int k = 1; k < 200; k++) {
        double next = -term * (2.0 * k - 1.0) * (2.0 * k - 1.0) / (8.0 * k * x);
        if (fabs(next) >= fabs(term))
            break;
        term = next;
        sum += term;
        if (fabs(term) < 1e-18 * fabs(sum))
            break;
    }
    return sqrt(PPB_PI / (2.0 * x)) * exp(-x) * sum;
}

double ppb_bessel_k0(double x)
{
    if (!(x > 0.0))
        return x == 0.0 ? INFINITY : NAN;
    if (isinf(x))
        return 0.0;
    if (x <= 2.0)
        return k0_series(x);
    if (x < 20.0)
        return k0_trapezoid(x);
    return k0_asymptotic(x);
}

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
