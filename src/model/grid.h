/* grid.h: the sweep grid of a config: the swept keys (axes) with their values, the number of
 * grid points and the expansion of a point index into one value index per axis (row-major over
 * the axes in the order their keys were set, the last axis fastest).
 *
 * Kept out of ppb_config, so that a config stays a few KB of plain values: whoever loads a
 * config that may be a sweep owns a heap-allocated grid (ppb_grid_new) and passes it to
 * ppb_config_load_grid(), which fills it, and to ppb_config_point(), which applies one point.
 * An axis names its key by the key's index in the config's key table (model/config.h). */
#ifndef PPB_GRID_H
#define PPB_GRID_H

#define PPB_MAX_AXES 8    /* swept keys */
#define PPB_MAX_LIST 1024 /* values of one swept key */
/* Points of a grid, a hard limit (a sweep's --yes lifts only the drivers' soft one): keeps the
 * point count far inside long long, however many axes multiply. */
#define PPB_GRID_MAX_POINTS 10000000LL

typedef struct ppb_axis {
    int key;        /* index in the key table (ppb_config_key_name) */
    int n;          /* values, >= 2 */
    double *values; /* [n], owned by the grid */
} ppb_axis;

typedef struct ppb_grid {
    int naxes;
    ppb_axis axes[PPB_MAX_AXES];
} ppb_grid;

/* An empty grid (one point), or NULL when out of memory; ppb_grid_free(NULL) does nothing. */
ppb_grid *ppb_grid_new(void);
void ppb_grid_free(ppb_grid *g);

/* Removes every axis. */
void ppb_grid_clear(ppb_grid *g);

/* Appends an axis over key with a copy of values[0..n). Returns -1 when the grid already has
 * PPB_MAX_AXES axes, n is outside [2, PPB_MAX_LIST], the grid would exceed PPB_GRID_MAX_POINTS
 * points or memory runs out; nothing changes then. */
int ppb_grid_add(ppb_grid *g, int key, const double *values, int n);

/* Removes the axis over key, if any (a key set again replaces its earlier list). */
void ppb_grid_remove(ppb_grid *g, int key);

/* Number of grid points: the product of the axes' sizes, 1 for NULL or no axis; at most
 * PPB_GRID_MAX_POINTS for a grid built by ppb_grid_add (LLONG_MAX should a caller have filled
 * the axes itself beyond that: never a wrapped count). */
long long ppb_grid_npoints(const ppb_grid *g);

/* Value of axis a at grid point i, 0 <= i < ppb_grid_npoints(g). */
double ppb_grid_value(const ppb_grid *g, int a, long long i);

#endif
