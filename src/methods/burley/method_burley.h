/* method_burley.h: Christensen & Burley 2015's normalized diffusion profile applied to the tube
 * as a renderer applies a BSSRDF (reference: Methods, `burley`): method id `burley`.
 * `burley+ss` is the registry's sum of burley and ss (method.h: ppb_method_sum). */
#ifndef PPB_METHOD_BURLEY_H
#define PPB_METHOD_BURLEY_H

#include "methods/method.h"

/* `burley`: fills out[0] (already initialised with the scene's layout). */
int ppb_method_burley(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Whether burley has a meaning at cfg's point: it has on every valid medium (A is defined and
 * s_fit(A) > 0 for every albedo, g and n); refuses only settings it cannot honour. */
int ppb_burley_check(const ppb_config *cfg, ppb_err *err);

/* The total diffuse reflectance A of the semi-infinite medium (albedo, g, n) under the scene's
 * beam (cos theta_L in air), per unit power entering: every scattering order, its exit through
 * the boundary included, from the plane-parallel solver (physics/ppsolver.h) on a slab thick
 * enough that nothing returns from its far face (tau0 = 40 / sigma_tr, at least 50). The
 * solver's R converges like 1/cells, so A is the Richardson extrapolation 2 R(2N) - R(N) from
 * N = `directions` and 2N cells (against Chandrasekhar's H-function at g = 0: within 5e-5 at
 * N = 334, where R(N) alone is up to 1.4e-3 off; tests/test_burley.c). Exactly 1 at albedo 1
 * (nothing is absorbed and nothing crosses a semi-infinite medium), 0 at albedo 0. */
int ppb_burley_albedo(double albedo, double g, double n, double cos_theta_l, int directions,
                      double *A, ppb_err *err);

#endif
