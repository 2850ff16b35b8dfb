/* method_ss.c: single scattering by ray marching (method_ss.h). */
#include "methods/pp/method_ss.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "kernels/ppb_fresnel.h"
#include "methods/pp/method_pp.h"

int ppb_method_ss(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return ppb_pp_pipeline(ctx, out, 0, err);
}

int ppb_work_images(const ppb_config *cfg, ppb_work_img *w)
{
    const ppb_scene *sc = &cfg->scene;
    memset(w, 0, sizeof *w);
    if (sc->geometry != PPB_GEOM_TUBE || !(sc->n > 1.0))
        return 0;
    ppb_fresnel_beam b = ppb_fresnel_beam_in(ppb_scene_cos_theta_l(sc), sc->n);
    if (!(b.sin_t > 0.0))
        return 0;
    const double d_cap = 40.0, tol = 0x1p-60; /* march.c's d_cap, ppb_beam_images.h's tolerance */
    double W = sc->width, H = sc->height, tn = b.sin_t / b.cos_t;
    double sig = sc->step == PPB_STEP_DENSITY ? fmin(sc->sigma_t, sc->sigma_t_right) : sc->sigma_t;
    double jmax = ceil(d_cap * b.cos_t / (sig * H));
    double r = b.f_inside * exp(-sig * H / b.cos_t);
    double jtol = r > 0.0 ? ceil(log(tol) / log(r)) : 1.0;
    w->rows = fmin(jmax, jtol) + 1.0;
    w->per_row = floor(1.0 + H * tn / W) + 3.0;
    /* A viewing-ray leg spans at least the smaller side's optical size; legs stop at d_cap or
     * after 4096 (march.cl). */
    double smin = sc->step == PPB_STEP_DENSITY ? fmin(sc->sigma_t, sc->sigma_t_right) : sc->sigma_t;
    w->legs = fmin(4096.0, ceil(d_cap / (smin * fmin(W, H))));
    /* work_estimate.h's rays of the marcher: cells x samples_dir^2 x samples_seg */
    w->rays = (double)ppb_scene_layout(sc).ncells * cfg->samples_dir * cfg->samples_dir *
              cfg->samples_seg;
    w->terms = w->rays * w->legs * w->rows * w->per_row;
    return 1;
}

/* At n > 1 ss marches the refracted beam and its reflections (kernels/march.cl): off S2 and S1
 * in the slab and in the tube at normal incidence, off all four faces by the cross-section's
 * mirror images at oblique incidence, where a density step's images enter the beam's optical
 * depth (ppb_image_depth). Every n in range has a meaning; what is refused is a cost: an image
 * series whose terms, estimated before any work (method_ss.h), exceed
 * PPB_WORK_IMAGE_TERMS_MAX (method_ss.h; a thin tube at grazing light near the critical angle,
 * where F_b is near 1 and a row of images adds little depth). */
int ppb_ss_check(const ppb_config *cfg, ppb_err *err)
{
    /* A line's once-scattered light is a line integral along the viewing ray's crossing of one
     * light plane, not the volume source the march integrates (reference: Methods, `ss`). */
    if (ppb_scene_lit_line(&cfg->scene))
        return ppb_config_key_fail(cfg, "light", "width", err,
                                   "ss: a line searchlight (width = 0) is refused: its single "
                                   "scattering is a line integral the march does not take; use "
                                   "a strip (width > 0)");
    ppb_work_img w;
    if (!ppb_work_images(cfg, &w) || w.terms <= PPB_WORK_IMAGE_TERMS_MAX)
        return 0;
    return ppb_fail(err,
                    "ss: the beam's images need up to %.3g terms (%.3g rays x up to %.3g legs x "
                    "%.3g rows x %.3g tiles), above the %.3g ss runs (docs/reference.md: "
                    "Methods): a thicker tube, light nearer the normal or fewer bins",
                    w.terms, w.rays, w.legs, w.rows, w.per_row, PPB_WORK_IMAGE_TERMS_MAX);
}

/* ss's work hook (and a sum's that holds ss): the march, then the beam's image series where it
 * applies. */
void ppb_ss_work(const ppb_config *cfg, const char *id, FILE *f)
{
    ppb_pp_march_work(cfg, id, f);
    ppb_work_img w;
    if (ppb_work_images(cfg, &w))
        fprintf(f,
                "%s: %s: work: the beam's images: %.3g rays x up to %.3g legs x %.3g rows x %.3g "
                "tiles = %.3g terms (at most %.3g)\n",
                cfg->name, id, w.rays, w.legs, w.rows, w.per_row, w.terms,
                PPB_WORK_IMAGE_TERMS_MAX);
}
