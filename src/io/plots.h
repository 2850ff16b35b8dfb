/* plots.h: an output set's figures (reference: Outputs): runs scripts/plots.sh, which draws them
 * with gnuplot from the set's CSVs and images into <dir>/plots/ and <dir>/images/ (PNG and PDF).
 * Owns the running of the script (what it plots and how is the script's) and one figure of its
 * own, plots/rte2d_refinements.{png,pdf} from rte2d_refinements.csv when the set has one. Found as
 * $PPBENCH_SCRIPTS/plots.sh, else PPB_SCRIPT_DIR/plots.sh (the Makefile sets the source tree's
 * scripts/), as the kernels are found. */
#ifndef PPB_PLOTS_H
#define PPB_PLOTS_H

#include "base/err.h"

/* The folder holding plots.sh and plot_style.gp (the style every gnuplot script loads). */
const char *ppb_plots_script_dir(void);

/* Draws the figures of the output set in dir (already holding its CSVs, provenance.txt and
 * images) of the experiment called name (the figures' titles); fails, naming the script, when
 * it cannot be started or exits non-zero, and when gnuplot fails on the refinements figure. */
int ppb_plots_write(const char *dir, const char *name, ppb_err *err);

#endif
