/* perf_mc.h: the Monte Carlo throughput benchmark: photons/s and scattering events/s
 * of kernels/mc.cl on the chosen device, for the uniform tube (reference: Cases) at g = 0 and
 * g = 0.5 (normal incidence, alpha = 0.95), printed with the device name and the 20 M events/s
 * target, and the figure of merit: the seconds to reach a 1% and a 0.5% noise floor
 * at the Table 2 cells (noise_rel at the x = 0 cells of S1 and S2, the larger), from the timed
 * run's noise scaled as 1/sqrt(photons). */
#ifndef PPB_MC_PERF_H
#define PPB_MC_PERF_H

#include <stdio.h>

#include "methods/method.h"

int ppb_perf_mc(ppb_run_ctx *ctx, FILE *out, ppb_err *err);

#endif
