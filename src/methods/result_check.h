/* result_check.h: what every deterministic method's output is checked for before it is written
 *: no NaN or inf (the method fails with where it happened, nothing is written for
 * it), no negative radiance (clamped to 0, counted and reported on stderr: a clamp is never
 * silent), and the energy sum R + T + sides + ballistic within a tolerance of at most 1
 * (reported when above; the values stay as computed: where a model is poor, as pp off the centre
 * of a thick tube, that is the model's answer, not a defect to hide). */
#ifndef PPB_RESULT_CHECK_H
#define PPB_RESULT_CHECK_H

#include "base/err.h"
#include "model/result.h"

/* Tolerance of the energy sum above 1 before it is reported. */
#define PPB_ENERGY_TOL 1e-3

/* Fails when a cell of r is not finite; clamps negative cells to 0 and reports how many (and
 * the most negative value) on stderr under `name` (the experiment's). Returns the count of
 * clamped cells through *clamped (may be NULL). */
int ppb_radiance_check(const char *name, ppb_result *r, long *clamped, ppb_err *err);

/* Round-off of a total, relative to the sum of the totals' magnitudes: a negative R, T, sides or
 * ballistic above -PPB_TOTAL_ROUNDOFF times that sum is the rounding or the solver's residual in
 * a total that is 0 to the method's accuracy (rte2d's sides on a 0.001-mfp tube: -4.7e-14 of 1,
 * and -6.3e-13 of 0.104 at 89 deg; its GMRES stops at a relative residual of 1e-7) and is set to
 * 0; below it, it is an error. */
#define PPB_TOTAL_ROUNDOFF 1e-9

/* Fails when a total is not finite or is negative beyond round-off (PPB_TOTAL_ROUNDOFF), sets
 * a round-off negative one to 0; reports on stderr when R + T + sides + ballistic exceeds
 * 1 + PPB_ENERGY_TOL. */
int ppb_totals_check(const char *name, ppb_result *r, ppb_err *err);

/* ppb_totals_check on r's totals with absorbed completed (ppb_totals_complete) as the writer
 * completes it, for a method that does not track absorption: the round-off clamps land in r,
 * absorbed stays as the method left it. */
int ppb_totals_check_completed(const char *name, ppb_result *r, ppb_err *err);

#endif
