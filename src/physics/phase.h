/* phase.h: the Henyey-Greenstein phase matrix of the direction cells (paper Eq. 8, with the
 * consistent Galerkin form of reference: Corrections).
 *
 * Owns p(cos) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2)) (normalised over 4 pi, so a row of
 * P sums to 1), the cell-pair integrals S_ij = double integral of p over Omega_i x Omega_j
 * (symmetric; P_ij = S_ij / |Omega_i|), and the cell integrals F_j(w) = integral of p(w.w')
 * over Omega_j for one continuous direction w. Derivation: with I = sum_j I_j 1_{Omega_j},
 * averaging alpha * integral p I over Omega_i gives alpha sum_j P_ij I_j with P_ij as above
 * (paper Eq. 7-8 carry a stray |Omega| factor, reference: Corrections).
 *
 * Quadrature: product Gauss per cell (directions.h), the order chosen per pair from how close
 * the pair comes to the HG peak (its complex singularity lies sqrt(D / |g|) away in angle,
 * D = 1 + g^2 - 2|g| cos(theta_min)), so far pairs cost 9-16 nodes and touching pairs of a
 * g = 0.95 function get up to 16 x 16 per cell. The self term (and for F the cell holding w)
 * is not integrated: it is set so that rows conserve energy exactly (sum_j S_ij = |Omega_i|,
 * sum_j F_j = 1), which keeps S symmetric and puts the small quadrature residual where the
 * peak sits. Wide sectors (the polar ring, narrow collars) also get the order their azimuth
 * rule needs: along a small circle the singularity lies acosh(X) away in phi however far the
 * peak, which the arc-length estimate misses (far pairs were off by 7e-6; now within 4e-8 of
 * the converged order-16 rule). For F, a cell next to w whose rule would need more than
 * PP_QMAX nodes per axis is bisected in (theta, phi) until each piece's rule suffices.
 * Symmetry: S is integrated once per orbit of a ring pair under the rotations that map both
 * rings onto themselves (turns by 2 pi / gcd of their sector counts, a half turn or more for
 * the even collars), the z mirror and the transpose; the orbit's members are copied, so these
 * symmetries hold exactly. The cap's diagonal term comes from a compensated row sum.
 * Backward scattering: on a partition closed under w -> -w (pp_dirs_antipode; the solver
 * builds one for g < 0, pp_dirs_make_antipodal), p(x.y; g) = p(x.(-y); -g) gives
 * S(i, j; g) = S(i, antipode(j); -g): the matrix is a column permutation of the |g| one and its
 * peak, on the pairs (i, antipode(i)), is the conserved self term of |g| (non-negative, as
 * resolved as the forward case), not an under-resolved integral. F is permuted the same way.
 * On a partition without antipodes (the default one for even N) g < 0 is integrated directly,
 * with the old limitation: the backward peak's residual lands on the diagonal (-1e-2 of a row
 * at N = 40, g = -0.95; rows still sum to 1). */
/* The truncated Legendre series (pp_phase_fn with nmom = L > 0; reference: Methods, `rte2d`,
 * delta-M): p(cos) = sum_{l < L} (2l + 1) chi_l P_l(cos) / (4 pi), a polynomial of degree L - 1,
 * which delta-M's Legendre truncation retains (Wiscombe 1977). It is entire, so one product
 * Gauss order per pair fixed by L times the cells' half-length integrates it (pp_phase_series_
 * order); the symmetries, the orbits and the conserved self terms are the HG matrix's. A
 * truncated series can dip below 0 (at g = 0.9, L = 16 down to -0.013 / sr near cos = -1): a
 * negative cell integral is set to 0 before the rows are conserved (S stays symmetric, rows sum
 * to 1, no cell receives negative light), and the largest share of a row so moved is reported
 * (*clipped). */
#ifndef PPB_PHASE_H
#define PPB_PHASE_H

#include "physics/directions.h"
#include "base/err.h"

/* HG phase function per steradian; |g| < 1. */
double pp_hg(double g, double cos_theta);

/* The two N x N blocks of S (row-major): Sa_ij = S(up i, up j), Sb_ij = S(up i, down N + j).
 * By the up/down mirror S(down, down) = Sa and S(down, up) = Sb; both blocks are symmetric. */
int pp_phase_blocks(pp_dirs *d, double g, double *Sa, double *Sb, ppb_err *err);

/* The full 2N x 2N matrix P_ij = S_ij / |Omega_i| (rows sum to 1); for tests and small N. */
int pp_phase_matrix(pp_dirs *d, double g, double *P, ppb_err *err);

/* F[j] = integral over cell j of p(w . w') dw' for j in [0, 2N), summing to 1. */
int pp_phase_row(pp_dirs *d, double g, const double w[3], double *F, ppb_err *err);

#define PP_SERIES_MAX 64 /* Legendre moments a series phase function may have */

/* A phase function the cells integrate: HG(g) where nmom = 0, else the series of the moments
 * chi[0 .. nmom - 1] (chi[0] = 1; g unused). */
typedef struct pp_phase_fn {
    double g;
    int nmom;
    double chi[PP_SERIES_MAX];
} pp_phase_fn;

/* The phase function per steradian at cos (HG or the series, by Clenshaw's recurrence). */
double pp_phase_eval(const pp_phase_fn *ph, double cos_theta);

/* pp_phase_blocks, pp_phase_matrix and pp_phase_row of either kind of phase function; clipped
 * (may be NULL): for a series the largest share of a row whose negative integrals were set to
 * 0, else 0. */
int pp_phase_blocks_fn(pp_dirs *d, const pp_phase_fn *ph, double *Sa, double *Sb, double *clipped,
                       ppb_err *err);
int pp_phase_matrix_fn(pp_dirs *d, const pp_phase_fn *ph, double *P, double *clipped, ppb_err *err);
int pp_phase_row_fn(pp_dirs *d, const pp_phase_fn *ph, const double w[3], double *F,
                    double *clipped, ppb_err *err);

#endif
