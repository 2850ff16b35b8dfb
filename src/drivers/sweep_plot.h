/* sweep_plot.h: the heat map of a sweep (issue 8): each method's RMS at x = 0 on S1 (R) and S2
 * (T) over the first two swept parameters, the others held at their first value, drawn by
 * gnuplot into <dir>/heatmap_<method>.png. */
#ifndef PPB_SWEEP_PLOT_H
#define PPB_SWEEP_PLOT_H

#include "base/err.h"
#include "model/config.h"
#include "model/grid.h"

int ppb_sweep_heatmaps(const ppb_config *cfg, const ppb_grid *grid, const char *dir, ppb_err *err);

#endif
