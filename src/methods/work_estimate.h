/* work_estimate.h: the work of a run estimated before anything is allocated, said in the run's
 * first lines: each method's own estimate (its registry entry's work hook: the Monte Carlo's
 * photons x expected events per photon, the marcher's rays x steps), and the bytes of the
 * experiment's result arrays, which the experiment checks against [run] memory_limit
 * (base/memory.h) before it allocates them. The estimates are orders of magnitude, not
 * predictions: they say what a setting costs. */
#ifndef PPB_WORK_ESTIMATE_H
#define PPB_WORK_ESTIMATE_H

#include <stdio.h>

#include "model/config.h"

/* Bytes of the experiment's result arrays: radiance and standard error per cell, per result
 * (a method with a companion result, mc's mc1, holds two). */
double ppb_work_results_bytes(const ppb_config *cfg);

/* One line per method of cfg whose work scales with the settings, "NAME: METHOD: work: ..."
 * (each method's work hook; a sum says its parts' under its own id). */
void ppb_work_print(FILE *f, const ppb_config *cfg);

#endif
