/* march_params.h: the one definition of what the ray-marching kernel (march.cl) receives, shared
 * by the host (src/physics/maps.c, src/physics/march_tables.c, src/methods/march.c) and the kernel.
 *
 * Owns: the launch parameters passed by value, the kernel argument indices, the layout of the
 * light maps (paper Sec. 3.1 and 3.3: optical depth D along the light path and average albedo)
 * and their bilinear lookup, and the layout of the integral tables (paper Eq. 15-17): the order
 * and count of their direction samples and where each (column, albedo node) block starts.
 *
 * Plain C that is also OpenCL C, like ppb_conventions.h. */
#ifndef PPB_MARCH_PARAMS_H
#define PPB_MARCH_PARAMS_H

#include "ppb_light.h"

#ifdef __OPENCL_VERSION__
#define PPB_GMEM __global
#else
#define PPB_GMEM
#endif

/* Which table the march integrates the plane-parallel modes with (cfg->pp.table). */
enum { PPB_TABLE_R = 0, PPB_TABLE_S = 1 };

/* Kernel arguments of ppb_march_kernel, by index. */
enum {
    PPB_MARCH_ARG_PARAMS = 0, /* ppb_march_params by value */
    PPB_MARCH_ARG_MAP = 1,    /* map cells, PPB_MAP_STRIDE doubles each */
    PPB_MARCH_ARG_TAB_R = 2,  /* R table [ncols][nalb][ndir][ntau[col]] (paper Eq. 15) */
    PPB_MARCH_ARG_TAB_S = 3,  /* S table, same layout (paper Eq. 16-17, corrected) */
    PPB_MARCH_ARG_COEF_C = 4, /* [ncols][nalb][ndir]: coefficient of exp(-D) in the source;
                               * pp at n > 1: then as many of exp(-(D_b - D)) (march_tables.h) */
    PPB_MARCH_ARG_OUT = 5,    /* radiance [rows][nbins] */
    PPB_MARCH_NARGS = 6
};

/* Column slabs: the medium is piecewise constant with its only jump on the vertical plane
 * x = step_x (reference: Medium), so every vertical column of the tube is a homogeneous slab of
 * optical thickness tau0 = sigma_t(x) H. The tables hold one slab solution per distinct column
 * thickness: column 0 is the left medium's (the only one without a density step), column 1 the
 * right medium's (x >= step_x) when a density step makes it differ. */
#define PPB_MARCH_MAX_COLS 2

/* Map cell layout: every cell of the light-aligned grid stores its four corner values of each
 * field as limits taken from inside the cell, so a jump that lies on a cell edge (the density or
 * albedo step at normal incidence, a shadow edge) stays sharp under bilinear interpolation.
 * Corner c = cx + 2 cy, cx along x', cy downwards in depth. */
enum {
    PPB_MAP_D = 0,    /* optical depth along the light path from S1, continued into shadow */
    PPB_MAP_ABAR = 1, /* average albedo along the light path (paper Sec. 3.3) */
    PPB_MAP_LIT = 2,  /* 1 lit, 0 shadowed (D is infinite there: the source is zero) */
    PPB_MAP_NFIELD = 3,
    PPB_MAP_STRIDE = 12 /* PPB_MAP_NFIELD x 4 corners */
};

/* Parameters of one launch, passed by value. The medium block, then all doubles, then an even
 * number of ints, so host and device agree on the layout without packing attributes; the host
 * asserts the size. */
typedef struct ppb_march_params {
    ppb_medium med; /* the cross-section and the medium (reference: Medium to Light) */
    ppb_lit lit;    /* S1's lit part: a searchlight's strip (ppb_light.h) */
    double tan_theta_l, cos_theta_l; /* light incidence */
    double light_x, light_y;         /* w_L = (light_x, light_y, 0) */
    /* map: light-aligned grid over x' = x + y tan(theta_L) and depth -y */
    double map_xp0; /* x' of the first node column */
    double map_h;   /* cell size, mfp */
    /* tables over tau = D cos(theta_L) in [0, tau0[col]] and the average albedo, per column */
    double tau0[PPB_MARCH_MAX_COLS], tau_h[PPB_MARCH_MAX_COLS];
    double alb0, alb_h;
    /* march */
    double ds;    /* ray-march step length, mfp (`pp.step`) */
    double d_cap; /* optical distance from the exit point beyond which the march stops */
    /* refractive boundaries (reference: Keys, `medium.n`): med.n <= 1 skips them all.
     * At n > 1 the light fields above (tan/cos_theta_l, light_x/y) are the refracted beam's
     * inside; beam_in is its perpendicular irradiance inside per unit E_perp in air,
     * (1 - F(cos theta_L)) cos theta_L / cos theta_t, and beam_fb = F(cos theta_t, 1/n) the
     * reflectance it meets at S2 and S1, beam_fs = F(sin theta_t, 1/n) the one at a side wall
     * (1 under total internal reflection). */
    double beam_in, beam_fb, beam_fs;
    int map_nx, map_ny; /* cells stored */
    int map_i0;         /* grid column of the first stored cell column (maps.h) */
    int map_pad;        /* unused: keeps the count of ints even */
    int ntau[PPB_MARCH_MAX_COLS], nalb;
    int ncols;      /* column slabs in the tables, 1 or 2 */
    int with_modes; /* 0: single scattering (ss), no tables */
    int table;      /* PPB_TABLE_R or PPB_TABLE_S */
    int telescope;  /* 1: a regular piece's S-table step sum in closed form (exact identity) */
    int nsamp;      /* direction samples per bin axis (n x n per bin) */
    int npts;       /* points per segment */
    int ntheta, nphi;
    int row0;      /* first segment row of this launch */
    int nseg[4];   /* segments per surface (slab: 1, 1, 0, 0) */
    int offset[4]; /* first segment row of each surface, as ppb_layout */
} ppb_march_params;

/* Table layout: R and S are [column][albedo node][direction][tau node] with ntau[c] tau nodes
 * in column c, C is [column][albedo node][direction]. First element of block (c, node) in R and
 * S, and in C. */
PPB_FN long ppb_march_table_offset(const int *ntau, int c, int node, int nalb, int ndir)
{
    long off = 0;
    for (int k = 0; k < c; k++)
        off += (long)nalb * ndir * ntau[k];
    return off + (long)node * ndir * ntau[c];
}
PPB_FN long ppb_march_coef_offset(int c, int node, int nalb, int ndir)
{
    return ((long)c * nalb + node) * ndir;
}

/* Bilinear map lookup at (x, y): D, average albedo and lit fraction. x is sheared along the light
 * (x' = x + y tan theta_L) so that every light path is a grid column: D is linear along it and
 * shadow edges are column edges. The grid's columns are numbered from xp0; only nx of them, from
 * column i0 on, are stored (the ones further left lie wholly in shadow, maps.h). Points off the
 * stored cells take the nearest cell's extrapolation clamped to it. */
PPB_FN void ppb_map_lookup(const PPB_GMEM double *cells, double xp0, double h, int i0, int nx,
                           int ny, double tan_theta_l, double x, double y, double *D, double *abar,
                           double *lit)
{
    double fx = (x + y * tan_theta_l - xp0) / h, fy = -y / h;
    int i = (int)floor(fx), j = (int)floor(fy);
    i = i < i0 ? i0 : (i >= i0 + nx ? i0 + nx - 1 : i);
    j = j < 0 ? 0 : (j >= ny ? ny - 1 : j);
    double tx = fx - i, ty = fy - j;
    tx = tx < 0.0 ? 0.0 : (tx > 1.0 ? 1.0 : tx);
    ty = ty < 0.0 ? 0.0 : (ty > 1.0 ? 1.0 : ty);
    const PPB_GMEM double *c = cells + ((long)j * nx + (i - i0)) * PPB_MAP_STRIDE;
    double w00 = (1.0 - tx) * (1.0 - ty), w10 = tx * (1.0 - ty), w01 = (1.0 - tx) * ty,
           w11 = tx * ty;
    *D = w00 * c[0] + w10 * c[1] + w01 * c[2] + w11 * c[3];
    *abar = w00 * c[4] + w10 * c[5] + w01 * c[6] + w11 * c[7];
    *lit = w00 * c[8] + w10 * c[9] + w01 * c[10] + w11 * c[11];
}

#endif
