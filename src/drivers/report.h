/* report.h: `ppbench report`: the study's summary pages from the cases' output directories.
 *
 * Reads each case's summary.csv and totals.csv and writes table2.csv and table2.md (every
 * method's RMS beside the paper's Table 2 value, with the noise floor) and README.md with the
 * tables, the plots and the images, so a reader sees the study at a glance.
 *
 * It replaces only files it wrote (issue 14: `ppbench report . CASE` overwrote the repository's
 * README.md): each file it writes starts with a line saying so, checked before anything is
 * written, and it says on stderr what it wrote, one line per file. */
#ifndef PPB_REPORT_H
#define PPB_REPORT_H

#include "base/err.h"

/* What ppb_report_write returns when a file it would write is not its own (nothing written). */
enum { PPB_REPORT_REFUSED = -2 };

/* study_dir holds one directory per case (names as in cases[]). Returns 0, -1 (a case's
 * summary.csv unreadable, a write failed) or PPB_REPORT_REFUSED. */
int ppb_report_write(const char *study_dir, const char *const *cases, int ncases, ppb_err *err);

#endif
