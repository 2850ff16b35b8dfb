/* work_estimate.c: work and result memory estimated before allocating (work_estimate.h). */
#include "methods/work_estimate.h"

#include <math.h>
#include <string.h>

#include "kernels/mc_params.h"
#include "methods/method_ss.h"
#include "methods/march.h"
#include "methods/registry.h"
#include "physics/march_tables.h"
#include "model/scene.h"

double ppb_work_mc_events(const ppb_config *cfg)
{
    const ppb_scene *sc = &cfg->scene;
    double a = sc->albedo;
    if (sc->step == PPB_STEP_ALBEDO && sc->albedo_right > a)
        a = sc->albedo_right;
    double by_weight = a <= 0.0 ? 1.0 : a >= 1.0 ? INFINITY : 1.0 + log(PPB_MC_ROULETTE_W) / log(a);
    double size = sc->geometry == PPB_GEOM_SLAB ? sc->height : fmin(sc->width, sc->height);
    double L = size * fmax(sc->sigma_t, sc->step == PPB_STEP_DENSITY ? sc->sigma_t_right : 0.0);
    double by_size = 1.0 + L + L * L;
    return fmin(fmin(by_weight, by_size), (double)PPB_MC_EVENT_CAP);
}

void ppb_work_march(const ppb_config *cfg, double *rays, double *steps)
{
    const ppb_scene *sc = &cfg->scene;
    double cells = (double)ppb_scene_layout(sc).ncells;
    *rays = cells * cfg->samples_dir * cfg->samples_dir * cfg->samples_seg;
    /* The most grazing direction sampled: the last theta bin's outer edge is 90 deg, its
     * samples lie inside it, at about 1 / (2 theta_bins samples_dir) of the projected solid
     * angle from it. */
    double mu = sqrt(1.0 / (2.0 * sc->ntheta * cfg->samples_dir));
    double len = sc->geometry == PPB_GEOM_SLAB
                     ? sc->height / mu
                     : sqrt(sc->width * sc->width + sc->height * sc->height);
    *steps = ceil(len / cfg->pp.step);
}

double ppb_work_results_bytes(const ppb_config *cfg)
{
    double nres = 0;
    for (int m = 0; m < cfg->nmethods; m++) {
        const ppb_method *me = ppb_method_find(cfg, cfg->methods[m]);
        nres += me && me->also ? 2 : 1;
    }
    return nres * (double)ppb_scene_layout(&cfg->scene).ncells * 2.0 * sizeof(double);
}

void ppb_work_print(FILE *f, const ppb_config *cfg)
{
    for (int m = 0; m < cfg->nmethods; m++) {
        const char *id = cfg->methods[m];
        if (strcmp(id, "mc") == 0) {
            double e = ppb_work_mc_events(cfg);
            fprintf(f, "%s: mc: work: %lld photons x about %.3g events = %.3g events\n", cfg->name,
                    cfg->mc.photons, e, (double)cfg->mc.photons * e);
        } else if (strcmp(id, "pp") == 0 || strcmp(id, "ss") == 0 || strcmp(id, "mp+ss") == 0) {
            double rays, steps;
            ppb_work_march(cfg, &rays, &steps);
            fprintf(f, "%s: %s: work: %.3g rays x up to %.3g steps = %.3g steps\n", cfg->name, id,
                    rays, steps, rays * steps);
            if (strcmp(id, "pp") == 0) {
                double solves, ndir;
                double w = ppb_march_tables_work(&cfg->scene, &cfg->pp, cfg->samples_dir,
                                                 PPB_MARCH_TAU_PER_MFP, &solves, &ndir);
                fprintf(f,
                        "%s: pp: work: tables: %.3g slab solves of %d directions, %.3g "
                        "table directions = about %.3g multiply-adds\n",
                        cfg->name, solves, cfg->pp.directions, ndir, w);
            }
            ppb_work_img w;
            if (strcmp(id, "pp") != 0 && ppb_work_images(cfg, &w))
                fprintf(f,
                        "%s: %s: work: the beam's images: %.3g rays x up to %.3g legs x %.3g "
                        "rows x %.3g tiles = %.3g terms (at most %.3g)\n",
                        cfg->name, id, w.rays, w.legs, w.rows, w.per_row, w.terms,
                        PPB_WORK_IMAGE_TERMS_MAX);
        }
    }
}
