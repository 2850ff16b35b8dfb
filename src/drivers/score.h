/* score.h: `ppbench score RADIANCE.csv --ref DIR [--out DIR2]` (docs/external.md):
 * scores the methods of a radiance file against a finished experiment, as `run` would have.
 *
 * The experiment's settings come from DIR/provenance.txt (its resolved config), the reference's
 * rows from DIR/radiance.csv; every method of RADIANCE.csv but the reference and its companion
 * is read and checked as an external method's output (methods/method_external.h), its totals
 * taken from the totals.csv beside RADIANCE.csv when that exists (else integrated), and the
 * summary, rms, regions and totals rows written into DIR2 by the run's own writers
 * (io/csv.h), with a provenance.txt marking DIR2 as score's output set. DIR is never written:
 * DIR2 defaults to DIR-score (DIR-score-2, ... when taken). DIR2 is claimed as run claims its
 * directory (ppb_out_claim: new, empty or an earlier score's set; locked) and replaced whole
 * (staged, checked, swapped), so an interrupted score leaves the previous set as it was. */
#ifndef PPB_SCORE_H
#define PPB_SCORE_H

/* The command: returns its exit code (0; 1 a failure writing; 2 bad operands or input files
 * (RADIANCE.csv, DIR), or a DIR2 that is not score's; 130 interrupted, nothing written), the
 * message printed. quiet: no "score: wrote" line; unless quiet, it ends with
 * drivers/summary_table.h's table on stdout. */
int ppb_score_main(const char *radiance, int nargs, const char *ref_dir, const char *out_dir,
                   int quiet);

#endif
