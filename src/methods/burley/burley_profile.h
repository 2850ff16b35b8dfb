/* burley_profile.h: the normalized diffusion profile of Christensen & Burley 2015 ("Approximate
 * Reflectance Profiles for Efficient Subsurface Scattering", Pixar Technical Memo 15-04; the
 * equation numbers below are the paper's) and its integrals over the tube's geometry
 * (reference: Methods, `burley`).
 *
 * Profile (Eq. 3, with d = l / s written as 1/s in the length unit):
 *   R(r) = A s (exp(-s r) + exp(-s r / 3)) / (8 pi r),  2 pi int_0^inf R(r) r dr = A.
 * s is a rate (1/length): the paper's dimensionless scaling factor for the searchlight
 * configuration and a mean-free-path parameterisation (Eq. 5), s_fit = 1.85 - A + 7 |A - 0.8|^3,
 * divided by the mean free path l: s = s_fit / l.
 *
 * Line kernel: over an infinite line at in-plane distance rho (the tube's z axis),
 *   int R(sqrt(rho^2 + z^2)) dz = A s (K0(s rho) + K0(s rho / 3)) / (4 pi),
 * since int_{-inf}^{inf} exp(-a sqrt(rho^2 + z^2)) / sqrt(rho^2 + z^2) dz = 2 K0(a rho)
 * (Abramowitz & Stegun 9.6.21 with z = rho sinh t). */
#ifndef PPB_BURLEY_PROFILE_H
#define PPB_BURLEY_PROFILE_H

#include "base/bessel.h" /* K0 */

/* The searchlight scaling factor of Eq. 5, s_fit(A) = 1.85 - A + 7 |A - 0.8|^3 (mfp
 * parameterisation), and the diffuse-surface-transmission one of Eq. 6,
 * 1.9 - A + 3.5 (A - 0.8)^2 (kept for comparison, not used). */
double ppb_burley_shape_searchlight(double A);
double ppb_burley_shape_diffuse(double A);

typedef struct ppb_burley {
    double A; /* total diffuse reflectance: the profile's plane integral */
    double s; /* rate, 1/length: s_fit(A) / l */
} ppb_burley;

/* The profile R(r) (Eq. 3), r > 0. */
double ppb_burley_R(const ppb_burley *b, double r);

/* The fraction of A within radius r: 1 - exp(-s r) / 4 - 3 exp(-s r / 3) / 4 (the profile's
 * CDF); 2 pi int_h^inf R(sqrt(rho^2 + h^2)) rho drho = A (1 - cdf(h)), the profile's integral
 * over a plane at distance h (r dr = rho drho). */
double ppb_burley_cdf(const ppb_burley *b, double r);

/* The line kernel above: int R(sqrt(rho^2 + z^2)) dz over the whole z axis, rho > 0. */
double ppb_burley_line(const ppb_burley *b, double rho);

/* int_{ua}^{ub} line(sqrt(u^2 + v^2)) du: a point at in-plane offset v from the line of entry
 * points (the exit point's depth below S1's plane), the entry points at offset u along S1.
 * Composite 10-point Gauss-Legendre: panels halving toward the nearest point of the strip down
 * to a quarter of its distance from the exit point (to 1e-14 of the panel when it lies on the
 * strip, where the integrand has K0's logarithmic singularity), then panels of at most
 * 10 / (nodes_per_d s) out to where s rho / 3 > 100 (the profile below e^-100). */
double ppb_burley_strip(const ppb_burley *b, double ua, double ub, double v, int nodes_per_d);

#endif
