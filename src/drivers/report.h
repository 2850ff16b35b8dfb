/* report.h: `ppbench report`: the study's summary pages from the cases' output directories.
 *
 * Reads each case's summary.csv, rms.csv and provenance.txt and writes table2.csv and
 * table2.md (every method's RMS beside the paper's Table 2 value, with the noise floor, one
 * row per case, cell and method) and README.md: the photon budget, Table 2 as the paper gives
 * it (cases x methods), the Monte Carlo's noise floor at x = 0 and per segment, the plots and
 * the images, and the case files kept in the repository, so a reader sees the study at a
 * glance (reference: Outputs).
 *
 * It replaces only files it wrote (`ppbench report . CASE` overwrote the repository's
 * README.md): each file it writes starts with a line saying so, checked before anything is
 * written. It says on stderr what it wrote, one line per file, and ends with the line
 * `ppbench report: wrote STUDY_DIR (3 files)` (as `run` says where results went).
 * The three files are written under temporary names and put in place together, with SIGINT
 * and SIGTERM held off for the renames (ppb_apaths_commit): never new tables beside an old
 * README. */
#ifndef PPB_REPORT_H
#define PPB_REPORT_H

#include "base/err.h"

/* What ppb_report_write returns when a file it would write is not its own, and when a case is
 * missing or unreadable (bad input): nothing written, exit code 2 either way. */
enum { PPB_REPORT_REFUSED = -2, PPB_REPORT_BAD_INPUT = -3 };

/* study_dir holds one directory per case (names as in cases[]). Returns 0, -1 (a write
 * failed), PPB_REPORT_REFUSED or PPB_REPORT_BAD_INPUT (a case's summary.csv unreadable). */
int ppb_report_write(const char *study_dir, const char *const *cases, int ncases, ppb_err *err);

#endif
