/* sweep_plot.h: the plots of a sweep (reference: Sweeps), drawn by gnuplot
 * as PNG and PDF with scripts/plot_style.gp's colours and palette. Two or more swept keys:
 * <dir>/heatmap_<method>.{png,pdf} for every method but the reference, its RMS at x = 0 on S1
 * (R) and S2 (T) in percent over the first two keys, one cell per grid point (index-spaced,
 * the values on the tics), the value printed in each cell, viridis; one row of panels per
 * value of a third key (its first 6 values, said in the title when there are more); keys
 * beyond the third at their first value, named in the title. One swept key:
 * <dir>/sweep_rms.{png,pdf}, the RMS of R and T against the key, a line per method. */
#ifndef PPB_SWEEP_PLOT_H
#define PPB_SWEEP_PLOT_H

#include "io/plots.h"
#include "model/config.h"
#include "model/grid.h"

/* Draws the figures above; one that cannot be drawn is said on stderr and in fig, and left
 * out: a sweep's figures never fail it (reference: Sweeps). */
void ppb_sweep_heatmaps(const ppb_config *cfg, const ppb_grid *grid, const char *dir,
                        ppb_figures *fig);

#endif
