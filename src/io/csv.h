/* csv.h: the CSV files of SPEC.md section 8, written once here for every method.
 *
 * radiance.csv, rms.csv, summary.csv and totals.csv keep SPEC.md's names and column order.
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
int ppb_write_totals_csv(const char *path, const ppb_result *rs, int n, ppb_err *err);

#endif
