/* bessel.h: the modified Bessel functions of the second kind K0 and K1, which the line
 * integrals of the diffusion profiles along the tube's z axis come to (A&S 9.6.21:
 * int exp(-a sqrt(rho^2 + z^2)) / sqrt(rho^2 + z^2) dz = 2 K0(a rho), and its rho-derivative
 * for the dipoles' (1 + a d) e^(-a d) / d^3 terms: 2 a K1(a rho) / rho).
 *
 * Each: the ascending series (A&S 9.6.13, 9.6.11) for x <= 2, the trapezoidal rule on A&S
 * 9.6.24 for 2 < x < 20 (step 1/8: exponentially convergent, error ~ exp(x - pi^2 / h)), the
 * asymptotic series A&S 9.7.2 cut at its smallest term for x >= 20 (error below exp(-2x));
 * ~1e-15 relative (tests/test_burley.c: A&S Table 9.8 and 30-digit values). +inf at 0, 0 at
 * +inf, NaN below 0. */
#ifndef PPB_BESSEL_H
#define PPB_BESSEL_H

double ppb_bessel_k0(double x);
double ppb_bessel_k1(double x);

#endif
