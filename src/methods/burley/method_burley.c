/* method_burley.c: the `burley` method (reference: Methods, `burley`): Christensen & Burley
 * 2015's normalized diffusion profile R(r) (their Eq. 3, burley_profile.h) applied to the tube
 * as a renderer applies a BSSRDF.
 *
 * - Profile parameters, per stretch of the lit strip with one medium: A = the total diffuse
 *   reflectance of the semi-infinite medium under the scene's beam, every scattering order,
 *   exact from the plane-parallel solver (ppb_burley_albedo); the length l = 1/sigma_t', the
 *   reduced mean free path (sigma_t' = sigma_a + sigma_s (1 - g)), and s = s_fit(A) / l with
 *   the searchlight fit of Eq. 5 (the beam is the paper's searchlight configuration).
 * - Tube: the flux at an exit point (x_o, y_o) per unit entering irradiance is
 *   int R(|x_o - x_i|) dA_i over the lit entry points x_i = (x, 0, z) of S1 (3-D distance):
 *   over z in closed form (the line kernel of burley_profile.h, 2 K0), over x by graded
 *   Gauss-Legendre (ppb_burley_strip). Each exit point takes the profile of the entry point's
 *   medium (the strip cut at a density or albedo step, as mp's sources).
 * - Slab: the plane integrals in closed form: R = A, T = A (1 - cdf(H)).
 * - Entry, segments, exit lobe and totals: physics/bssrdf_tube.h (A is already the reflectance
 *   in air, so the exit lobe only distributes the flux over the bins). */
#include "methods/burley/method_burley.h"

#include <math.h>
#include <stdio.h>

#include "kernels/ppb_fresnel.h"
#include "methods/burley/burley_profile.h"
#include "methods/result_check.h"
#include "physics/bssrdf_tube.h"
#include "physics/medium.h"
#include "physics/ppsolver.h"

int ppb_burley_albedo(double albedo, double g, double n, double cos_theta_l, int directions,
                      double *A, ppb_err *err)
{
    if (!(albedo >= 0.0 && albedo <= 1.0) || !(g > -1.0 && g < 1.0) || !(n >= 1.0) ||
        !(cos_theta_l > 0.0 && cos_theta_l <= 1.0))
        return ppb_fail(err, "burley: albedo %g, g %g, n %g, cos theta_L %g out of range", albedo,
                        g, n, cos_theta_l);
    if (albedo == 0.0) {
        *A = 0.0;
        return 0;
    }
    if (albedo >= 1.0 - 1e-13) { /* conservative and semi-infinite: all that enters returns */
        *A = 1.0;
        return 0;
    }
    double sigma_tr = sqrt(3.0 * (1.0 - albedo) * (1.0 - albedo * g)); /* per sigma_t */
    /* The solver's R at N and 2N cells, extrapolated: its discretisation error falls like 1/N
     * (method_burley.h). */
    double R[2];
    for (int k = 0; k < 2; k++) {
        pp_params p = {.tau0 = fmin(1e6, fmax(50.0, 40.0 / sigma_tr)),
                       .albedo = albedo,
                       .g = g,
                       .mu0 = cos_theta_l,
                       .directions = directions << k};
        pp_solution *sol = NULL;
        int rc = n > 1.0 ? pp_solve_fresnel(&p, n, NULL, &sol, NULL, err)
                         : pp_solve_ex(&p, NULL, &sol, NULL, err);
        if (rc)
            return -1;
        double T, ballistic;
        pp_totals(sol, &R[k], &T, &ballistic);
        pp_free(sol);
    }
    double entry = n > 1.0 ? 1.0 - ppb_fresnel(cos_theta_l, n) : 1.0;
    *A = (2.0 * R[1] - R[0]) / entry; /* pp_totals: fractions of the incident power */
    return 0;
}

/* The profile of each lit piece of S1 (physics/medium.h: at most two, cut at a density or
 * albedo step); piece 0 is the scene's medium in slab mode. */
typedef struct burley_model {
    ppb_burley profile[2];
    int samples; /* burley.samples: nodes per profile length along the strip */
} burley_model;

static int piece_profile(const ppb_config *cfg, double sigma_t, double albedo, ppb_burley *p,
                         ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    double A;
    if (ppb_burley_albedo(albedo, sc->g, sc->n, ppb_scene_cos_theta_l(sc), cfg->burley.directions,
                          &A, err))
        return -1;
    double sigma_t_reduced = sigma_t * (1.0 - albedo * sc->g); /* sigma_a + sigma_s (1 - g) */
    p->A = A;
    p->s = ppb_burley_shape_searchlight(A) * sigma_t_reduced; /* s_fit / l */
    return 0;
}

static double burley_strip(const void *model, int piece, double xa, double xb, double x, double y,
                           int surf)
{
    (void)surf; /* the profile is radial: only the distance counts */
    const burley_model *m = model;
    return ppb_burley_strip(&m->profile[piece], xa - x, xb - x, y, m->samples);
}

/* A line of entry points along z at x = xa: the line kernel (2 K0, closed form) at the in-plane
 * distance from the line (reference: Light; burley_profile.h). */
static double burley_line(const void *model, int piece, double xa, double x, double y, int surf)
{
    (void)surf;
    const burley_model *m = model;
    return ppb_burley_line(&m->profile[piece], hypot(x - xa, y));
}

/* The profile over the planes at 0 and H in closed form: R = A, T = A (1 - cdf(H)) (the tube's
 * S2 rule far from its sides). */
static void burley_slab(const void *model, double height, double *R, double *T)
{
    const burley_model *m = model;
    *R = m->profile[0].A;
    *T = m->profile[0].A * (1.0 - ppb_burley_cdf(&m->profile[0], height));
}

int ppb_method_burley(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    const ppb_scene *sc = &cfg->scene;
    if (ppb_burley_check(cfg, err))
        return -1;
    burley_model model = {.samples = cfg->burley.samples};
    if (sc->geometry == PPB_GEOM_SLAB) {
        if (piece_profile(cfg, sc->sigma_t, sc->albedo, &model.profile[0], err))
            return -1;
    } else {
        ppb_lit_piece lit[2];
        int nlit = ppb_lit_pieces(sc, lit);
        for (int i = 0; i < nlit; i++)
            if (piece_profile(cfg, lit[i].sigma_t, lit[i].albedo, &model.profile[i], err))
                return -1;
    }
    ppb_bssrdf m = {
        .model = &model, .strip = burley_strip, .line = burley_line, .slab = burley_slab};
    if (ppb_bssrdf_fill(cfg, &m, ctx->quiet, out, err) ||
        ppb_radiance_check(cfg->name, out, NULL, err))
        return -1;
    return ppb_totals_check_completed(cfg->name, out, err);
}

int ppb_burley_check(const ppb_config *cfg, ppb_err *err)
{
    return ppb_bssrdf_check(cfg, "burley", 1, err); /* the line hook above */
}
