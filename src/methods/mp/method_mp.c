/* method_mp.c: the `mp` method (reference: Methods), the paper's multipole baseline.
 *
 * Slab mode: the multipole's plane-integrated R and T (Donner & Jensen 2005) as a Lambertian
 * exit radiance cos(theta_L) R / pi on S1 and cos(theta_L) T / pi on S2.
 * Tube: the multipole of a slab of the tube's thickness H is placed below every lit point of S1
 * (at n = 1 below the entry point, at every incidence angle: Jensen et al. 2001's placement;
 * at n > 1 along the refracted beam, below), with the medium coefficients of the entry point; each
 * sample point of S1..S4 takes the diffusive flux through its own surface from the 3-D
 * source-to-point vectors (multipole.h: exact over z, Gauss-Legendre over the lit strip), averaged
 * over the segment (its 1/rho^2 part exactly, the smooth rest on samples_seg points); radiance =
 * flux / pi in every direction bin. The ballistic total is the scene's exact one (physics/maps.h),
 * as for every deterministic method.
 *
 * n > 1 (reference: Methods, `mp`; every factor is 1 and skipped at n = 1):
 * - A = (1 + F_dr) / (1 - F_dr) with the exact inside diffuse Fresnel reflectance, z_b = 2 A D
 *   at both faces (Jensen et al. 2001 Eq. 4; Donner & Jensen 2005 Sec. 3).
 * - Entry: the sources carry the power that enters, 1 - F(theta_L) of the incident (the
 *   `specular` total is F(theta_L), as for every method), and sit on the refracted beam,
 *   1/sigma_t' from the entry point: at depth cos(theta_t)/sigma_t', shifted by
 *   sin(theta_t)/sigma_t' along x (the lit strip of sources moves with it; those of entry points
 *   that close to S4 lie beyond it, as mp's slab model has no side walls). n = 1 keeps
 *   Jensen's placement, 1/sigma_t' straight below the entry point at every angle (the paper's
 *   baseline, kept bit for bit), so at oblique light mp jumps between n = 1 and n = 1 + 0. At
 *   45 deg the refracted placement measured closer to mc at both n (README).
 * - Exit: Jensen et al. 2001's S_d = (1/pi) F_t(w_i) R_d F_t(w_o) form with the exit lobe
 *   normalised (physics/diffuse_exit.h, ppb_diffuse_exit_lobe): radiance J lobe(theta_o) / pi, so a
 *   face's total is its diffusion flux J; R, T, sides are then (1 - F(theta_L)) times the
 *   fluxes of the multipole with A and the placed sources.
 * - Ballistic: the unscattered refracted beam followed through its internal reflections (F at
 *   each face, TIR entirely) until it has left; slab mode in closed form. */
#include "methods/mp/method_mp.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/progress.h"
#include "kernels/ppb_fresnel.h"
#include "methods/result_check.h"
#include "physics/diffuse_exit.h"
#include "physics/maps.h"
#include "physics/medium.h"
#include "methods/mp/multipole.h"

/* The boundary terms at n > 1 (file comment); fresnel = 0 at n = 1, where none applies. */
#define MP_MAX_THETA 64
typedef struct mp_boundary {
    int fresnel;
    double A;                  /* boundary factor, 1 at n = 1 */
    double specular;           /* F(cos theta_L) */
    double entry;              /* 1 - F(cos theta_L) */
    double lobe[MP_MAX_THETA]; /* exit lobe per theta bin, mean 1 */
    double cos_t, sin_t;       /* the refracted beam (1, 0 at n = 1: Jensen's placement) */
} mp_boundary;

static int mp_boundary_init(const ppb_scene *sc, mp_boundary *b, ppb_err *err)
{
    b->fresnel = sc->n > 1.0;
    b->A = 1.0;
    b->specular = 0.0;
    b->entry = 1.0;
    b->cos_t = 1.0;
    b->sin_t = 0.0;
    if (!b->fresnel)
        return 0;
    if (sc->ntheta > MP_MAX_THETA)
        return ppb_fail(err, "mp: bins.theta = %d above %d", sc->ntheta, MP_MAX_THETA);
    b->A = ppb_multipole_boundary_A(sc->n);
    b->specular = ppb_fresnel(ppb_scene_cos_theta_l(sc), sc->n);
    b->entry = 1.0 - b->specular;
    b->cos_t = ppb_refract_cos(ppb_scene_cos_theta_l(sc), sc->n);
    b->sin_t = sqrt(fmax(0.0, 1.0 - b->cos_t * b->cos_t));
    ppb_diffuse_exit_lobe(sc->n, sc->ntheta, b->lobe);
    return 0;
}

/* A stretch of the lit strip of S1 with one set of medium coefficients. */
typedef struct mp_piece {
    double xa, xb;
    ppb_multipole mp;
} mp_piece;

/* The lit strip, cut at the step when the medium changes there: at most two pieces. */
static int mp_pieces(const ppb_config *cfg, const mp_boundary *bd, mp_piece piece[2], int *npiece,
                     ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    ppb_lit_piece lit[2];
    *npiece = ppb_lit_pieces(sc, lit);
    for (int i = 0; i < *npiece; i++) {
        mp_piece *p = &piece[i];
        p->xa = lit[i].xa;
        p->xb = lit[i].xb;
        if (ppb_multipole_init_boundary(&p->mp, lit[i].sigma_t, lit[i].albedo, sc->g, sc->height,
                                        cfg->mp.pairs, bd->A, bd->cos_t, err))
            return -1;
        if (bd->fresnel) { /* the sources 1/sigma_t' along the refracted beam */
            double shift = bd->sin_t / p->mp.sigma_t_reduced;
            p->xa += shift;
            p->xb += shift;
        }
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

/* A face's radiance from its flux J per unit E_perp: J / pi in every bin at n = 1, J lobe / pi
 * (the exit lobe of its theta bin) at n > 1. */
static void fill_bins(ppb_result *out, const ppb_scene *sc, const mp_boundary *bd, int surf,
                      int seg, double flux)
{
    double radiance = flux / PPB_PI;
    for (int b = 0; b < out->layout.nbins; b++)
        out->radiance[ppb_cell(&out->layout, surf, seg, b)] =
            bd->fresnel ? radiance * bd->lobe[b / sc->nphi] : radiance;
}

/* The diffusion flux through a surface can come out negative (the dipole images
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

static int mp_tube(const ppb_config *cfg, const mp_boundary *bd, ppb_result *out, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    mp_piece piece[2];
    int npiece;
    if (mp_pieces(cfg, bd, piece, &npiece, err))
        return -1;
    double cos_l = ppb_scene_cos_theta_l(sc);
    double power = ppb_scene_power_in(sc); /* entering the lit S1 per unit z */
    double surface_power[PPB_NSURF] = {0};
    clamp_count neg = {0, 0.0};
    for (int surf = 0; surf < PPB_NSURF; surf++) {
        int nseg = out->layout.nseg[surf];
        double len = ppb_scene_segment_length(sc, surf);
        for (int seg = 0; seg < nseg; seg++) {
            double flux = cos_l * mp_segment_flux(cfg, piece, npiece, surf, seg, len);
            if (bd->fresnel)
                flux *= bd->entry; /* the power that entered */
            flux = clamp_flux(&neg, flux);
            fill_bins(out, sc, bd, surf, seg, flux);
            surface_power[surf] += flux * len;
        }
    }
    clamp_report(cfg, out, &neg);
    double scale = power > 0 ? 1.0 / power : 0.0;
    out->totals.R = surface_power[PPB_S1] * scale;
    out->totals.T = surface_power[PPB_S2] * scale;
    out->totals.sides = (surface_power[PPB_S3] + surface_power[PPB_S4]) * scale;
    out->totals.ballistic = bd->fresnel ? ppb_ballistic_refracted(sc)
                                        : ppb_ballistic_fraction(sc); /* over the lit strip */
    out->totals.specular = bd->specular;
    return 0;
}

static int mp_slab(const ppb_config *cfg, const mp_boundary *bd, ppb_result *out, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    ppb_multipole mp;
    if (ppb_multipole_init_boundary(&mp, sc->sigma_t, sc->albedo, sc->g, sc->height, cfg->mp.pairs,
                                    bd->A, bd->cos_t, err))
        return -1;
    double cos_l = ppb_scene_cos_theta_l(sc);
    clamp_count neg = {0, 0.0};
    double R = ppb_multipole_total_R(&mp), T = ppb_multipole_total_T(&mp);
    if (bd->fresnel) {
        R *= bd->entry;
        T *= bd->entry;
    }
    out->totals.R = clamp_flux(&neg, R);
    out->totals.T = clamp_flux(&neg, T);
    clamp_report(cfg, out, &neg);
    out->totals.sides = 0;
    out->totals.ballistic = bd->fresnel ? ppb_ballistic_refracted(sc) : ppb_ballistic_fraction(sc);
    out->totals.specular = bd->specular;
    fill_bins(out, sc, bd, PPB_S1, 0, cos_l * out->totals.R);
    fill_bins(out, sc, bd, PPB_S2, 0, cos_l * out->totals.T);
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
    mp_boundary bd;
    if (mp_boundary_init(&cfg->scene, &bd, err))
        return -1;
    ppb_progress pr; /* the completion line, as every method prints one */
    ppb_progress_begin(&pr, out->method, "segments", nseg, ctx->quiet);
    int rc = cfg->scene.geometry == PPB_GEOM_SLAB ? mp_slab(cfg, &bd, out, err)
                                                  : mp_tube(cfg, &bd, out, err);
    if (!rc)
        ppb_progress_end(&pr, nseg);
    if (rc || ppb_radiance_check(cfg->name, out, NULL, err))
        return -1;
    return ppb_totals_check_completed(cfg->name, out, err);
}

int ppb_mp_check(const ppb_config *cfg, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    /* Where the model has no meaning, say so before any work. */
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
    if (ppb_scene_lit_line(sc)) /* its strip quadrature has no line kernel yet */
        return ppb_config_key_fail(cfg, "light", "width", err,
                                   "mp, mp+ss: a line searchlight (width = 0) is refused: the "
                                   "model integrates its sources over a strip; use width > 0");
    return 0; /* n > 1: mp has the Fresnel boundary (file comment) */
}
