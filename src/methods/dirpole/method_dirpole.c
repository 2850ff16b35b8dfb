/* method_dirpole.c: the `dirpole` method (reference: Methods, `dirpole`): the directional dipole
 * of Frisvad, Hachisuka & Kjeldsen 2014 (dirpole_profile.h) applied to the tube as a renderer
 * applies a BSSRDF.
 *
 * - Parameters, per stretch of the lit strip with one medium: sigma_t' = sigma_a + sigma_s (1 - g),
 *   D = 1 / (3 sigma_t'), sigma_tr = sqrt(sigma_a / D), d_e = 2.131 D / sqrt(alpha'), A from the
 *   Fresnel moments' fits; w_12 the beam refracted by Snell's law (kernels/ppb_fresnel.h).
 * - Tube: the flux at an exit point (x_o, y_o) of S1..S4 (its outward normal n_o) per unit
 *   entering irradiance is int M(x_o - x_i) dA_i over the lit entry points x_i = (x, 0, z) of S1
 *   (outward normal +y), M the model's exitance (S_d times 4 pi C_phi(1/eta), the Fresnel
 *   transmission over the exit hemisphere): over z and x by the quadratures of dirpole_profile.h.
 * - Slab: the same integral over the whole plane of entry points, at an exit point on the face
 *   (R) and on the far face (T).
 * - Entry, segments, exit lobe and totals: physics/bssrdf_tube.h (the model's exit lobe is
 *   T_21(w_o) cos theta_o, the shared normalised Fresnel lobe). */
#include "methods/dirpole/method_dirpole.h"

#include <math.h>

#include "kernels/ppb_conventions.h"
#include "kernels/ppb_fresnel.h"
#include "methods/dirpole/dirpole_profile.h"
#include "methods/result_check.h"
#include "physics/bssrdf_tube.h"
#include "physics/medium.h"

typedef struct dirpole_model {
    ppb_dirpole profile[2]; /* per lit piece of S1 (physics/medium.h), piece 0 in slab mode */
    int samples;            /* dirpole.samples */
} dirpole_model;

/* The refracted beam inside: (sin theta_L / n, -cos theta_t, 0) for w_L = (sin, -cos, 0). */
static void refracted_beam(const ppb_scene *sc, double w[3])
{
    double cos_l = ppb_scene_cos_theta_l(sc), sin_l = ppb_scene_sin_theta_l(sc);
    double n = sc->n > 1.0 ? sc->n : 1.0;
    w[0] = sin_l / n;
    w[1] = -(n > 1.0 ? ppb_refract_cos(cos_l, n) : cos_l);
    w[2] = 0.0;
}

static double dirpole_strip(const void *model, int piece, double xa, double xb, double x, double y,
                            int surf)
{
    const dirpole_model *m = model;
    const double no[3] = {ppb_normal_x(surf), ppb_normal_y(surf), 0.0};
    /* entry points at x - u for u in [x - xb, x - xa] */
    return ppb_dirpole_strip(&m->profile[piece], x - xb, x - xa, y, no, m->samples);
}

/* A line of entry points along z at x = xa: the exitance's z integral at u = x - xa (z = q sinh t
 * Gauss-Legendre, dirpole_profile.h), the exit normal the surface's. */
static double dirpole_line(const void *model, int piece, double xa, double x, double y, int surf)
{
    const dirpole_model *m = model;
    const double no[3] = {ppb_normal_x(surf), ppb_normal_y(surf), 0.0};
    return ppb_dirpole_line(&m->profile[piece], x - xa, y, no, m->samples);
}

/* The whole plane of entry points (the strip out to where e^(-sigma_tr r) < 5e-18) at an exit
 * point on the entry face (R) and on the face at depth `height` (T). */
static void dirpole_slab(const void *model, double height, double *R, double *T)
{
    const dirpole_model *m = model;
    const double up[3] = {0.0, 1.0, 0.0}, down[3] = {0.0, -1.0, 0.0};
    const ppb_dirpole *p = &m->profile[0];
    double wide = 100.0 / fmax(p->sigma_tr, 1e-4 / p->D); /* the strip stops at 40 of these */
    *R = ppb_dirpole_strip(p, -wide, wide, 0.0, up, m->samples);
    *T = ppb_dirpole_strip(p, -wide, wide, -height, down, m->samples);
}

int ppb_method_dirpole(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    const ppb_scene *sc = &cfg->scene;
    if (ppb_dirpole_check(cfg, err))
        return -1;
    dirpole_model model = {.samples = cfg->dirpole.samples};
    double w[3];
    refracted_beam(sc, w);
    if (sc->geometry == PPB_GEOM_SLAB) {
        ppb_dirpole_init(&model.profile[0], sc->sigma_t, sc->albedo, sc->g, sc->n, w);
    } else {
        ppb_lit_piece lit[2];
        int nlit = ppb_lit_pieces(sc, lit);
        for (int i = 0; i < nlit; i++)
            ppb_dirpole_init(&model.profile[i], lit[i].sigma_t, lit[i].albedo, sc->g, sc->n, w);
    }
    ppb_bssrdf m = {
        .model = &model, .strip = dirpole_strip, .line = dirpole_line, .slab = dirpole_slab};
    if (ppb_bssrdf_fill(cfg, &m, ctx->quiet, out, err) ||
        ppb_radiance_check(cfg->name, out, NULL, err))
        return -1;
    return ppb_totals_check_completed(cfg->name, out, err);
}

int ppb_dirpole_check(const ppb_config *cfg, ppb_err *err)
{
    return ppb_bssrdf_check(cfg, "dirpole", 1, err); /* the line hook above */
}
