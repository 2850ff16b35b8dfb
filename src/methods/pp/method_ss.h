/* method_ss.h: single scattering `ss` (reference: Methods; paper Eq. 5 with n = 1): the same
 * ray march as `pp` with the attenuated direct beam as the only source. */
#ifndef PPB_METHOD_SS_H
#define PPB_METHOD_SS_H

#include <stdio.h>

#include "methods/method.h"

/* Fills out[0] with the bin-averaged once-scattered exit radiance and its totals. */
int ppb_method_ss(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Whether ss has a meaning at cfg's point (the registry's check hook). */
int ppb_ss_check(const ppb_config *cfg, ppb_err *err);

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

/* ss's work hook: the march's line, then the image series' where it applies. */
void ppb_ss_work(const ppb_config *cfg, const char *id, FILE *f);

#endif
