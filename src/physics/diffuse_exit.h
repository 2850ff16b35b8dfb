/* diffuse_exit.h: the refractive boundary's terms shared by the methods that carry light from a
 * lit entry point to a diffuse exit (`mp`, `burley`; reference: Methods): the diffuse Fresnel
 * reflectance, the exit lobe in air of a diffuse flux (Jensen et al. 2001's F_t(w_o) / pi form,
 * normalised) and the ballistic total of the refracted beam. Every one is the identity or the
 * plain value at n = 1, where the methods skip them. */
#ifndef PPB_DIFFUSE_EXIT_H
#define PPB_DIFFUSE_EXIT_H

#include "model/scene.h"

/* Diffuse (hemispherical, cosine-weighted) Fresnel reflectance 2 int_0^1 F(mu, n_rel) mu dmu of
 * the exact unpolarized F of kernels/ppb_fresnel.h, for light arriving from the side where the
 * relative index is n_rel: n_rel = n from air (F_dr,e, smooth in mu: composite 16-point
 * Gauss-Legendre, ~1e-15), n_rel = 1/n from inside (the F_dr of Jensen et al. 2001, with TIR).
 * The inside value is 1 - (1 - F_dr,e(n)) / n^2 exactly: substituting the air-side cosine
 * (n^2 mu dmu = mu_o dmu_o by Snell) in the part below the critical angle, with F equal on both
 * sides of a refraction (Stokes); Prahl 1988 Eq. B.14. 0 at n_rel = 1. */
double ppb_diffuse_fresnel(double n_rel);

/* The exit lobe in air at n > 1, per theta bin of kernels/ppb_conventions.h (edges sin^2 =
 * k / ntheta, equal projected solid angle): lobe[k] = the bin's projected-solid-angle mean of
 * F_t(mu_o) = 1 - F(mu_o, n), divided by 1 - F_dr,e(n), its mean over the hemisphere. The
 * radiance leaving a face is J lobe[k] / pi for a flux J through it: Jensen et al. 2001's
 * F_t(eta, w_o) / pi form, normalised so that the lobe integrates to J over the exit
 * hemisphere (the flux already is the power that crosses the boundary: mp's boundary condition
 * with A holds its internal reflections, burley's A is the reflectance in air). The mean of
 * lobe[] over the bins is 1 to rounding; each bin's mean by 16-point Gauss-Legendre in mu_o,
 * where F is smooth. */
void ppb_diffuse_exit_lobe(double n, int ntheta, double *lobe);

/* The ballistic total at n > 1 per unit incident power: the entering 1 - F(theta_L) times the
 * fraction of it that leaves unscattered, the refracted beam followed through its internal
 * reflections (F at each face it meets, TIR entirely) until less than 1e-16 of it is left. Slab
 * mode in closed form; the tube by ppb_lit_integral over the lit entry points (physics/maps.h).
 * n = 1: ppb_ballistic_fraction. */
double ppb_ballistic_refracted(const ppb_scene *sc);

#endif
