#include "model/scene.h"

#include <math.h>

#include "kernels/ppb_tube.h"

ppb_layout ppb_scene_layout(const ppb_scene *sc)
{
    ppb_layout lo = {0};
    int tube = sc->geometry == PPB_GEOM_TUBE;
    lo.nsurf = ppb_surface_count(tube);
    lo.nseg[PPB_S1] = lo.nseg[PPB_S2] = tube ? sc->segments_top : 1;
    lo.nseg[PPB_S3] = lo.nseg[PPB_S4] = tube ? sc->segments_side : 0;
    int rows = 0;
    for (int s = 0; s < PPB_NSURF; s++) {
        lo.offset[s] = rows;
        rows += lo.nseg[s];
    }
    lo.nbins = ppb_bin_count(sc->ntheta, sc->nphi);
    lo.ncells = (size_t)rows * (size_t)lo.nbins;
    return lo;
}

/* Segments of a surface (reference: Geometry; segments_top on S1/S2, segments_side on S3/S4). */
static int tube_segments(const ppb_scene *sc, int surf)
{
    return (surf == PPB_S1 || surf == PPB_S2) ? sc->segments_top : sc->segments_side;
}

double ppb_scene_sample_point(const ppb_scene *sc, int surf, int seg, double *x, double *y)
{
    if (sc->geometry == PPB_GEOM_SLAB) {
        *x = 0.0;
        *y = surf == PPB_S1 ? 0.0 : -sc->height;
        return 0.0;
    }
    return ppb_segment_centre(surf, seg, tube_segments(sc, surf), sc->width, sc->height, x, y);
}

/* theta_L in radians: the one conversion from [light] theta_deg. */
static double theta_l(const ppb_scene *sc)
{
    return sc->theta_deg * PPB_PI / 180.0;
}

double ppb_scene_cos_theta_l(const ppb_scene *sc)
{
    return cos(theta_l(sc));
}

double ppb_scene_sin_theta_l(const ppb_scene *sc)
{
    return sin(theta_l(sc));
}

double ppb_scene_tan_theta_l(const ppb_scene *sc)
{
    return tan(theta_l(sc));
}

void ppb_scene_light_dir(const ppb_scene *sc, double w[3])
{
    w[0] = ppb_scene_sin_theta_l(sc);
    w[1] = -ppb_scene_cos_theta_l(sc);
    w[2] = 0.0;
}

int ppb_scene_searchlight(const ppb_scene *sc)
{
    return sc->geometry == PPB_GEOM_TUBE && sc->searchlight;
}

int ppb_scene_lit_line(const ppb_scene *sc)
{
    return ppb_scene_searchlight(sc) && sc->light_width == 0.0;
}

void ppb_scene_lit_range(const ppb_scene *sc, double *lo, double *hi)
{
    *lo = -0.5 * sc->width;
    *hi = 0.5 * sc->width;
    if (ppb_scene_searchlight(sc)) {
        /* The config keeps the strip on S1 (config.c); the clamp only guards round-off. */
        *lo = fmax(*lo, sc->light_x0 - 0.5 * sc->light_width);
        *hi = fmin(*hi, sc->light_x0 + 0.5 * sc->light_width);
    } else if (sc->step == PPB_STEP_SHADOW && sc->geometry == PPB_GEOM_TUBE)
        *hi = fmin(*hi, sc->step_x);
}

double ppb_scene_lit_width(const ppb_scene *sc)
{
    if (sc->geometry == PPB_GEOM_SLAB)
        return 1.0;
    if (sc->step == PPB_STEP_SHADOW && !ppb_scene_searchlight(sc)) {
        double lit = sc->step_x + 0.5 * sc->width;
        return lit < 0 ? 0 : (lit > sc->width ? sc->width : lit);
    }
    if (ppb_scene_searchlight(sc)) {
        double lo, hi;
        ppb_scene_lit_range(sc, &lo, &hi);
        return hi > lo ? hi - lo : 0.0;
    }
    return sc->width;
}

double ppb_scene_lit_measure(const ppb_scene *sc)
{
    return ppb_scene_lit_line(sc) ? 1.0 : ppb_scene_lit_width(sc);
}

double ppb_scene_power_in(const ppb_scene *sc)
{
    return ppb_scene_lit_measure(sc) * ppb_scene_cos_theta_l(sc);
}

double ppb_scene_segment_length(const ppb_scene *sc, int surf)
{
    if (sc->geometry == PPB_GEOM_SLAB)
        return 1.0;
    return ppb_segment_length(surf, tube_segments(sc, surf), sc->width, sc->height);
}

double ppb_scene_cell_measure(const ppb_scene *sc, int surf)
{
    return ppb_scene_segment_length(sc, surf) * ppb_bin_proj_solid_angle(sc->ntheta, sc->nphi);
}

const char *ppb_surface_name(int surf)
{
    static const char *names[PPB_NSURF] = {"S1", "S2", "S3", "S4"};
    return (surf >= 0 && surf < PPB_NSURF) ? names[surf] : "?";
}
