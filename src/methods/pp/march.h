/* march.h: the host side of the ray marcher shared by `pp` and `ss` (paper Sec. 3.4, Fig. 3's
 * rendering process; reference: Bins, Methods): uploads the light maps (maps.h) and the tables
 * (march_tables.h) and runs march.cl over every (segment, bin) cell (reference: Bins); the
 * totals from the bin radiance are physics/totals.h's. */
#ifndef PPB_MARCH_H
#define PPB_MARCH_H

#include "kernels/march_params.h"
#include "physics/maps.h"
#include "physics/march_tables.h"
#include "methods/method.h"

typedef struct ppb_march_opts {
    int table;     /* PPB_TABLE_R or PPB_TABLE_S (ignored without tables) */
    double step;   /* step length, mfp */
    int telescope; /* 1: closed form of a regular piece's S-table step sum (an identity) */
    int npts;      /* points per segment (tube) */
    double d_cap;  /* optical distance where the march stops; 0 = the default (40) */
} ppb_march_opts;

/* A marcher ready to launch: program, kernel and device buffers. */
typedef struct ppb_marcher {
    ppb_ocl *ocl;
    cl_program prog;
    cl_kernel kernel;
    cl_mem map, tab_r, tab_s, coef_c, out;
    int rows, nbins;
    ppb_march_params params; /* of every launch; row0 set per launch */
} ppb_marcher;

int ppb_marcher_init(ppb_marcher *mr, ppb_ocl *ocl, const ppb_scene *sc, const ppb_maps *maps,
                     const ppb_march_tables *tab, const ppb_march_opts *opts, ppb_err *err);
/* Marches rows [row0, row0 + nrows) of the layout and waits for them. */
int ppb_marcher_run(ppb_marcher *mr, int row0, int nrows, ppb_err *err);
/* Reads the radiance of every cell, [rows * nbins] in layout order. */
int ppb_marcher_read(ppb_marcher *mr, double *radiance, ppb_err *err);
void ppb_marcher_free(ppb_marcher *mr);

/* The whole layout, with progress lines and interruption between launches; *partial set to 1
 * if interrupted. */
int ppb_march_all(ppb_ocl *ocl, const ppb_scene *sc, const ppb_maps *maps,
                  const ppb_march_tables *tab, const ppb_march_opts *opts, const char *label,
                  int quiet, double *radiance, int *partial, ppb_err *err);

/* Tau resolution of the tables, nodes per unit optical depth (linear interpolation in tau; the
 * S march reads its table only at piece ends, the R march at every step). */
#define PPB_MARCH_TAU_PER_MFP 64

/* The marcher kernel, in the source tree (runtime/ocl.h). */
#define PPB_MARCH_KERNEL "src/methods/pp/march.cl"

#endif
