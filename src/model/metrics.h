/* metrics.h: the error metrics of SPEC.md section 5.
 *
 * rms_rel of a method against a reference over a set of sample points, the reference's noise
 * floor from its standard errors, and rms_excess = sqrt(max(0, rms^2 - noise^2)). When the
 * compared method has standard errors of its own (mc against ppslab), they add to the noise
 * floor in quadrature; for a deterministic method against mc this is exactly SPEC.md's
 * noise_rel. Also the Table 2 cells (the two segments next to x = 0). */
#ifndef PPB_METRICS_H
#define PPB_METRICS_H

#include "model/result.h"

typedef struct ppb_rms {
    double rms_rel, noise_rel, rms_excess;
} ppb_rms;

/* A sample point: surface and segment. */
typedef struct ppb_point {
    int surf, seg;
} ppb_point;

ppb_rms ppb_rms_points(const ppb_result *m, const ppb_result *ref, const ppb_point *pts, int n);

/* noise_rel of one result over the points: sqrt(sum w_k se^2 / sum w_k L^2); NAN where the
 * radiance is 0 everywhere. */
double ppb_noise_points(const ppb_result *r, const ppb_point *pts, int n);

/* The summary cells of SPEC.md section 5, in output order. */
enum {
    PPB_CELL_R_X0,
    PPB_CELL_T_X0,
    PPB_CELL_S1_ALL,
    PPB_CELL_S2_ALL,
    PPB_CELL_S3_ALL,
    PPB_CELL_S4_ALL,
    PPB_NCELLS
};
const char *ppb_cell_name(int cell);

/* Points of a summary cell; returns how many were written to pts (at most the surface's
 * segments); 0 when the surface does not exist (S3/S4 in slab mode). */
int ppb_cell_points(const ppb_layout *lo, int cell, ppb_point *pts, int cap);

#endif
