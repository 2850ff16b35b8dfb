/* summary_table.h: the short table `run` and `score` print on stdout at the end (reference:
 * Outputs, "The table on stdout"): each measured method's rms_excess at the summary cells (the
 * Table 2 cells R_x0, T_x0 and every surface), beside the noise floor noise_rel, both in %.
 * The numbers are summary.csv's: model/metrics.h's ppb_cell_points and ppb_rms_points, the
 * functions io/csv.c writes summary.csv with. */
#ifndef PPB_SUMMARY_TABLE_H
#define PPB_SUMMARY_TABLE_H

#include <stdio.h>

#include "model/result.h"

/* Prints the table for the results rs[0..n) against ref (one of rs), leaving out ref and the
 * result named skip (its companion, e.g. mc1; NULL for none), titled with name. Prints nothing
 * when no result is measured. */
void ppb_summary_table_print(FILE *f, const char *name, const ppb_result *rs, int n,
                             const ppb_result *ref, const char *skip);

#endif
