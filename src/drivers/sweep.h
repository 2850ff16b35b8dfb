/* sweep.h: parameter grid sweeps (`ppbench sweep`, `ppbench merge`).
 *
 * A config whose numeric keys hold lists expands into the Cartesian product of its values.
 * Every grid point runs every method; its rows of sweep.csv from the method on (RMS at x = 0
 * and per surface, noise floor, totals) are written atomically to points/<hash>.rows2.csv, the
 * hash being that of the point's resolved settings, so a re-run skips finished points and
 * recomputes changed ones; the point index and swept values are prefixed from the current grid
 * (grid.txt) when sweep.csv is assembled, so a grown grid reuses its finished points.
 * --shard I/N takes the points with index % N == I - 1; merge concatenates shard directories'
 * points in grid order into one sweep.csv, byte-identical to a whole run, and refuses shards
 * of another grid. Timings go to timings.csv beside it, never into sweep.csv. --jobs J runs J
 * processes on this machine, each taking every J-th point of the shard; they die with it.
 * An interrupted sweep keeps its finished points and returns 0 (the caller exits 130). */
#ifndef PPB_SWEEP_H
#define PPB_SWEEP_H

#include "base/err.h"
#include "model/config.h"
#include "model/grid.h"

#define PPB_SWEEP_BAD_CONFIG 2
#define PPB_SWEEP_MAX_POINTS 10000 /* larger grids need --yes */

typedef struct ppb_sweep_opts {
    const char *device;
    int quiet, yes;
    int shard_i, shard_n;  /* 1-based part of n */
    int jobs;              /* processes on this machine (each opens the device), 1 = serial */
    const char *ref_cache; /* every point's Monte Carlo reference cache (mc_cache.h), or NULL */
} ppb_sweep_opts;

/* Runs the grid points of cfg (its keys holding lists, loaded into grid by
 * ppb_config_load_grid). Returns 0, -1 on a run failure, PPB_SWEEP_BAD_CONFIG when the grid
 * is refused before any work starts. */
int ppb_sweep_run(const ppb_config *cfg, const ppb_grid *grid, const ppb_sweep_opts *o,
                  ppb_err *err);
/* Returns 0, -1, or PPB_SWEEP_BAD_CONFIG for shards whose grids differ (the message names the
 * shard directory). */
int ppb_sweep_merge(const char *const *dirs, int n, const char *out_dir, ppb_err *err);

#endif
