/* perf_rte2d.h: the benchmark of `rte2d`: one converged study case (the run's
 * config, default the uniform g = 0 tube) on the device, its time per case (with the refinement
 * study, as `ppbench run` pays it) and per refinement (one march over the grid), the study's
 * share, and the solve's size. */
#ifndef PPB_RTE2D_PERF_H
#define PPB_RTE2D_PERF_H

#include <stdio.h>

#include "base/err.h"
#include "methods/method.h"

int ppb_perf_rte2d(ppb_run_ctx *ctx, FILE *out, ppb_err *err);

#endif
