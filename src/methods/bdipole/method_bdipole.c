/* method_bdipole.c: the `bdipole` method (reference: Methods, `bdipole`): d'Eon's better dipole
 * (bdipole_profile.h) applied to the tube as a renderer applies a BSSRDF.
 *
 * - Profile parameters, per stretch of the lit strip with one medium: from its (sigma_t,
 *   albedo) and the scene's g and n (bdipole_profile.h: reduced coefficients, Grosjean's D, the
 *   exact Fresnel moments of the inside boundary).
 * - Tube: the flux at an exit point (x_o, y_o) per unit entering irradiance is
 *   int R(|x_o - x_i|) dA_i over the lit entry points x_i = (x, 0, z) of S1 (3-D distance):
 *   over z in closed form (K0 and K1), over x by graded Gauss-Legendre (ppb_bdipole_strip).
 *   Each exit point takes the profile of the entry point's medium (the strip cut at a density or
 *   albedo step, as mp's sources).
 * - Slab: the plane integrals in closed form: R = R_d = P(0), T = P(H).
 * - Entry, segments, exit lobe and totals: physics/bssrdf_tube.h (R(r) already is the flux that
 *   crosses the boundary: C_phi and C_E hold its Fresnel transmission). */
#include "methods/bdipole/method_bdipole.h"

#include <math.h>

#include "methods/bdipole/bdipole_profile.h"
#include "methods/result_check.h"
#include "physics/bssrdf_tube.h"
#include "physics/medium.h"

/* The profile of each lit piece of S1 (physics/medium.h: at most two, cut at a density or
 * albedo step); piece 0 is the scene's medium in slab mode. */
typedef struct bdipole_model {
    ppb_bdipole profile[2];
    int samples; /* bdipole.samples: nodes per 1 / sigma_tr along the strip */
} bdipole_model;

static double bdipole_strip(const void *model, int piece, double xa, double xb, double x, double y,
                            int surf)
{
    (void)surf; /* the profile is radial: only the distance counts */
    const bdipole_model *m = model;
    return ppb_bdipole_strip(&m->profile[piece], xa - x, xb - x, y, m->samples);
}

/* A line of entry points along z at x = xa: the line kernel (K0, K1 in closed form) at the
 * in-plane distance from the line (reference: Light; bdipole_profile.h). */
static double bdipole_line(const void *model, int piece, double xa, double x, double y, int surf)
{
    (void)surf;
    const bdipole_model *m = model;
    return ppb_bdipole_line(&m->profile[piece], hypot(x - xa, y));
}

static void bdipole_slab(const void *model, double height, double *R, double *T)
{
    const bdipole_model *m = model;
    *R = ppb_bdipole_plane(&m->profile[0], 0.0);
    *T = ppb_bdipole_plane(&m->profile[0], height);
}

int ppb_method_bdipole(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    const ppb_scene *sc = &cfg->scene;
    if (ppb_bdipole_check(cfg, err))
        return -1;
    bdipole_model model = {.samples = cfg->bdipole.samples};
    if (sc->geometry == PPB_GEOM_SLAB) {
        model.profile[0] = ppb_bdipole_make(sc->sigma_t, sc->albedo, sc->g, sc->n);
    } else {
        ppb_lit_piece lit[2];
        int nlit = ppb_lit_pieces(sc, lit);
        for (int i = 0; i < nlit; i++)
            model.profile[i] = ppb_bdipole_make(lit[i].sigma_t, lit[i].albedo, sc->g, sc->n);
    }
    ppb_bssrdf m = {
        .model = &model, .strip = bdipole_strip, .line = bdipole_line, .slab = bdipole_slab};
    if (ppb_bssrdf_fill(cfg, &m, ctx->quiet, out, err) ||
        ppb_radiance_check(cfg->name, out, NULL, err))
        return -1;
    return ppb_totals_check_completed(cfg->name, out, err);
}

int ppb_bdipole_check(const ppb_config *cfg, ppb_err *err)
{
    return ppb_bssrdf_check(cfg, "bdipole", 1, err); /* the line hook above */
}
