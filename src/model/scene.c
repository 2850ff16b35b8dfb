#include "model/scene.h"

#include <math.h>

ppb_layout ppb_scene_layout(const ppb_scene *sc)
{
    ppb_layout lo = {0};
    int tube = sc->geometry == PPB_GEOM_TUBE;
    lo.nsurf = tube ? 4 : 2;
    lo.nseg[PPB_S1] = lo.nseg[PPB_S2] = tube ? sc->segments_top : 1;
    lo.nseg[PPB_S3] = lo.nseg[PPB_S4] = tube ? sc->segments_side : 0;
    int rows = 0;
    for (int s = 0; s < PPB_NSURF; s++) {
        lo.offset[s] = rows;
        rows += lo.nseg[s];
    }
    lo.nbins = sc->ntheta * sc->nphi;
    lo.ncells = (size_t)rows * (size_t)lo.nbins;
    return lo;
}

double ppb_scene_sample_point(const ppb_scene *sc, int surf, int seg, double *x, double *y)
{
    if (sc->geometry == PPB_GEOM_SLAB) {
        *x = 0.0;
        *y = surf == PPB_S1 ? 0.0 : -sc->height;
        return 0.0;
    }
    int nseg = (surf == PPB_S1 || surf == PPB_S2) ? sc->segments_top : sc->segments_side;
    return ppb_segment_centre(surf, seg, nseg, sc->width, sc->height, x, y);
}

void ppb_scene_light_dir(const ppb_scene *sc, double w[3])
{
    double t = sc->theta_deg * PPB_PI / 180.0;
    w[0] = sin(t);
    w[1] = -cos(t);
    w[2] = 0.0;
}

double ppb_scene_lit_width(const ppb_scene *sc)
{
    if (sc->geometry == PPB_GEOM_SLAB)
        return 1.0;
    if (sc->step == PPB_STEP_SHADOW) {
        double lit = sc->step_x + 0.5 * sc->width;
        return lit < 0 ? 0 : (lit > sc->width ? sc->width : lit);
    }
    return sc->width;
}

const char *ppb_surface_name(int surf)
{
    static const char *names[PPB_NSURF] = {"S1", "S2", "S3", "S4"};
    return (surf >= 0 && surf < PPB_NSURF) ? names[surf] : "?";
}
