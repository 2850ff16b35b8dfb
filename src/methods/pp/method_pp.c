/* method_pp.c: the paper's method, plane-parallel ray marching (method_pp.h): the pipeline of
 * the paper's Fig. 3, from the light maps through the slab tables to the march. */
#include "methods/pp/method_pp.h"

#include <stdio.h>
#include <string.h>

#include "base/memory.h"
#include "methods/pp/march.h"
#include "physics/totals.h"
#include "methods/result_check.h"

/* Issue 15: what the pipeline will hold at its peak, estimated before it allocates, against
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
    ppb_march_tables own = {0};
    const ppb_march_tables *tab = &own;
    if (pp_memory_check(cfg, with_modes, err) || ppb_maps_build(sc, cfg->pp.map_res, &maps, err))
        return -1;
    /* 2. The integral tables R or S from the plane-parallel solution of each column's slab
     *    (Sec. 3.2, Eq. 15-17); `ss` keeps the direct beam's term only. */
    int rc;
    if (ctx->march_cache)
        /* A sweep's earlier grid point may have built these very tables (byte-identical). */
        rc = ppb_march_cache_tables(ctx->march_cache, sc, &cfg->pp, cfg->samples_dir,
                                    PPB_MARCH_TAU_PER_MFP, with_modes, &tab, err);
    else
        rc = with_modes ? ppb_march_tables_pp(sc, &cfg->pp, cfg->samples_dir, PPB_MARCH_TAU_PER_MFP,
                                              &own, err)
                        : ppb_march_tables_ss(sc, cfg->samples_dir, &own, err);
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
    /* Issue 15: nothing non-finite is written, negative radiance is clamped with a count. */
    if (!rc)
        rc = ppb_radiance_check(cfg->name, out, NULL, err);
    if (!rc) {
        memset(out->se, 0, out->layout.ncells * sizeof *out->se);
        ppb_bin_totals(sc, &out->layout, out->radiance, &out->totals);
        rc = ppb_totals_check(cfg->name, out, err);
    }
    ppb_march_tables_free(&own);
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
    (void)cfg;
    (void)err;
    return 0;
}
