/* method_mp.c: the `mp` and `mp+ss` methods (reference: Methods), the paper's multipole baseline.
 *
 * Slab mode: the multipole's plane-integrated R and T (Donner & Jensen 2005) as a Lambertian
 * exit radiance cos(theta_L) R / pi on S1 and cos(theta_L) T / pi on S2.
 * Tube: the multipole of a slab of the tube's thickness H is placed below every lit point of S1
 * (below the entry point, at every incidence angle: Jensen et al. 2001's placement, not a
 * refracted-direction one), with the medium coefficients of the entry point; each sample point
 * of S1..S4 takes the diffusive flux through its own surface from the 3-D source-to-point
 * vectors (multipole.h: exact over z, Gauss-Legendre over the lit strip), averaged over the
 * segment (its 1/rho^2 part exactly, the smooth rest on samples_seg points); radiance = flux / pi
 * in every direction bin. The ballistic total is the scene's exact one (physics/maps.h), as for
 * every deterministic method. */
#include "methods/method_mp.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/progress.h"
#include "methods/method_ss.h"
#include "methods/result_check.h"
#include "physics/maps.h"
#include "physics/multipole.h"

/* A stretch of the lit strip of S1 with one set of medium coefficients. */
typedef struct mp_piece {
    double xa, xb;
    ppb_multipole mp;
} mp_piece;

/* The lit strip, cut at the step when the medium changes there: at most two pieces. */
static int mp_pieces(const ppb_config *cfg, mp_piece piece[2], int *npiece, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    double xa = -0.5 * sc->width, xb = 0.5 * sc->width;
    if (sc->step == PPB_STEP_SHADOW)
        xb = fmin(xb, sc->step_x);
    double cut[3] = {xa, xb, xb};
    int n = 1;
    if ((sc->step == PPB_STEP_DENSITY || sc->step == PPB_STEP_ALBEDO) && sc->step_x > xa &&
        sc->step_x < xb) {
        cut[1] = sc->step_x;
        n = 2;
    }
    *npiece = 0;
    for (int i = 0; i < n; i++) {
        if (!(cut[i + 1] > cut[i]))
            continue;
        double x = 0.5 * (cut[i] + cut[i + 1]); /* the piece's coefficients: at its entry points */
        mp_piece *p = &piece[(*npiece)++];
        p->xa = cut[i];
        p->xb = cut[i + 1];
        double st = ppb_sigma_t_at(x, sc->step, sc->step_x, sc->sigma_t, sc->sigma_t_right);
        double al = ppb_albedo_at(x, sc->step, sc->step_x, sc->albedo, sc->albedo_right);
        if (ppb_multipole_init(&p->mp, st, al, sc->g, sc->height, cfg->mp.pairs, err))
            return -1;
    }
    return 0;
}

/* Segment-averaged flux per unit irradiance on S1 (multipole.h: the singular part averaged in
 * closed form, the smooth rest on samples_seg points). */
static double mp_segment_flux(const ppb_config *cfg, const mp_piece *piece, int npiece, int surf,
                              int seg, double seg_len)
{
    double x, y;
    ppb_scene_sample_point(&cfg->scene, surf, seg, &x, &y);
    int along_x = surf == PPB_S1 || surf == PPB_S2;
    double dx = along_x ? 0.5 * seg_len : 0, dy = along_x ? 0 : 0.5 * seg_len, sum = 0;
    for (int i = 0; i < npiece; i++)
        sum += ppb_multipole_segment_flux(&piece[i].mp, x - dx, y - dy, x + dx, y + dy,
                                          ppb_normal_x(surf), ppb_normal_y(surf), piece[i].xa,
                                          piece[i].xb, cfg->mp.samples, cfg->samples_seg);
    return sum;
}

static void fill_bins(ppb_result *out, int surf, int seg, double radiance)
{
    for (int b = 0; b < out->layout.nbins; b++)
        out->radiance[ppb_cell(&out->layout, surf, seg, b)] = radiance;
}

/* Issue 15: the diffusion flux through a surface can come out negative (the dipole images
 * outweigh the real sources where the slab is thin against the extrapolation distance, and at
 * strongly anisotropic g). Radiance cannot be negative, so such a segment is set to 0, counted,
 * and the count reported: never clamped silently. */
typedef struct clamp_count {
    long n;
    double low; /* most negative flux */
} clamp_count;

static double clamp_flux(clamp_count *c, double flux)
{
    if (!(flux < 0.0))
        return flux;
    c->n++;
    c->low = fmin(c->low, flux);
    return 0.0;
}

static void clamp_report(const ppb_config *cfg, const ppb_result *out, const clamp_count *c)
{
    if (c->n)
        fprintf(stderr,
                "%s: %s: warning: the diffusion flux was negative at %ld segments or faces (down "
                "to %.3g per unit irradiance); set to 0\n",
                cfg->name, out->method, c->n, c->low);
}

static int mp_tube(const ppb_config *cfg, ppb_result *out, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    mp_piece piece[2];
    int npiece;
    if (mp_pieces(cfg, piece, &npiece, err))
        return -1;
    double cos_l = ppb_scene_cos_theta_l(sc);
    double power = ppb_scene_power_in(sc); /* entering the lit S1 per unit z */
    double surface_power[PPB_NSURF] = {0};
    clamp_count neg = {0, 0.0};
    for (int surf = 0; surf < PPB_NSURF; surf++) {
        int nseg = out->layout.nseg[surf];
        double len = ppb_scene_segment_length(sc, surf);
        for (int seg = 0; seg < nseg; seg++) {
            double flux =
                clamp_flux(&neg, cos_l * mp_segment_flux(cfg, piece, npiece, surf, seg, len));
            fill_bins(out, surf, seg, flux / PPB_PI);
            surface_power[surf] += flux * len;
        }
    }
    clamp_report(cfg, out, &neg);
    double scale = power > 0 ? 1.0 / power : 0.0;
    out->totals.R = surface_power[PPB_S1] * scale;
    out->totals.T = surface_power[PPB_S2] * scale;
    out->totals.sides = (surface_power[PPB_S3] + surface_power[PPB_S4]) * scale;
    out->totals.ballistic = ppb_ballistic_fraction(sc); /* over the lit strip */
    return 0;
}

static int mp_slab(const ppb_config *cfg, ppb_result *out, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    ppb_multipole mp;
    if (ppb_multipole_init(&mp, sc->sigma_t, sc->albedo, sc->g, sc->height, cfg->mp.pairs, err))
        return -1;
    double cos_l = ppb_scene_cos_theta_l(sc);
    clamp_count neg = {0, 0.0};
    out->totals.R = clamp_flux(&neg, ppb_multipole_total_R(&mp));
    out->totals.T = clamp_flux(&neg, ppb_multipole_total_T(&mp));
    clamp_report(cfg, out, &neg);
    out->totals.sides = 0;
    out->totals.ballistic = ppb_ballistic_fraction(sc);
    fill_bins(out, PPB_S1, 0, cos_l * out->totals.R / PPB_PI);
    fill_bins(out, PPB_S2, 0, cos_l * out->totals.T / PPB_PI);
    return 0;
}

int ppb_method_mp(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    if (cfg->mp.samples < 1)
        return ppb_fail(err, "mp: mp.samples = %d, needs >= 1", cfg->mp.samples);
    out->totals.absorbed_tracked = 0; /* absorbed = 1 - the rest, by the writer */
    if (ppb_mp_check(cfg, err))
        return -1;
    int nseg = 0; /* over every surface: the slab's two faces are one segment each */
    for (int surf = 0; surf < out->layout.nsurf; surf++)
        nseg += out->layout.nseg[surf];
    ppb_progress pr; /* the completion line, as every method prints one */
    ppb_progress_begin(&pr, out->method, "segments", nseg, ctx->quiet);
    int rc = cfg->scene.geometry == PPB_GEOM_SLAB ? mp_slab(cfg, out, err) : mp_tube(cfg, out, err);
    if (!rc)
        ppb_progress_end(&pr, nseg);
    if (rc || ppb_radiance_check(cfg->name, out, NULL, err))
        return -1;
    if (strcmp(out->method, "mp") != 0)
        return 0; /* mp+ss checks its own sum */
    ppb_totals t = out->totals;
    ppb_totals_complete(&t);
    ppb_result probe = *out;
    probe.totals = t;
    return ppb_totals_check(cfg->name, &probe, err);
}

int ppb_mp_check(const ppb_config *cfg, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    /* Where the model has no meaning, say so before any work (issue 15). */
    if (sc->albedo >= 1.0)
        return ppb_config_key_fail(
            cfg, "medium", "albedo", err,
            "mp, mp+ss: albedo = 1 gives sigma_tr = 0, where the multipole's image series of a "
            "finite slab converges only conditionally (truncated, it gives T = 0); use albedo < 1 "
            "or leave mp out");
    if (sc->geometry == PPB_GEOM_TUBE && sc->step == PPB_STEP_ALBEDO && sc->albedo_right >= 1.0)
        return ppb_config_key_fail(
            cfg, "medium", "albedo_right", err,
            "mp, mp+ss: albedo = 1 gives sigma_tr = 0, where the multipole's image series of a "
            "finite slab converges only conditionally; use albedo < 1 or leave mp out");
    return ppb_method_refuse_refractive(cfg, "mp", err);
}

int ppb_mp_ss_check(const ppb_config *cfg, ppb_err *err)
{
    return ppb_mp_check(cfg, err) || ppb_ss_check(cfg, err) ? -1 : 0;
}

/* mp + ss, cell by cell. The parts are this experiment's mp and ss results when they ran before
 * (ctx->prior: the same numbers, so nothing is computed twice), else computed here. */
int ppb_method_mp_ss(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_result *mp = ppb_ctx_prior(ctx, "mp"), *ss = ppb_ctx_prior(ctx, "ss");
    int reused = (mp != NULL) + (ss != NULL);
    ppb_progress pr;
    ppb_progress_begin(&pr, out->method, reused == 2 ? "cells, mp and ss reused," : "cells",
                       (double)out->layout.ncells, ctx->quiet);
    if (mp) {
        memcpy(out->radiance, mp->radiance, out->layout.ncells * sizeof *out->radiance);
        out->totals = mp->totals;
    } else if (ppb_method_mp(ctx, out, err)) {
        return -1;
    }
    ppb_result own = {0};
    if (!ss) {
        if (ppb_result_init(&own, "ss", &out->layout, err))
            return -1;
        if (ppb_method_ss(ctx, &own, err)) {
            ppb_result_free(&own);
            return -1;
        }
        ss = &own;
    }
    for (size_t i = 0; i < out->layout.ncells; i++)
        out->radiance[i] += ss->radiance[i];
    out->totals.R += ss->totals.R; /* the diffusion already holds single scattering: MP+S counts */
    out->totals.T += ss->totals.T; /* it twice, as the paper's energy remark says */
    out->totals.sides += ss->totals.sides;
    out->partial |= ss->partial;
    ppb_result_free(&own);
    ppb_progress_end(&pr, (double)out->layout.ncells);
    ppb_result probe = *out;
    ppb_totals_complete(&probe.totals);
    return ppb_totals_check(ctx->cfg->name, &probe, err);
}
