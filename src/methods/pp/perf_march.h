/* perf_march.h: the ray marcher's benchmark: ray-march evaluations per second and the
 * time of one whole tube case (every segment x every bin) for `pp` (S and R tables) and `ss` on
 * the device, beside the host time to build the maps and tables. */
#ifndef PPB_PP_PERF_MARCH_H
#define PPB_PP_PERF_MARCH_H

#include <stdio.h>

#include "methods/method.h"

/* Runs on ctx->cfg's scene and settings forced to the tube geometry. */
int ppb_perf_march(ppb_run_ctx *ctx, FILE *out, ppb_err *err);

#endif
