/* perf_mc.h: the Monte Carlo throughput benchmark (issue 4): photons/s and scattering events/s
 * of kernels/mc.cl on the chosen device, for the uniform tube (reference: Cases) at g = 0 and
 * g = 0.5 (normal incidence, alpha = 0.95), printed with the device name and the 20 M events/s
 * target. */
#ifndef PPB_PERF_MC_H
#define PPB_PERF_MC_H

#include <stdio.h>

#include "methods/method.h"

int ppb_perf_mc(ppb_run_ctx *ctx, FILE *out, ppb_err *err);

#endif
