/* medium.c: the medium block from the scene (medium.h). */
#include "physics/medium.h"

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
