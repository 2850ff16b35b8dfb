/* sweep_failures.h: the failed points of a sweep: a method that fails or is refused
 * at a grid point is recorded with its reason while the sweep goes on, and failures.csv beside
 * sweep.csv lists them (docs/reference.md: Outputs).
 *
 * A point's failures live beside its rows, in points/<hash>.failures.csv (one record per
 * failed method: method, reason), so resumed, parallel (--jobs) and sharded sweeps keep them
 * as they keep the rows; failures.csv is assembled from them in grid order when sweep.csv is. */
#ifndef PPB_SWEEP_FAILURES_H
#define PPB_SWEEP_FAILURES_H

#include <stdint.h>

#include "base/err.h"
#include "drivers/experiment.h"

/* After ppb_experiment_compute returned rc for the point with hash h of the sweep in out_dir:
 * writes points/<h>.failures.csv when a method failed (removes a stale one otherwise). Returns
 * the point's status: 0 when the point is done (its rows, possibly none, are to be written),
 * including when every method failed and each failure is recorded; rc otherwise. */
int ppb_sweep_failures_point(const char *out_dir, uint64_t h, const ppb_experiment *ex, int rc,
                             ppb_err *err);

/* Writes out/failures.csv: the columns of dirs[0]/grid.txt up to and including method, then
 * reason; one record per failed method of each point, in grid order, the points' failure
 * files found in any of dirs. */
int ppb_sweep_failures_assemble(const char *const *dirs, int ndirs, const char *out, ppb_err *err);

#endif
