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

/* The beam's image series of ss at n > 1 in the tube at oblique light (kernels/ppb_beam_images.h):
 * rays, the legs of a viewing ray (up to d_cap = 40 over the smaller side's optical size, at most
 * 4096), the depth rows j one leg sums (until F_b^j e^(-j a) falls below the series' tolerance
 * 2^-60, or the beam's depth reaches d_cap), the tiles per row, and their product `terms`. */
typedef struct ppb_work_img {
    double rays, legs, rows, per_row, terms;
} ppb_work_img;

/* The most image terms a run may sum: ss refuses a config above it before any work
 * (docs/reference.md: Methods). The estimate's legs are an upper bound: about 4e8 estimated
 * terms went by a second on 2 CPU cores (a 0.01 mfp tube at 89 deg, n = 2.5), so this is
 * minutes of work. */
#define PPB_WORK_IMAGE_TERMS_MAX 1e11

/* Fills w and returns 1 when the images apply (tube, n > 1, oblique light), else 0. */
int ppb_work_images(const ppb_config *cfg, ppb_work_img *w);

/* Bytes of the experiment's result arrays: radiance and standard error per cell, per result
 * (a method with a companion result, mc's mc1, holds two). */
double ppb_work_results_bytes(const ppb_config *cfg);

/* One line per method of cfg whose work scales with the settings, "NAME: METHOD: work: ...". */
void ppb_work_print(FILE *f, const ppb_config *cfg);

#endif
