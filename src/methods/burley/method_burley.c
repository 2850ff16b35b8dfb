/* method_burley.c: the `burley` method (reference: Methods, `burley`): Christensen & Burley
 * 2015's normalized diffusion profile R(r) (their Eq. 3, burley_profile.h) applied to the tube
 * as a renderer applies a BSSRDF.
 *
 * - Profile parameters, per stretch of the lit strip with one medium: A = the total diffuse
 *   reflectance of the semi-infinite medium under the scene's beam, every scattering order,
 *   exact from the plane-parallel solver (ppb_burley_albedo); the length l = 1/sigma_t', the
 *   reduced mean free path (sigma_t' = sigma_a + sigma_s (1 - g)), and s = s_fit(A) / l with
 *   the searchlight fit of Eq. 5 (the beam is the paper's searchlight configuration).
 * - Tube: a sample point of S1..S4 at (x_o, y_o) takes the flux J = E_in int R(|x_o - x_i|) dA_i
 *   over the lit entry points x_i = (x, 0, z) of S1 (3-D distance), E_in = cos(theta_L)
 *   (1 - F(theta_L)) the irradiance that enters; over z in closed form (the line kernel of
 *   burley_profile.h, 2 K0), over x by graded Gauss-Legendre (ppb_burley_strip), averaged over
 *   the segment on samples_seg points. Each exit point takes the profile of the entry point's
 *   medium (the strip cut at a density or albedo step, as mp's sources).
 * - Slab: the plane integrals in closed form: R = (1 - F) A, T = (1 - F) A (1 - cdf(H)) (the
 *   profile over the plane at distance H, the tube's S2 rule far from its sides).
 * - Exit: radiance J / pi in every bin at n = 1, J lobe / pi at n > 1 (the normalised exit lobe
 *   of physics/diffuse_exit.h, mp's convention): A is already the reflectance in air, so the
 *   lobe only distributes J over the bins.
 * - Totals: R, T, sides from the segments' fluxes as mp; ballistic and specular the scene's
 *   exact ones (physics/diffuse_exit.h, physics/maps.h). */
#include "methods/burley/method_burley.h"

#include <math.h>
#include <stdio.h>

#include "base/progress.h"
#include "kernels/ppb_fresnel.h"
#include "methods/burley/burley_profile.h"
#include "methods/result_check.h"
#include "physics/diffuse_exit.h"
#include "physics/maps.h"
#include "physics/medium.h"
#include "physics/ppsolver.h"

#define BURLEY_MAX_THETA 64

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

/* A stretch of the lit strip of S1 with one medium, and its profile. */
typedef struct burley_piece {
    double xa, xb;
    ppb_burley profile;
} burley_piece;

static int piece_profile(const ppb_config *cfg, double sigma_t, double albedo, burley_piece *p,
                         ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    double A;
    if (ppb_burley_albedo(albedo, sc->g, sc->n, ppb_scene_cos_theta_l(sc), cfg->burley.directions,
                          &A, err))
        return -1;
    double sigma_t_reduced = sigma_t * (1.0 - albedo * sc->g); /* sigma_a + sigma_s (1 - g) */
    p->profile.A = A;
    p->profile.s = ppb_burley_shape_searchlight(A) * sigma_t_reduced; /* s_fit / l */
    return 0;
}

/* The lit strip, cut at the step when the medium changes there: at most two pieces (mp's). */
static int burley_pieces(const ppb_config *cfg, burley_piece piece[2], int *npiece, ppb_err *err)
{
    ppb_lit_piece lit[2];
    *npiece = ppb_lit_pieces(&cfg->scene, lit);
    for (int i = 0; i < *npiece; i++) {
        burley_piece *p = &piece[i];
        p->xa = lit[i].xa;
        p->xb = lit[i].xb;
        if (piece_profile(cfg, lit[i].sigma_t, lit[i].albedo, p, err))
            return -1;
    }
    return 0;
}

/* Flux per unit entering irradiance averaged over a segment: the strip integral at
 * samples_seg points spread evenly over it (the midpoint rule). */
static double segment_flux(const ppb_config *cfg, const burley_piece *piece, int npiece, int surf,
                           int seg, double seg_len)
{
    double x, y;
    ppb_scene_sample_point(&cfg->scene, surf, seg, &x, &y);
    int along_x = surf == PPB_S1 || surf == PPB_S2, points = cfg->samples_seg;
    points = points < 1 ? 1 : points;
    double sum = 0.0;
    for (int j = 0; j < points; j++) {
        double f = (j + 0.5) / points - 0.5;
        double xp = along_x ? x + f * seg_len : x, yp = along_x ? y : y + f * seg_len;
        for (int i = 0; i < npiece; i++)
            sum += ppb_burley_strip(&piece[i].profile, piece[i].xa - xp, piece[i].xb - xp, yp,
                                    cfg->burley.samples);
    }
    return sum / points;
}

typedef struct burley_exit {
    int fresnel;
    double specular, entry;
    double lobe[BURLEY_MAX_THETA]; /* per theta bin, mean 1 (n > 1) */
} burley_exit;

static void fill_bins(ppb_result *out, const ppb_scene *sc, const burley_exit *ex, int surf,
                      int seg, double flux)
{
    double radiance = flux / PPB_PI;
    for (int b = 0; b < out->layout.nbins; b++)
        out->radiance[ppb_cell(&out->layout, surf, seg, b)] =
            ex->fresnel ? radiance * ex->lobe[b / sc->nphi] : radiance;
}

static int burley_tube(const ppb_config *cfg, const burley_exit *ex, ppb_result *out, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    burley_piece piece[2];
    int npiece;
    if (burley_pieces(cfg, piece, &npiece, err))
        return -1;
    double e_in = ppb_scene_cos_theta_l(sc) * ex->entry; /* irradiance entering S1 */
    double power = ppb_scene_power_in(sc), surface_power[PPB_NSURF] = {0};
    for (int surf = 0; surf < PPB_NSURF; surf++) {
        double len = ppb_scene_segment_length(sc, surf);
        for (int seg = 0; seg < out->layout.nseg[surf]; seg++) {
            double flux = e_in * segment_flux(cfg, piece, npiece, surf, seg, len);
            fill_bins(out, sc, ex, surf, seg, flux);
            surface_power[surf] += flux * len;
        }
    }
    double scale = power > 0 ? 1.0 / power : 0.0;
    out->totals.R = surface_power[PPB_S1] * scale;
    out->totals.T = surface_power[PPB_S2] * scale;
    out->totals.sides = (surface_power[PPB_S3] + surface_power[PPB_S4]) * scale;
    return 0;
}

static int burley_slab(const ppb_config *cfg, const burley_exit *ex, ppb_result *out, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    burley_piece p;
    if (piece_profile(cfg, sc->sigma_t, sc->albedo, &p, err))
        return -1;
    double cos_l = ppb_scene_cos_theta_l(sc);
    out->totals.R = ex->entry * p.profile.A;
    out->totals.T = ex->entry * p.profile.A * (1.0 - ppb_burley_cdf(&p.profile, sc->height));
    out->totals.sides = 0.0;
    fill_bins(out, sc, ex, PPB_S1, 0, cos_l * out->totals.R);
    fill_bins(out, sc, ex, PPB_S2, 0, cos_l * out->totals.T);
    return 0;
}

int ppb_method_burley(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    const ppb_scene *sc = &cfg->scene;
    if (ppb_burley_check(cfg, err))
        return -1;
    out->totals.absorbed_tracked = 0; /* absorbed = 1 - the rest, by the writer */
    burley_exit ex = {.fresnel = sc->n > 1.0, .specular = 0.0, .entry = 1.0};
    if (ex.fresnel) {
        ex.specular = ppb_fresnel(ppb_scene_cos_theta_l(sc), sc->n);
        ex.entry = 1.0 - ex.specular;
        ppb_diffuse_exit_lobe(sc->n, sc->ntheta, ex.lobe);
    }
    int nseg = 0;
    for (int surf = 0; surf < out->layout.nsurf; surf++)
        nseg += out->layout.nseg[surf];
    ppb_progress pr;
    ppb_progress_begin(&pr, out->method, "segments", nseg, ctx->quiet);
    int rc = sc->geometry == PPB_GEOM_SLAB ? burley_slab(cfg, &ex, out, err)
                                           : burley_tube(cfg, &ex, out, err);
    if (rc)
        return -1;
    ppb_progress_end(&pr, nseg);
    out->totals.ballistic = ex.fresnel ? ppb_ballistic_refracted(sc) : ppb_ballistic_fraction(sc);
    out->totals.specular = ex.specular;
    if (ppb_radiance_check(cfg->name, out, NULL, err))
        return -1;
    return ppb_totals_check_completed(cfg->name, out, err);
}

int ppb_burley_check(const ppb_config *cfg, ppb_err *err)
{
    if (cfg->scene.ntheta > BURLEY_MAX_THETA)
        return ppb_config_key_fail(cfg, "bins", "theta", err, "burley: bins.theta = %d above %d",
                                   cfg->scene.ntheta, BURLEY_MAX_THETA);
    if (ppb_scene_lit_line(&cfg->scene)) /* its strip integral has no line kernel yet */
        return ppb_config_key_fail(cfg, "light", "width", err,
                                   "burley: a line searchlight (width = 0) is refused: the profile "
                                   "is integrated over a strip; use width > 0");
    return 0;
}
