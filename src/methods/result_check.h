/* result_check.h: what every deterministic method's output is checked for before it is written
 * (issue 15): no NaN or inf (the method fails with where it happened, nothing is written for
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

/* Fails when a total is not finite; reports on stderr when R + T + sides + ballistic exceeds
 * 1 + PPB_ENERGY_TOL. */
int ppb_totals_check(const char *name, const ppb_result *r, ppb_err *err);

#endif
