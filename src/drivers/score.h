/* score.h: `ppbench score RADIANCE.csv --ref DIR [--out DIR2]` (docs/external.md):
 * scores the methods of a radiance file against a finished experiment, as `run` would have.
 *
 * The experiment's settings come from DIR/provenance.txt (its resolved config), the reference's
 * rows from DIR/radiance.csv; every method of RADIANCE.csv but the reference and its companion
 * is read and checked as an external method's output (methods/method_external.h), its totals
 * taken from the totals.csv beside RADIANCE.csv when that exists (else integrated), and the
 * summary, rms, regions and totals rows written into DIR2 by the run's own writers
 * (io/csv.h). DIR is never written: DIR2 defaults to DIR-score (DIR-score-2, ... when taken). */
#ifndef PPB_SCORE_H
#define PPB_SCORE_H

/* The command: returns its exit code (0; 1 a failure reading or writing; 2 bad operands, with
 * the message printed). Unless quiet, ends with drivers/summary_table.h's table on stdout. */
int ppb_score_main(const char *radiance, int nargs, const char *ref_dir, const char *out_dir,
                   int quiet);

#endif
