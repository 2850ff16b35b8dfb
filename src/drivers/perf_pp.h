/* perf_pp.h: the plane-parallel solver's benchmark: median times of the stages of a
 * full slab solve (src/physics/ppsolver.h) at M = 668 and M = 128, on one core. */
#ifndef PPB_PERF_PP_H
#define PPB_PERF_PP_H

#include <stdio.h>

#include "base/err.h"

/* Prints one line per M: phase matrix, eigendecomposition, boundary solve (particular solution,
 * boundary systems, totals), the full solve, and one direction's evaluation (pp_radiance), each
 * the median of several runs. Sets OpenBLAS to one thread (restoring nothing: the benchmark
 * measures one core). */
int ppb_perf_ppsolver(FILE *out, ppb_err *err);

#endif
