/* rte2d_beam.h: the direct beam's collision density integrated exactly over an axis-aligned
 * rectangle of the cross-section, the first-scattering source of a flat-source region of `rte2d`
 * (reference: Methods, Light; Medium for n > 1).
 *
 * Owns: the closed-form integral of sigma_t E_k over [x0, x1] x [y0, y1] for the beam's four
 * direction classes k, with E_k exactly as kernels/rte2d.cl's rte_ray_side weights them:
 *   n <= 1: E_0 = lit exp(-D), D and lit from ppb_rte_light (rte2d_params.h);
 *   n > 1, the slab or the tube at normal incidence: E_0 = e exp(-D), E_1 = e F_b exp(-(2 D_b -
 * D)), e = beam_in / (1 - F_b^2 exp(-2 D_b)), D_b = sigma_t H / cos theta_t; n > 1, the tube at
 * oblique incidence: the image sum of kernels/ppb_beam_images.h (tile (k, j), weight beam_in F_b^j
 * F_s^k, class 2 (k odd) + (j odd)), every image whose weight can exceed 1e-17 of the first one's.
 * Each term is w exp(affine) on convex pieces of the rectangle cut by the lines where lit or D's
 * formula changes; each piece is integrated in closed form (rte2d_beam.c). No sampling: the sum
 * over a tiling of the cross-section is the beam's total collision power to rounding. */
#ifndef PPB_RTE2D_BEAM_H
#define PPB_RTE2D_BEAM_H

#include "methods/rte2d/rte2d_params.h"

/* The beam's direction classes, (sin, cos) of the beam inside and the sign of each. */
enum {
    PPB_BEAM_PLUS_DOWN = 0,  /* (+sin, down): the beam as it enters */
    PPB_BEAM_PLUS_UP = 1,    /* (+sin, up): reflected an odd number of times at S1, S2 */
    PPB_BEAM_MINUS_DOWN = 2, /* (-sin, down): reflected an odd number of times at S3, S4 */
    PPB_BEAM_MINUS_UP = 3,
    PPB_BEAM_CLASSES = 4
};

/* out[k] = integral over [x0, x1] x [y0, y1] of sigma_t E_k dA (x0 < x1, y0 < y1, inside the
 * cross-section: -W/2 <= x, -H <= y <= 0), P as ppb_rte_grid_make fills it. sigma_t must be
 * constant in the rectangle (the caller never lets it straddle step_x with a density step); it
 * is taken at the rectangle's centre. The first-scattering emission into a direction with phase
 * coefficients cb[4] is then albedo sum_k cb[k] out[k] / area. Slab mode (P->tube == 0): x0, x1
 * are ignored and out is per unit width. */
void ppb_rte_beam_rect(const ppb_rte_params *P, double x0, double x1, double y0, double y1,
                       double out[PPB_BEAM_CLASSES]);

/* The integral of exp(a + b x + c y) over the convex polygon (x[i], y[i]), i < n (either
 * orientation), in closed form: exposed for the tests. */
double ppb_rte_poly_exp(const double *x, const double *y, int n, double a, double b, double c);

#endif
