/* march_tables.h: the integral tables of the ray march (paper Sec. 3.2-3.3, Eq. 15-17) and the
 * per-direction coefficient of the attenuated beam, for every direction sample of every bin.
 *
 * The marched source at a point with light-path optical depth D, tau = D cos(theta_L), average
 * albedo abar, local albedo alpha and extinction sigma_t is (SPEC.md section 7)
 *     sigma_t alpha [ R(tau; w) + C(w) exp(-D) ],
 * R(tau; w) = sum_k A_k(w) e_k(tau)  (paper Eq. 15: A_k = the slab's a_k / abar, its modes'
 *             angular integral P_Vj c_j; the slab solution at abar, Sec. 3.3),
 * C(w)      = p(w.w_L) + b(w) / abar  (the direct beam's single scattering and the particular
 *             part of the diffuse field; the beam is handled analytically, not tabulated).
 * The S table (Eq. 16-17, derived afresh: SPEC.md section 10) integrates R along a step where
 * tau = tau1 + r0 sigma_t l, r0 = w_y being the slab's slope:
 *     integral_0^h e^{-sigma_t l} sigma_t R(tau1 + r0 sigma_t l) dl = e^{-sigma_t h} S(tau2) -
 * S(tau1), S(tau) = sum_k A_k e_k(tau) / (lambda_k r0 - 1)  + any multiple of e^{tau / r0}, and the
 * table stores the well-conditioned member that vanishes at the far face of the slab (tau* = tau0
 * when r0 > 0, 0 when r0 < 0): S(tau) = -(delta/r0) sum_k A_k e_k(tau) phi((lambda_k - 1/r0)
 * delta),  delta = tau* - tau, phi(z) = (e^z - 1)/z, which has no pole where lambda_k r0 = 1 and
 * equals minus the slab's radiance from the modes: the march of a whole slab returns the slab's own
 * field. Layout: [albedo node][direction][tau node], tau nodes uniform on [0, tau0], albedo nodes
 * uniform on the range of albedos the medium holds (one node for a uniform albedo). */
#ifndef PPB_MARCH_TABLES_H
#define PPB_MARCH_TABLES_H

#include "config.h"
#include "err.h"
#include "scene.h"

typedef struct ppb_march_tables {
    int nsamp; /* direction samples per bin axis */
    int ndir;  /* nsurf x nbins x nsamp^2, ordered by ppb_march_dir_index */
    int nalb;  /* albedo nodes */
    double alb0, alb_h;
    int ntau; /* tau nodes, tau0 / tau_h + 1 */
    double tau0, tau_h;
    int nmodes; /* modes of the slab solution, and how many the tables keep (n_e) */
    int modes_kept;
    double *R; /* [nalb][ndir][ntau], NULL for ss */
    double *S; /* [nalb][ndir][ntau], NULL unless the S table was asked for */
    double *C; /* [nalb][ndir] */
} ppb_march_tables;

/* Single scattering: C = p(w.w_L), no tables. */
int ppb_march_tables_ss(const ppb_scene *sc, int nsamp, ppb_march_tables *t, ppb_err *err);

/* The plane-parallel tables: a slab solution (src/ppsolver.h) of optical thickness
 * sigma_t H at every albedo node; the R table always (the S march falls back to it on steps whose
 * slope is not the slab's), the S table when pp->table asks for it. tau_per_mfp sets the tau
 * resolution. */
int ppb_march_tables_pp(const ppb_scene *sc, const ppb_pp_settings *pp, int nsamp, int tau_per_mfp,
                        ppb_march_tables *t, ppb_err *err);

void ppb_march_tables_free(ppb_march_tables *t);

#endif
