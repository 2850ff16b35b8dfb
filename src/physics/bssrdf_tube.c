/* bssrdf_tube.c: a BSSRDF model's profile applied to the tube (bssrdf_tube.h; reference:
 * Methods, "Diffusion profiles in the tube"). */
#include "physics/bssrdf_tube.h"

#include "base/progress.h"
#include "kernels/ppb_fresnel.h"
#include "physics/diffuse_exit.h"
#include "physics/maps.h"
#include "physics/medium.h"

typedef struct bssrdf_exit {
    int fresnel;
    double specular, entry;
    double lobe[PPB_BSSRDF_MAX_THETA]; /* per theta bin, mean 1 (n > 1) */
} bssrdf_exit;

/* The flux at the exit point (x, y) per unit entering irradiance (per unit line strength for
 * a line), summed over the lit pieces. */
static double point_flux(const ppb_bssrdf *m, const ppb_lit_piece *lit, int nlit, double x,
                         double y, int surf)
{
    double sum = 0.0;
    for (int i = 0; i < nlit; i++)
        sum += lit[i].xa == lit[i].xb ? m->line(m->model, i, lit[i].xa, x, y, surf)
                                      : m->strip(m->model, i, lit[i].xa, lit[i].xb, x, y, surf);
    return sum;
}

/* The midpoint rule on `points` points over the stretch of length len centred at mid, along x
 * (S1, S2: at y = other) or along y (the sides: at x = other): the sum of the fluxes. */
static double midpoint_sum(const ppb_bssrdf *m, const ppb_lit_piece *lit, int nlit, int surf,
                           int along_x, double mid, double len, double other, int points)
{
    double sum = 0.0;
    for (int j = 0; j < points; j++) {
        double t = mid + ((j + 0.5) / points - 0.5) * len;
        sum += along_x ? point_flux(m, lit, nlit, t, other, surf)
                       : point_flux(m, lit, nlit, other, t, surf);
    }
    return sum;
}

/* Flux per unit entering irradiance averaged over a segment: the strips' flux at samples_seg
 * points spread evenly over it (the midpoint rule); a segment of S1 with a line inside it is
 * split at the line, each part by its own midpoint rule, weighted by its length. */
static double segment_flux(const ppb_config *cfg, const ppb_bssrdf *m, const ppb_lit_piece *lit,
                           int nlit, int surf, int seg, double seg_len)
{
    double x, y;
    ppb_scene_sample_point(&cfg->scene, surf, seg, &x, &y);
    int along_x = surf == PPB_S1 || surf == PPB_S2, points = cfg->samples_seg;
    points = points < 1 ? 1 : points;
    double a = x - 0.5 * seg_len, b = x + 0.5 * seg_len;
    for (int i = 0; i < nlit && surf == PPB_S1; i++) {
        double xl = lit[i].xa, la = xl - a, lb = b - xl;
        if (lit[i].xb == xl && la > 0.0 && lb > 0.0)
            return (midpoint_sum(m, lit, nlit, surf, 1, a + 0.5 * la, la, y, points) * la +
                    midpoint_sum(m, lit, nlit, surf, 1, xl + 0.5 * lb, lb, y, points) * lb) /
                   (points * seg_len);
    }
    return midpoint_sum(m, lit, nlit, surf, along_x, along_x ? x : y, seg_len, along_x ? y : x,
                        points) /
           points;
}

static void fill_bins(ppb_result *out, const ppb_scene *sc, const bssrdf_exit *ex, int surf,
                      int seg, double flux)
{
    double radiance = flux / PPB_PI;
    for (int b = 0; b < out->layout.nbins; b++)
        out->radiance[ppb_cell(&out->layout, surf, seg, b)] =
            ex->fresnel ? radiance * ex->lobe[b / sc->nphi] : radiance;
}

static void fill_tube(const ppb_config *cfg, const ppb_bssrdf *m, const bssrdf_exit *ex,
                      ppb_progress *pr, ppb_result *out)
{
    const ppb_scene *sc = &cfg->scene;
    ppb_lit_piece lit[2];
    int nlit = ppb_lit_pieces(sc, lit), done = 0;
    double e_in = ppb_scene_cos_theta_l(sc) * ex->entry; /* irradiance entering S1 */
    double power = ppb_scene_power_in(sc), surface_power[PPB_NSURF] = {0};
    for (int surf = 0; surf < PPB_NSURF; surf++) {
        double len = ppb_scene_segment_length(sc, surf);
        for (int seg = 0; seg < out->layout.nseg[surf]; seg++) {
            double flux = e_in * segment_flux(cfg, m, lit, nlit, surf, seg, len);
            fill_bins(out, sc, ex, surf, seg, flux);
            surface_power[surf] += flux * len;
            ppb_progress_update(pr, ++done);
        }
    }
    double scale = power > 0 ? 1.0 / power : 0.0;
    out->totals.R = surface_power[PPB_S1] * scale;
    out->totals.T = surface_power[PPB_S2] * scale;
    out->totals.sides = (surface_power[PPB_S3] + surface_power[PPB_S4]) * scale;
}

static void fill_slab(const ppb_config *cfg, const ppb_bssrdf *m, const bssrdf_exit *ex,
                      ppb_result *out)
{
    const ppb_scene *sc = &cfg->scene;
    double R, T, cos_l = ppb_scene_cos_theta_l(sc);
    m->slab(m->model, sc->height, &R, &T);
    out->totals.R = ex->entry * R;
    out->totals.T = ex->entry * T;
    out->totals.sides = 0.0;
    fill_bins(out, sc, ex, PPB_S1, 0, cos_l * out->totals.R);
    fill_bins(out, sc, ex, PPB_S2, 0, cos_l * out->totals.T);
}

int ppb_bssrdf_fill(const ppb_config *cfg, const ppb_bssrdf *m, int quiet, ppb_result *out,
                    ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    if (ppb_bssrdf_check(cfg, out->method, m->line != NULL, err))
        return -1;
    out->totals.absorbed_tracked = 0; /* absorbed = 1 - the rest, by the writer */
    bssrdf_exit ex = {.fresnel = sc->n > 1.0, .specular = 0.0, .entry = 1.0};
    if (ex.fresnel) {
        ex.specular = ppb_fresnel(ppb_scene_cos_theta_l(sc), sc->n);
        ex.entry = 1.0 - ex.specular;
        ppb_diffuse_exit_lobe(sc->n, sc->ntheta, ex.lobe);
    }
    int nseg = 0;
    for (int surf = 0; surf < out->layout.nsurf; surf++)
        nseg += out->layout.nseg[surf];
    ppb_progress pr;
    ppb_progress_begin(&pr, out->method, "segments", nseg, quiet);
    if (sc->geometry == PPB_GEOM_SLAB)
        fill_slab(cfg, m, &ex, out);
    else
        fill_tube(cfg, m, &ex, &pr, out);
    ppb_progress_end(&pr, nseg);
    out->totals.ballistic = ex.fresnel ? ppb_ballistic_refracted(sc) : ppb_ballistic_fraction(sc);
    out->totals.specular = ex.specular;
    return 0;
}

int ppb_bssrdf_check(const ppb_config *cfg, const char *id, int has_line, ppb_err *err)
{
    if (cfg->scene.ntheta > PPB_BSSRDF_MAX_THETA)
        return ppb_config_key_fail(cfg, "bins", "theta", err, "%s: bins.theta = %d above %d", id,
                                   cfg->scene.ntheta, PPB_BSSRDF_MAX_THETA);
    /* The strip callback integrates a profile over [xa, xb]: a line searchlight (xa == xb)
     * needs the model's line kernel at the point instead (reference: Light). */
    if (ppb_scene_lit_line(&cfg->scene) && !has_line)
        return ppb_config_key_fail(cfg, "light", "width", err,
                                   "%s: a line searchlight (width = 0) is refused: the model has "
                                   "no line kernel; use width > 0",
                                   id);
    return 0;
}
