/* medium.c: the medium block from the scene (medium.h). */
#include "physics/medium.h"

#include <math.h>

ppb_medium ppb_medium_of(const ppb_scene *sc)
{
    int tube = sc->geometry == PPB_GEOM_TUBE;
    ppb_medium m = {
        .width = sc->width,
        .height = sc->height,
        .sigma_t = sc->sigma_t,
        .sigma_t_right = sc->sigma_t_right,
        .albedo = sc->albedo,
        .albedo_right = sc->albedo_right,
        .step_x = sc->step_x,
        .n = sc->n,
        .g = sc->g,
        .step = tube ? sc->step : PPB_STEP_NONE,
        .tube = tube,
    };
    return m;
}

ppb_lit ppb_lit_of(const ppb_scene *sc)
{
    ppb_lit L = {0.0, 0.0, ppb_scene_searchlight(sc), 0};
    ppb_scene_lit_range(sc, &L.lo, &L.hi);
    return L;
}

int ppb_lit_pieces(const ppb_scene *sc, ppb_lit_piece piece[2])
{
    double xa, xb; /* the lit part (reference: Light), cut below where the medium steps */
    ppb_scene_lit_range(sc, &xa, &xb);
    double cut[3] = {xa, xb, xb};
    int n = 1, npiece = 0;
    if ((sc->step == PPB_STEP_DENSITY || sc->step == PPB_STEP_ALBEDO) && sc->step_x > xa &&
        sc->step_x < xb) {
        cut[1] = sc->step_x;
        n = 2;
    }
    for (int i = 0; i < n; i++) {
        /* A line (xa == xb) is one degenerate piece; an empty strip part is left out. */
        if (!(cut[i + 1] > cut[i]) && !(n == 1 && ppb_scene_lit_line(sc)))
            continue;
        double x = 0.5 * (cut[i] + cut[i + 1]); /* the piece's coefficients: at its entry points */
        ppb_lit_piece *p = &piece[npiece++];
        p->xa = cut[i];
        p->xb = cut[i + 1];
        p->sigma_t = ppb_sigma_t_at(x, sc->step, sc->step_x, sc->sigma_t, sc->sigma_t_right);
        p->albedo = ppb_albedo_at(x, sc->step, sc->step_x, sc->albedo, sc->albedo_right);
    }
    return npiece;
}
