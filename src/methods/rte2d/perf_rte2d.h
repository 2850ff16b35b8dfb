/* perf_rte2d.h: the benchmark of `rte2d` as a reference: on every study case
 * (configs/study.list, or the comma-separated $PPBENCH_PERF_RTE2D_CASES), the converged solve at
 * the case's settings (its seconds, sweeps, exit march), its estimated distance to its own limit
 * (Richardson from the grid and track spacing halved and from the direction cells doubled, the
 * worst summary cell's rms_rel), and the Monte Carlo's time to that accuracy: its rate and noise
 * measured in the same run on the same case ($PPBENCH_PERF_MC_PHOTONS photons, default 4e6),
 * scaled as noise ~ 1/sqrt(photons). The Monte Carlo comes from ppb_run_ctx.reference (set by
 * `ppbench perf`); without it those columns are nan. */
#ifndef PPB_RTE2D_PERF_H
#define PPB_RTE2D_PERF_H

#include <stdio.h>

#include "base/err.h"
#include "methods/method.h"

int ppb_perf_rte2d(ppb_run_ctx *ctx, FILE *out, ppb_err *err);

#endif
