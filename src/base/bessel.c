/* bessel.c: the modified Bessel functions of the second kind K0 and K1 (bessel.h). */
#include "base/bessel.h"

#include <math.h>

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

/* A&S 9.6.24 with the trapezoidal rule: e^x K_nu(x) = int_0^inf exp(-x (cosh t - 1)) cosh(nu t)
 * dt (nu = 0, 1); the integrand is analytic in |Im t| < pi/2, where it grows at most like e^x,
 * so the rule's error is about e^(x - pi^2/h) (Trefethen & Weideman 2014, Thm 5.1): below 1e-17
 * for x < 20 at h = 1/8. */
static double kn_trapezoid(int nu, double x)
{
    const double h = 0.125;
    double sum = 0.5; /* t = 0 with the half weight */
    for (int k = 1; k < 100000; k++) {
        double term = exp(-x * (cosh(k * h) - 1.0)) * (nu ? cosh(k * h) : 1.0);
        sum += term;
        if (term < 1e-18 * sum)
            break;
    }
    return exp(-x) * h * sum;
}

/* A&S 9.7.2: K_nu(x) ~ sqrt(pi / 2x) e^-x sum_k a_k, a_0 = 1,
 * a_k = a_{k-1} (4 nu^2 - (2k - 1)^2) / (8 k x); summed while the terms fall (to k ~ 2x). */
static double kn_asymptotic(int nu, double x)
{
    double term = 1.0, sum = 1.0, mu = 4.0 * nu * nu;
    for (int k = 1; k < 200; k++) {
        double next = term * (mu - (2.0 * k - 1.0) * (2.0 * k - 1.0)) / (8.0 * k * x);
        if (fabs(next) >= fabs(term))
            break;
        term = next;
        sum += term;
        if (fabs(term) < 1e-18 * fabs(sum))
            break;
    }
    return sqrt(M_PI / (2.0 * x)) * exp(-x) * sum;
}

/* K_nu for nu = 0, 1: the series below 2 (series(x)), the trapezoid to 20, the expansion beyond. */
static double kn(int nu, double x, double (*series)(double))
{
    if (!(x > 0.0))
        return x == 0.0 ? INFINITY : NAN;
    if (isinf(x))
        return 0.0;
    if (x <= 2.0)
        return series(x);
    if (x < 20.0)
        return kn_trapezoid(nu, x);
    return kn_asymptotic(nu, x);
}

double ppb_bessel_k0(double x)
{
    return kn(0, x, k0_series);
}

/* A&S 9.6.11 at n = 1: K1(x) = 1/x + ln(x/2) I1(x) - (x/4) sum_{k>=0} (psi(k+1) + psi(k+2))
 * (x^2/4)^k / (k! (k+1)!), psi(k+1) = -gamma + H_k; I1(x) = (x/2) sum_k (x^2/4)^k /
 * (k! (k+1)!) (A&S 9.6.10). Same convergence as k0_series. */
static double k1_series(double x)
{
    double q = 0.25 * x * x, term = 1.0, i1 = 1.0, harmonic = 0.0;
    double rest = -2.0 * EULER_GAMMA + 1.0; /* k = 0: psi(1) + psi(2) = -2 gamma + 1 */
    for (int k = 1; k < 40; k++) {
        term *= q / ((double)k * (k + 1));
        harmonic += 1.0 / k;
        double psi_sum = -2.0 * EULER_GAMMA + 2.0 * harmonic + 1.0 / (k + 1);
        i1 += term;
        rest += term * psi_sum;
        if (fabs(term * psi_sum) < 1e-18 * fabs(rest))
            break;
    }
    return 1.0 / x + log(0.5 * x) * 0.5 * x * i1 - 0.25 * x * rest;
}

double ppb_bessel_k1(double x)
{
    return kn(1, x, k1_series);
}
