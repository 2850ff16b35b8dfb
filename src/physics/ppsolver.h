/* ppsolver.h: the plane-parallel solution of a homogeneous slab (paper Sec. 2.2, Eq. 8-12).
 *
 * Owns the discretised transfer equation K dI/dtau = (E - alpha P) I - alpha q exp(-tau/mu0)
 * over the direction cells of directions.h (tau = -y sigma_t grows downward, mu = w.y, Eq. 8 as
 * corrected (reference: Corrections)), its eigen solution (Eq. 9-11), the boundary conditions (Eq.
 * 12: no diffuse light enters either face), the collimated beam as a particular solution, and
 * the evaluation API the ray marcher and `ppslab` use.
 *
 * Choices, and why:
 * - Eigenproblem: the up/down mirror gives P = [[A, B], [B, A]], so with u = X+ + X-,
 *   v = X+ - X- the 2N problem becomes lambda^2 v = C G+ C G- v (C = (|Omega| K+)^-1,
 *   G+- = |Omega| (E - alpha (A +- B)), both symmetric). With T = C^(1/2), H+- = T G+- T and
 *   H- = L L^T (Cholesky; H- is positive definite for alpha <= 1), L^T H+ L is symmetric with
 *   eigenvalues lambda^2 >= 0: one N x N symmetric eigensolve (LAPACKE_dsyevd) gives all 2N
 *   modes +-lambda, with u = T L y, v = lambda T L^-T y.
 * - Scaling: a mode with lambda > 0 is written exp(lambda (tau - tau0)), one with lambda < 0
 *   exp(lambda tau), so every exponential is <= 1 inside the slab; the boundary system splits
 *   into the two N x N systems of the sums and differences of its unknowns.
 * - Beam: the single-scattering source alpha q_i exp(-tau/mu0) (q_i = cell average of
 *   p(w . w_L)) gets the particular solution Z exp(-tau/mu0), solved in the eigenbasis. Where
 *   1/mu0 meets an eigenvalue (|lambda mu0 - 1| < 1e-7) mu0 is moved by 2e-7 relative, the
 *   discrete-ordinates treatment; the whole solution (beam included) then uses the moved mu0,
 *   so it stays an exact, conserving solution of a beam 1e-7 rad away (pp_mu0 tells).
 * - alpha = 1 (taken for 1 - alpha < 1e-13): the double zero eigenvalue is replaced by its two
 *   exact solutions, the isotropic constant and the diffusion mode tau 1 + h. The constant
 *   is an ordinary mode with lambda = 0; the linear part adds pp_source_linear() * tau to J.
 * - Radiance in any direction: by integrating the source function J exactly along the ray
 *   (the discrete-ordinates "source-function integration"), not by looking up a cell, so
 *   angular detail finer than a cell (single scattering, the HG peak) is kept.
 * - Energy: rows of P conserve exactly (phase.h), so R + T + absorbed + ballistic = 1 holds to
 *   rounding for the cell field; the totals come from the cell field at the faces.
 * - Refractive boundaries, n > 1 (reference: Keys): every Fresnel path is skipped at
 *   n = 1, which stays the code above bit for bit. At n > 1:
 *   - Boundary conditions (paper Sec. 3.2's smooth faces): at each face the light of an
 *     outgoing cell reflects into its mirror cell with the cell-averaged reflectance
 *     R_i = int F mu dOmega / int mu dOmega (F depends on mu alone, so a 1-D integral over the
 *     cell's mu range: the totally reflected part exactly, the rest by 16-point Gauss-Legendre
 *     in the air-side cosine, in which F is smooth); cells wholly beyond the critical angle
 *     have R_i = 1. The up/down symmetry of the slab survives (both faces are alike), so the
 *     sum and difference systems keep their form with X+- replaced by X+- - R X-+.
 *   - The beam enters refracted, mu0 = cos theta_t (sin theta_t = sin theta_L / n), with
 *     E_perp inside (1 - F(theta_L)) cos theta_L / mu0 per unit E_perp in air. Its unscattered
 *     part reflects at S2 and S1 with F_b = F(mu0 inside) each time: a geometric series of
 *     collimated sources, summed: downward D exp(-tau/mu0), D = E_in / (1 - F_b^2
 *     exp(-2 tau0/mu0)), and upward U exp(-(tau0 - tau)/mu0), U = D F_b exp(-tau0/mu0). (They
 *     are not negligible: at n = 1.5, tau0 = 1 the first return is 1.5 % of the beam.) The
 *     upward source's particular solution is Z mirrored (cells i <-> N + i, tau <-> tau0 -
 *     tau), so one solve serves both.
 *   - Radiance along a continuous direction includes the boundary's reflections: the ray from
 *     a face reflects there from its mirror direction, a 2 x 2 system per direction pair
 *     solved in closed form (pp_radiance). Exits into air follow the n^2 law (pp_exit_radiance).
 *   - Totals are fractions of the power cos theta_L incident from air: R and T leave through
 *     1 - R_i, the ballistic through 1 - F_b at both faces, `specular` = F(theta_L), so R + T +
 *     absorbed + ballistic + specular = 1 still holds to rounding.
 * - Delta-M for forward-peaked HG (pp_params.delta_m; reference: Methods, `ppslab`). The cell
 *   matrix projects the field on piecewise-constant cells, which shrinks every phase function's
 *   first moment by the cells' mean |cell-mean direction|^2 (0.99686 at 334 cells, whatever g):
 *   harmless at g = 0.5 (the transport coefficient 1 - g is 0.3 % off), 2.8 % at g = 0.9, and
 *   the totals of thick slabs follow (UR1, UT1 off by up to 9e-3 at g = 0.95 against
 *   adding-doubling). Wiscombe's (1977) delta-M writes p = F delta + (1 - F) p' and keeps the
 *   delta part unscattered; here F is the part of the forward scattering the cells do not
 *   resolve, measured on the cell matrix itself: the discrete slab's diffusion coefficient at
 *   albedo 1, D_c (the conservative diffusion mode's h, 2 sum |Omega| k_i h_i / 4 pi), against
 *   the cells' isotropic D_0 (their 1/3); the matrix F E + (1 - F) P has D_c / (1 - F), equal
 *   to D_0 / (1 - g) for F = 1 - (1 - g) D_c / D_0 (0.030 at g = 0.9, 334 cells). The scaling
 *   is applied in its unscaled form, P -> F E + (1 - F) P for the diffuse field only (equal to
 *   tau' = (1 - alpha F) tau, alpha' = (1 - F) alpha / (1 - alpha F) for it), so rows still
 *   sum to 1 and S stays symmetric, and p' is the cells' HG(g) itself. The beam is not scaled:
 *   it keeps its exact attenuation exp(-tau / mu0) and its exact first scattering (q, and
 *   p(w . w_L) in J), so the single scattering needs no TMS correction (Nakajima & Tanaka
 *   1988) and `ballistic` stays the unscattered light. Measured against adding-doubling
 *   (tests/test_deltam.c): scaling the beam too, or truncating HG to HG(g') with g' = (g - f) /
 *   (1 - f), f = g^M, made the thin slabs worse (HG(g') misplaces the higher moments, the
 *   scaled beam counts the cells' forward part twice) and did not help the thick ones. With it
 *   the 108 cases of g 0.7-0.95 are within 1.4e-3 at 334 cells (8.9e-3 without), 6.6e-4 at
 *   1000 (3.7e-3). What bounds the rest is the polar resolution (docs/methods.md, the slab
 *   solver's error budget): the default partition's 12 rings per hemisphere at 334 cells are a
 *   midpoint rule in mu (sum |Omega| k^2 3.1e-3 short of 2 pi / 3); pp_solve_collars on the
 *   polar rings (directions.h) with 79 collars brings the same 334 cells within 9.9e-5 on
 *   the whole table. |Omega_i| is per cell (dirs.area): the polar rings' cells differ. */
#ifndef PPB_PPSOLVER_H
#define PPB_PPSOLVER_H

#include "base/err.h"

typedef struct pp_params {
    double tau0;    /* optical thickness, (0, 1e6] */
    double albedo;  /* [0, 1] */
    double g;       /* HG asymmetry, |g| < 1 */
    double mu0;     /* cos theta_L in (0, 1] */
    int directions; /* cells per hemisphere */
} pp_params;

/* Delta-M for the HG forward peak (above): off (the paper's solver, and every caller of
 * pp_solve_fresnel), on, or auto (on where g >= PP_DELTA_M_AUTO_G). Never at g <= 0. */
enum { PP_DELTA_M_OFF = 0, PP_DELTA_M_ON = 1, PP_DELTA_M_AUTO = 2 };
#define PP_DELTA_M_AUTO_G 0.6

typedef struct pp_solution pp_solution; /* opaque */

/* Seconds spent in each stage of a solve (for the benchmark). */
typedef struct pp_timing {
    double phase;    /* phase matrix blocks and the beam's source vector */
    double eigen;    /* the symmetric reduction and eigendecomposition */
    double boundary; /* particular solution, boundary systems, totals */
} pp_timing;

/* Solves one slab; rejects invalid params with a clear message. */
int pp_solve(const pp_params *p, pp_solution **out, ppb_err *err);

/* The same, reusing the phase matrix of `share` when it has the same g and directions (the
 * matrix depends on nothing else: the marcher's tables at several albedos need it once), and
 * reporting stage times when t is not NULL. share and t may be NULL. */
int pp_solve_ex(const pp_params *p, const pp_solution *share, pp_solution **out, pp_timing *t,
                ppb_err *err);

/* pp_solve_ex with refractive index n inside (outside 1; 1 <= n <= 10): p->mu0 is cos theta_L in
 * air, and n = 1 is pp_solve_ex itself. */
int pp_solve_fresnel(const pp_params *p, double n, const pp_solution *share, pp_solution **out,
                     pp_timing *t, ppb_err *err);
void pp_free(pp_solution *s);

/* The flux-weighted mean Fresnel reflectance, int F mu dmu / int mu dmu, of the inside cosines
 * [lo, hi] (0 <= lo < hi <= 1) at index n: 1 under total internal reflection. The boundary
 * condition of a direction cell at n > 1, here and in rte2d's walls (rte2d_grid.c). */
double pp_fresnel_ring_mean(double lo, double hi, double n);

/* pp_solve_fresnel with delta-M mode delta_m (PP_DELTA_M_*). */
int pp_solve_delta_m(const pp_params *p, double n, int delta_m, const pp_solution *share,
                     pp_solution **out, pp_timing *t, ppb_err *err);
/* pp_solve_delta_m on the polar-ring partition with `collars` + 1 rings per hemisphere ([pp]
 * collars; 0: the near-square cells every other entry point uses, bit for bit; directions.h:
 * pp_dirs_make_collars). Polar resolution is what the slab's totals need: at 334 cells the
 * default partition has 12 polar rings per hemisphere (docs/methods.md, the slab solver's error
 * budget). share is used only when it has the same collars. */
int pp_solve_collars(const pp_params *p, double n, int delta_m, int collars,
                     const pp_solution *share, pp_solution **out, pp_timing *t, ppb_err *err);
/* [pp] collars against [pp] directions and the light (ppslab's and pp's checks, before any
 * work): a clear error naming the key (in `section`, the methods' settings section) where it
 * exceeds pp_dirs_max_collars, or where collars > 0 meets oblique light (the polar rings
 * resolve a field symmetric about the normal only). */
struct ppb_config;
int pp_collars_check(const struct ppb_config *cfg, const char *section, ppb_err *err);
/* Whether mode delta_m applies delta-M at asymmetry g. */
int pp_delta_m_wanted(int delta_m, double g);
/* The forward fraction F the solve took as unscattered (0: delta-M off). */
double pp_delta_m(const pp_solution *s);

/* mu0 as used inside (see the resonance note above; the refracted cosine at n > 1). */
double pp_mu0(const pp_solution *s);

/* Homogeneous modes (M of them: 2N, or 2N - 1 at alpha = 1), sorted by |lambda| ascending;
 * e_k(tau) = exp(lambda_k (tau - tau_ref_k)), tau_ref_k = 0 if lambda_k < 0 else tau0. */
int pp_nmodes(const pp_solution *s);
/* The most modes a solution of these directions has: m, the cell count (2n). At albedo 1 (1 -
 * albedo < 1e-13) the eigenvalue pair +-lambda_0 is degenerate at 0 and becomes the constant
 * and linear (diffusion) mode, stored as one: m - 1 modes; every other albedo has m. */
int pp_mode_capacity(const pp_solution *s);
void pp_modes(const pp_solution *s, double *lambda, double *tau_ref);

/* Source function for scattering into the continuous direction w (unit vector, tube frame),
 * per unit optical depth, E_perp = 1:
 *   J(tau, w) = alpha integral p(w.w') I_diffuse(tau, w') dw' + alpha p(w.w_L) exp(-tau/mu0).
 * Diffuse part in modal form: sum_k a_k(w) e_k(tau) + b(w) exp(-tau/mu0) + a_lin tau.
 * At n > 1 b is the downward beam's part only (the upward reflected beam's is not in it:
 * pp_source_beams gives both, which the marcher uses); pp_source and pp_radiance hold both. */
void pp_source_coeffs(const pp_solution *s, const double w[3], double *a, double *b);
/* The same modes a_k(w) with the beams' whole coefficients, single scattering included: J's
 * coefficient of exp(-tau/mu0) (*down) and of exp(-(tau0 - tau)/mu0) (*up, the beam reflected
 * at S2; 0 at n = 1): J = sum_k a_k e_k + down e^{-tau/mu0} + up e^{-(tau0-tau)/mu0} + a_lin tau
 * (the marcher at n > 1). */
void pp_source_beams(const pp_solution *s, const double w[3], double *a, double *down, double *up);
double pp_source_linear(const pp_solution *s); /* a_lin: 0 unless alpha = 1 */
double pp_source_direct(const pp_solution *s, double tau, const double w[3]);
double pp_source(const pp_solution *s, double tau, const double w[3]);

/* Scattered radiance at depth tau in direction w: J integrated exactly along w back to the face
 * it comes from. At tau = 0 with w.y > 0 the reflected radiance, at tau0 with w.y < 0 the
 * transmitted. Horizontal w (w.y = 0) gives J(tau, w), the infinite-slab limit. */
double pp_radiance(const pp_solution *s, double tau, const double w[3]);

/* Radiance leaving the slab into air at the face tau = 0 (w.y > 0) or tau0 (w.y < 0) along the
 * air-side direction w: at n = 1 exactly pp_radiance; at n > 1 the n^2 law, (1 - F) / n^2 times
 * the inside radiance along the refracted direction (same azimuth, sin_in = sin_air / n). */
double pp_exit_radiance(const pp_solution *s, const double w[3]);

/* Cell averages I_i(tau), i in [0, 2N) (up cells first, then their mirrors). */
void pp_cell_field(const pp_solution *s, double tau, double *field);

/* Fractions of the incident power cos(theta_L) E_perp: reflected and transmitted scattered
 * light, and the unscattered beam exp(-tau0/mu0); pp_absorbed the rest, computed. */
void pp_totals(const pp_solution *s, double *R, double *T, double *ballistic);
double pp_absorbed(const pp_solution *s);

/* n > 1: the entry's specular reflection F(theta_L), and the part of pp_totals' ballistic that
 * leaves through S1 (the beam reflected at S2); both 0 at n = 1. */
void pp_boundary_totals(const pp_solution *s, double *specular, double *ballistic_top);

/* Sets OpenBLAS's thread count (base/memory.h: ppb_memory_blas_threads), executing ppbench
 * again (argv) when the library started with another; first thing in main. */
void pp_blas_threads(char **argv);

/* Has OpenBLAS allocate its work buffer now, while the memory is there (base/memory.h:
 * PPB_BLAS_BUFFER_BYTES): it keeps it for the process, and a later call never waits for one.
 * Fails "out of memory: ..." when the buffer cannot be had. */
int pp_blas_reserve(ppb_err *err);

#endif
