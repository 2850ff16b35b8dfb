/* csv.h: the CSV files (reference: Outputs), written once here for every method.
 *
 * radiance.csv, rms.csv, summary.csv and totals.csv keep their specified names and column order.
 * regions.csv (method, region, rms_rel, noise_rel, rms_excess) adds the RMS over the regions of
 * model/metrics.h (S1/S2 away from, around and near the step and the walls), which the
 * regression gate and the plots read instead of re-deriving the Metrics from radiance.csv.
 * Results are written in the order given; `ref` is the result every other one is measured
 * against, and `skip` (may be NULL) names a result left out of the RMS files besides the
 * reference (its companion: mc1 beside mc). Every file goes through atomic_file. */
#ifndef PPB_CSV_H
#define PPB_CSV_H

#include "base/err.h"
#include "model/result.h"
#include "model/scene.h"

int ppb_write_radiance_csv(const char *path, const ppb_scene *sc, const ppb_result *rs, int n,
                           ppb_err *err);
int ppb_write_rms_csv(const char *path, const ppb_scene *sc, const ppb_result *rs, int n,
                      const ppb_result *ref, const char *skip, ppb_err *err);
int ppb_write_summary_csv(const char *path, const ppb_result *rs, int n, const ppb_result *ref,
                          const char *skip, ppb_err *err);
int ppb_write_regions_csv(const char *path, const ppb_scene *sc, const ppb_result *rs, int n,
                          const ppb_result *ref, const char *skip, ppb_err *err);
/* angular.csv: every result's radiance at the Table 2 cells (S1's R_x0, S2's T_x0 points),
 * averaged over the cell's segments, per bin with the bin centre's theta and phi in degrees and
 * the mean's standard error: what the angular plot (paper Fig. 5) reads. */
int ppb_write_angular_csv(const char *path, const ppb_scene *sc, const ppb_result *rs, int n,
                          ppb_err *err);
int ppb_write_totals_csv(const char *path, const ppb_result *rs, int n, ppb_err *err);

#endif
