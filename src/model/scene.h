/* scene.h: what is being simulated (reference: Medium to Bins): geometry, medium, light, bins, and
 * the layout of every radiance array over (surface, segment, bin); the light's angle in the
 * forms the methods use (theta_L is converted from degrees here only), the power entering the
 * lit S1 and the segment length x projected solid angle that turn cell energies into average
 * radiances (reference: Bins).
 *
 * Conventions themselves (frames, bin edges, segment centres, the medium step) live in
 * kernels/ppb_conventions.h so host and kernels share them; this header adds the host-side
 * struct and the layout. */
#ifndef PPB_SCENE_H
#define PPB_SCENE_H

#include <stddef.h>

#include "kernels/ppb_conventions.h"

typedef enum { PPB_GEOM_TUBE = 0, PPB_GEOM_SLAB = 1 } ppb_geometry;

typedef struct ppb_scene {
    ppb_geometry geometry;
    double width, height; /* mfp; width unused in slab mode */
    int segments_top, segments_side;
    double sigma_t, albedo, g;
    double n; /* refractive index inside (outside is 1); n <= 1 means no boundary */
    int step; /* PPB_STEP_* */
    double step_x, sigma_t_right, albedo_right;
    double theta_deg; /* light incidence from the S1 normal */
    /* S1's lit part (reference: Light): searchlight 0 (zero-initialised: the default) lights the
     * whole face (x < step_x with a shadow step); 1 the strip of centre light_x0 and width
     * light_width, a line along z at light_x0 when light_width = 0. */
    int searchlight;
    double light_x0, light_width;
    int ntheta, nphi;
} ppb_scene;

/* Where each surface's segments sit in a flat radiance array. */
typedef struct ppb_layout {
    int nsurf;             /* 4 for the tube, 2 for the slab */
    int nseg[PPB_NSURF];   /* 0 for surfaces that do not exist */
    int offset[PPB_NSURF]; /* first segment row of each surface */
    int nbins;             /* ntheta * nphi */
    size_t ncells;         /* total rows * nbins */
} ppb_layout;

ppb_layout ppb_scene_layout(const ppb_scene *sc);

/* Flat index of (surface, segment, bin); bin = theta_bin * nphi + phi_bin (ppb_cell_index). */
static inline size_t ppb_cell(const ppb_layout *lo, int surf, int seg, int bin)
{
    return ppb_cell_index(lo->offset[surf], seg, lo->nbins, bin);
}

/* Segment centre and coordinate s along the surface (s = 0 in slab mode). */
double ppb_scene_sample_point(const ppb_scene *sc, int surf, int seg, double *x, double *y);

/* The light direction w_L = (sin theta_L, -cos theta_L, 0), and cos, sin and tan of theta_L
 * (the incidence angle from the S1 normal, [light] theta_deg in degrees). */
void ppb_scene_light_dir(const ppb_scene *sc, double w[3]);
double ppb_scene_cos_theta_l(const ppb_scene *sc);
double ppb_scene_sin_theta_l(const ppb_scene *sc);
double ppb_scene_tan_theta_l(const ppb_scene *sc);

/* The one definition of S1's lit part (reference: Light), tube mode: [*lo, *hi], the whole face
 * [-W/2, W/2], or [-W/2, step_x] with a shadow step, or the searchlight's strip
 * [x0 - width/2, x0 + width/2] (lo == hi == x0 for a line). Slab mode: [-W/2, W/2] (unused:
 * the slab is lit everywhere). */
void ppb_scene_lit_range(const ppb_scene *sc, double *lo, double *hi);

/* Whether the light is a searchlight (a strip narrower than the face, or a line), and whether it
 * is a line ([light] width = 0: a delta in x at x0). */
int ppb_scene_searchlight(const ppb_scene *sc);
int ppb_scene_lit_line(const ppb_scene *sc);

/* Width of the lit part of S1 (tube) -- the shadow step lights x < step_x only, a strip its
 * width, a line 0; 1 in slab mode (per unit area). */
double ppb_scene_lit_width(const ppb_scene *sc);

/* The lit part's measure that normalises the power entering: the lit width, except 1 for a line
 * (a line of unit strength: the limit of a strip of width w under E_perp = 1 / w). */
double ppb_scene_lit_measure(const ppb_scene *sc);

/* Power entering the lit part of S1 per unit E_perp: lit measure x cos(theta_L) per unit length
 * in z (tube; a line: cos(theta_L) per unit line strength), cos(theta_L) per unit area (slab).
 * Totals are fractions of it (reference: Light). */
double ppb_scene_power_in(const ppb_scene *sc);

/* Length of one segment of surface surf (ppb_segment_length); 1 in slab mode (per unit area). */
double ppb_scene_segment_length(const ppb_scene *sc, int surf);

/* Segment length x projected solid angle of one bin (reference: Bins): a cell's energy per
 * unit length in z (per unit area in slab mode) divided by this is its average radiance. */
double ppb_scene_cell_measure(const ppb_scene *sc, int surf);

const char *ppb_surface_name(int surf);

#endif
