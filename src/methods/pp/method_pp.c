/* method_pp.c: the paper's method, plane-parallel ray marching (method_pp.h): the pipeline of
 * the paper's Fig. 3, from the light maps through the slab tables to the march. */
#include "methods/pp/method_pp.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/memory.h"
#include "methods/pp/march.h"
#include "physics/ppsolver.h"
#include "physics/totals.h"
#include "methods/result_check.h"

/* What the pipeline will hold at its peak, estimated before it allocates, against
 * the run's memory limit: the maps and the tables twice (host and device copy), the tables'
 * build scratch and the radiance buffer. */
static int pp_memory_check(const ppb_config *cfg, int with_modes, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    double tables, maps = ppb_maps_bytes(sc, cfg->pp.map_res);
    double build = ppb_march_tables_bytes(sc, &cfg->pp, cfg->samples_dir, PPB_MARCH_TAU_PER_MFP,
                                          with_modes, &tables);
    double cells = (double)ppb_scene_layout(sc).ncells * sizeof(double);
    double total = 2.0 * maps + build + tables + cells;
    char detail[256];
    snprintf(detail, sizeof detail, "maps %.3g GB x 2, tables %.3g GB x 2, their build %.3g GB",
             maps / 1e9, tables / 1e9, (build - tables) / 1e9);
    return ppb_memory_check(total, cfg->memory_limit, with_modes ? "pp" : "ss", detail, err);
}

/* The marcher's tables, kept for the run: a sweep's points, or pp and ss of one experiment,
 * that share a medium build them once (a hit is byte-identical to a fresh build,
 * march_tables.h). */
static ppb_march_cache *march_cache(ppb_run_ctx *ctx, ppb_err *err)
{
    static const char key[] = "pp.march_tables";
    ppb_march_cache *c = ppb_ctx_state(ctx, key);
    if (c)
        return c;
    if (!(c = ppb_march_cache_new())) {
        ppb_fail(err, "pp: out of memory for the march tables' cache");
        return NULL;
    }
    return ppb_ctx_keep(ctx, key, c, (void (*)(void *))ppb_march_cache_free, err) ? NULL : c;
}

int ppb_pp_pipeline(ppb_run_ctx *ctx, ppb_result *out, int with_modes, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    const ppb_scene *sc = &cfg->scene;
    ppb_ocl *ocl;
    if (ppb_ctx_ocl(ctx, &ocl, err))
        return -1;
    /* 1. The light maps over the cross-section: optical depth D along the light path and its
     *    average albedo (Sec. 3.3). */
    ppb_maps maps = {0};
    const ppb_march_tables *tab = NULL;
    if (pp_memory_check(cfg, with_modes, err) || ppb_maps_build(sc, cfg->pp.map_res, &maps, err))
        return -1;
    /* 2. The integral tables R or S from the plane-parallel solution of each column's slab
     *    (Sec. 3.2, Eq. 15-17); `ss` keeps the direct beam's term only. */
    ppb_march_cache *cache = march_cache(ctx, err);
    int rc = !cache || ppb_march_cache_tables(cache, sc, &cfg->pp, cfg->samples_dir,
                                              PPB_MARCH_TAU_PER_MFP, with_modes, &tab, err);
    if (rc) {
        ppb_maps_free(&maps);
        return -1;
    }
    /* 3. The march along every viewing ray of every (segment, bin) cell (Sec. 3.4, Fig. 3),
     *    then the totals (reference: Bins). */
    ppb_march_opts opts = {
        .table = cfg->pp.table, .step = cfg->pp.step, .telescope = 1, .npts = cfg->samples_seg};
    rc = ppb_march_all(ocl, sc, &maps, tab, &opts, out->method, ctx->quiet, out->radiance,
                       &out->partial, err);
    /* Nothing non-finite is written, negative radiance is clamped with a count. */
    if (!rc)
        rc = ppb_radiance_check(cfg->name, out, NULL, err);
    if (!rc) {
        memset(out->se, 0, out->layout.ncells * sizeof *out->se);
        ppb_bin_totals(sc, &out->layout, out->radiance, &out->totals);
        rc = ppb_totals_check(cfg->name, out, err);
    }
    ppb_maps_free(&maps);
    return rc;
}

int ppb_method_pp(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return ppb_pp_pipeline(ctx, out, 1, err);
}

/* At n > 1 pp marches the Fresnel slab solution (march_tables.c, kernels/march.cl) with the
 * columns and albedo nodes of n = 1: one slab per column thickness, one solution per albedo node,
 * each with its direction variants. Every n in range has a meaning: nothing is refused. */
int ppb_pp_check(const ppb_config *cfg, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    double lo, hi;
    ppb_scene_lit_range(sc, &lo, &hi);
    /* The paper's method reads a plane-parallel field along the light path: a searchlight strip
     * narrower than S1 has none (reference: Methods, `pp`). */
    if (ppb_scene_searchlight(sc) && (lo > -0.5 * sc->width || hi < 0.5 * sc->width))
        return ppb_config_key_fail(cfg, "light", "width", err,
                                   "pp: a searchlight (a strip or line narrower than S1) has no "
                                   "plane-parallel field; leave pp out or light the whole face");
    return pp_collars_check(cfg, "pp", err);
}

/* Rays the marcher traces (cells x samples_dir^2 x samples_seg) and steps along the longest
 * (the tube's diagonal or the slab's thickness at the bins' most grazing direction, over the
 * march step). */
static void work_march(const ppb_config *cfg, double *rays, double *steps)
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

void ppb_pp_march_work(const ppb_config *cfg, const char *id, FILE *f)
{
    double rays, steps;
    work_march(cfg, &rays, &steps);
    fprintf(f, "%s: %s: work: %.3g rays x up to %.3g steps = %.3g steps\n", cfg->name, id, rays,
            steps, rays * steps);
}

/* pp's work: the march, and the tables' build (slab solves x table directions). */
void ppb_pp_work(const ppb_config *cfg, const char *id, FILE *f)
{
    ppb_pp_march_work(cfg, id, f);
    double solves, ndir;
    double w = ppb_march_tables_work(&cfg->scene, &cfg->pp, cfg->samples_dir, PPB_MARCH_TAU_PER_MFP,
                                     &solves, &ndir);
    fprintf(f,
            "%s: %s: work: tables: %.3g slab solves of %d directions, %.3g table directions = "
            "about %.3g multiply-adds\n",
            cfg->name, id, solves, cfg->pp.directions, ndir, w);
}
