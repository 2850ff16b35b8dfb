/* metrics.h: the error metrics (reference: Metrics).
 *
 * rms_rel of a method against a reference over a set of sample points, the reference's noise
 * floor from its standard errors, and rms_excess = sqrt(max(0, rms^2 - noise^2)). When the
 * compared method has standard errors of its own (mc against ppslab), they add to the noise
 * floor in quadrature; for a deterministic method against mc this is exactly the
 * noise_rel. Also the Table 2 cells (the two segments next to x = 0) and the regions of the
 * tube's top and bottom (segments away from, at, or near the medium's step and the walls) that
 * the regression gate and the plots read from regions.csv instead of re-deriving them. */
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

/* The metrics with every bin's w_k equal (pi / (ntheta nphi) each, reference: Bins): the
 * common factor cancels and is left out. */
ppb_rms ppb_rms_points(const ppb_result *m, const ppb_result *ref, const ppb_point *pts, int n);

/* The same with explicit weights: w[k] (k < nbins) is bin k's projected solid angle w_k; NULL
 * means equal bins (exactly ppb_rms_points). */
ppb_rms ppb_rms_points_w(const ppb_result *m, const ppb_result *ref, const ppb_point *pts, int n,
                         const double *w);

/* noise_rel of one result over the points: sqrt(sum w_k se^2 / sum w_k L^2); NAN where the
 * radiance is 0 everywhere. */
double ppb_noise_points(const ppb_result *r, const ppb_point *pts, int n);

/* The summary cells (reference: Metrics), in output order. */
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

/* The regions of regions.csv, in output order, for S1 then S2 (the surfaces along x), with
 * x0 = step_x (the medium's step; 0, the tube's centre, when there is none):
 *   x<x0-2, x>x0+2 and |x-x0|<=2 split each surface's segments (by centre s) into the part left
 *   of the step, right of it, and the 4 mfp around it, every segment in exactly one;
 *   x<-W/2+3 and x>W/2-3 are the segments within 3 mfp of the walls S3 and S4.
 * The side walls S3/S4 are not split (summary.csv's S3_all/S4_all cover them). */
enum {
    PPB_REGION_LEFT,
    PPB_REGION_RIGHT,
    PPB_REGION_STEP,
    PPB_REGION_WALL_LEFT,
    PPB_REGION_WALL_RIGHT,
    PPB_NREGIONS_PER_SURF,
    PPB_NREGIONS = 2 * PPB_NREGIONS_PER_SURF /* S1's, then S2's */
};

/* "S1:x>x0+2" etc.: the name regions.csv and tests/thresholds.txt use. */
const char *ppb_region_name(int region);

/* Points of a region; returns how many were written to pts (at most cap); 0 in slab mode,
 * which has no x. */
int ppb_region_points(const ppb_scene *sc, const ppb_layout *lo, int region, ppb_point *pts,
                      int cap);

#endif
