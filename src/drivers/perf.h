/* perf.h: `ppbench perf` / `make perf`: every benchmark, printed with the device name. Speed
 * targets live here, as printed figures and ratios measured in the same run, never in tests. */
#ifndef PPB_PERF_H
#define PPB_PERF_H

#include <stdio.h>

#include "methods/method.h"

int ppb_perf_all(ppb_run_ctx *ctx, FILE *out, ppb_err *err);

#endif
