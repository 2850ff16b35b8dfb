/* phase_rings.h: the HG cell-pair integral of the polar-ring partition by azimuthal convolution.
 *
 * Owns S_ab = integral over Omega_a x Omega_b of p(w . w') for the long, thin cells of
 * pp_dirs_make_collars (directions.h), where phase.c's product Gauss rule would need far more
 * than PP_QMAX nodes along a cell (a sector of up to a radian against the 0.05 rad of a g = 0.95
 * peak). Both cells are (theta, phi) rectangles and p depends on phi - phi' alone, so
 *   integral_[a0, a1] integral_[b0, b1] f(phi - phi') dphi' dphi = integral W(D) f(D) dD,
 * W(D) = |[a0, a1] intersected with [b0, b1] + D|, a trapezoid in D. Per pair of theta nodes
 * (Gauss in theta with the weight sin theta, rescaled to the cells' exact mu widths) the
 * one-dimensional integral is split at W's kinks, at p's peaks (D = 0 mod 2 pi for a positive
 * cosine coefficient) and half-way between them, and graded geometrically away from each peak
 * at the peak's own half-width, 8 Gauss nodes a piece; see docs/methods.md (the slab solver's
 * error budget) for the measured effect. */
#ifndef PPB_PHASE_RINGS_H
#define PPB_PHASE_RINGS_H

#include "physics/directions.h"

/* S between cells a and b in [0, 2N), a != b, for HG with |g| < 1. */
double pp_phase_pair_rings(const pp_dirs *d, double g, int a, int b);

#endif
