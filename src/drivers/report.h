/* report.h: `ppbench report`: the study's summary pages from the cases' output directories.
 *
 * Reads each case's summary.csv and totals.csv and writes table2.csv and table2.md (every
 * method's RMS beside the paper's Table 2 value, with the noise floor) and README.md with the
 * tables, the plots and the images, so a reader sees the study at a glance. */
#ifndef PPB_REPORT_H
#define PPB_REPORT_H

#include "base/err.h"

/* study_dir holds one directory per case (names as in cases[]). */
int ppb_report_write(const char *study_dir, const char *const *cases, int ncases, ppb_err *err);

#endif
