/* work_estimate.h: the work of a run estimated before anything is allocated (issue 15), said in
 * the run's first lines: the Monte Carlo's photons x expected events per photon, the marcher's
 * rays x steps (pp, ss, mp+ss), and the bytes of the experiment's result arrays, which the
 * experiment checks against [run] memory_limit (base/memory.h) before it allocates them. The
 * estimates are orders of magnitude, not predictions: they say what a setting costs. */
#ifndef PPB_WORK_ESTIMATE_H
#define PPB_WORK_ESTIMATE_H

#include <stdio.h>

#include "model/config.h"

/* Expected scattering events per Monte Carlo photon: with implicit capture a photon's weight
 * after k events is albedo^k, rouletted below PPB_MC_ROULETTE_W, so about
 * ln(w) / ln(albedo) events; a walk leaves a medium of optical size L (the tube's smaller side,
 * the slab's thickness) after about 1 + L + L^2 events (diffusion); capped at PPB_MC_EVENT_CAP
 * (kernels/mc_params.h). The least of the three. */
double ppb_work_mc_events(const ppb_config *cfg);

/* Rays the marcher traces (cells x samples_dir^2 x samples_seg) and steps along the longest
 * (the tube's diagonal or the slab's thickness at the bins' most grazing direction, over the
 * march step). */
void ppb_work_march(const ppb_config *cfg, double *rays, double *steps);

/* Bytes of the experiment's result arrays: radiance and standard error per cell, per result
 * (a method with a companion result, mc's mc1, holds two). */
double ppb_work_results_bytes(const ppb_config *cfg);

/* One line per method of cfg whose work scales with the settings, "NAME: METHOD: work: ...". */
void ppb_work_print(FILE *f, const ppb_config *cfg);

#endif
