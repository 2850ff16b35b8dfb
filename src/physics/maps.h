/* maps.h: the tube's light maps (paper Sec. 3.1 and 3.3; reference: Medium to Light): the optical
 * depth D along the light path from S1 (infinite where S1's lit part cannot be seen along -w_L)
 * and the average albedo along that path, on a light-aligned grid over the cross-section, plus
 * the exact light-path quantities they sample and the exact ballistic exit fraction.
 *
 * The grid's columns follow the light (x' = x + y tan theta_L), so D is linear in depth along a
 * column and every shadow edge is a column edge; each cell keeps its corners as limits from
 * inside (kernels/march_params.h). Node values are exact for the piecewise-constant media, so
 * the only map error is bilinear interpolation across a kink or jump that cuts a cell (oblique
 * light with a density or albedo step), and it vanishes as map_res grows.
 *
 * At n > 1 the maps and ppb_light_path_exact follow the refracted beam inside
 * (sin theta_t = sin theta_L / n); ppb_beam_depth, ppb_lit_integral and ppb_ballistic_fraction
 * keep theta_L and no Fresnel factor (the marcher's totals at n > 1 use them at normal
 * incidence only, where theta_t = theta_L, and add the factors themselves: march.c). */
#ifndef PPB_MAPS_H
#define PPB_MAPS_H

#include "base/err.h"
#include "model/scene.h"

typedef struct ppb_maps {
    int tube;
    double tan_theta_l;
    double xp0;    /* x' of the grid's node column 0 */
    double h;      /* cell size, mfp */
    int i0;        /* grid column of the first stored cell column */
    int nx, ny;    /* cells stored: columns i0 .. i0 + nx - 1, rows 0 .. ny - 1 */
    double *cells; /* [ny][nx][PPB_MAP_STRIDE] */
} ppb_maps;

/* Builds the maps with map_res cells per mfp (slab mode: one column). The grid's columns reach
 * left of x' = -W/2 far enough for the paths of S3's lower end, but those columns lie wholly in
 * shadow (reference: Light; a path meeting S1's plane left of -W/2 is unlit), so only the
 * nearest of them is stored: the lookup clamps the others to it, where lit = 0 exactly and the
 * march adds nothing. At oblique light that is the difference between W and W + H tan(theta_L)
 * columns (22 GB at H = 100, theta_L = 80). */
int ppb_maps_build(const ppb_scene *sc, int map_res, ppb_maps *m, ppb_err *err);

/* Bytes ppb_maps_build will allocate (estimated before any allocation). */
double ppb_maps_bytes(const ppb_scene *sc, int map_res);
void ppb_maps_free(ppb_maps *m);

/* Interpolated map values at (x, y): D (finite, continued into shadow), average albedo and the
 * lit fraction (0 or 1 except inside a cell that a shadow edge cuts). */
void ppb_maps_lookup(const ppb_maps *m, double x, double y, double *D, double *abar, double *lit);

/* D from the map as the paper defines it: infinite where fully shadowed. */
double ppb_maps_depth(const ppb_maps *m, double x, double y);

/* Exact values at (x, y) inside the cross-section (y <= 0): D continued into shadow, the length
 * average of the albedo along the light path (paper Sec. 3.3), and whether the point is lit
 * (reference: Light). In slab mode x is ignored. */
void ppb_light_path_exact(const ppb_scene *sc, double x, double y, double *D, double *abar,
                          int *lit);

/* Exact optical depth of the straight segment (x0, y0)-(x1, y1) through the medium. */
double ppb_segment_optical_depth(const ppb_scene *sc, double x0, double y0, double x1, double y1);

/* Exact optical depth of the unscattered beam from its entry point x_e on S1 to where it leaves
 * the tube: through S2, or through S4 when oblique light reaches x = W/2 first (theta_L >= 0),
 * across the density step if it meets it. Slab mode: sigma_t H / cos(theta_L), x_e ignored. */
double ppb_beam_depth(const ppb_scene *sc, double xe);

/* Fraction of the power entering the lit part of S1 that leaves unscattered, through any
 * surface (reference: Bins, ballistic): exp(-ppb_beam_depth) averaged over the lit entry
 * points, by Gauss-Legendre panels between the entry points where the path's end switches from
 * S2 to S4 or the path starts or ends on the step (~1e-14); exp(-tau0 / mu0) in slab mode. The
 * one ballistic fraction of every deterministic method. */
double ppb_ballistic_fraction(const ppb_scene *sc);

/* The integral over the lit part of S1 (tube mode) of f(x_e) dx_e, x_e the beam's entry point,
 * by Gauss-Legendre panels between the entry points where f may jump or kink (the beam's path
 * switching its exit from S2 to S4, the step); *width is the lit width. A line searchlight is a
 * delta of unit strength (ppb_scene_lit_measure): f at the line, *width = 1. The ballistic fraction
 * and rte2d's absorbed beam are its two integrands. */
typedef double (*ppb_entry_fn)(const ppb_scene *sc, double x_entry, void *arg);
double ppb_lit_integral(const ppb_scene *sc, ppb_entry_fn f, void *arg, double *width);

/* The same integrand's midpoint sum, sum_i f(a + (i + 1/2) w / np) over np equal parts of the
 * lit part [a, a + w] of S1 (w = *width): the integral is the sum times w / np. For the
 * integrands whose breaks are not known in closed form: at n > 1 the refracted beam walked
 * through its reflections off all four faces (march.c's ballistic fraction, rte2d_grid.c's
 * absorbed beam) kinks or jumps wherever the walk's sequence of faces changes. Returns 0 (and
 * *width = 0) when no part is lit; a line: np f(x0), *width = 1. */
double ppb_lit_midpoint_sum(const ppb_scene *sc, ppb_entry_fn f, void *arg, int np, double *width);

/* The midpoints both Fresnel walks take: 2e4 put their integrals within ~1e-5. */
#define PPB_LIT_MIDPOINTS 20000

#endif
