/* method_pp3d.c: the object methods ss3d and pp3d (pp3d.h): the light map, pp3d's tables, the
 * march of every patch face's and pixel's rays (paper Fig. 3: pre-process, then rendering). */
#include "methods/pp3d/pp3d.h"

#include <math.h>

#include "base/clock.h"
#include "base/memory.h"

/* What both refuse before any work: a refractive boundary (the paper's Fig. 9 and this march
 * are n = 1), a light that is no unit vector, an empty grid, a material or a texture albedo
 * out of range. */
static int pp3d_check(const char *id, const ppb_object *o, ppb_err *err)
{
    double nl = sqrt(o->light_dir[0] * o->light_dir[0] + o->light_dir[1] * o->light_dir[1] +
                     o->light_dir[2] * o->light_dir[2]);
    if (o->n != 1.0)
        return ppb_fail(err, "%s: %s: n = %g: only n = 1 is marched (paper Sec. 4.2, Fig. 9)",
                        o->name, id, o->n);
    if (fabs(nl - 1.0) > 1e-9)
        return ppb_fail(err, "%s: %s: the light direction is not a unit vector (|w_L| = %g)",
                        o->name, id, nl);
    if (!(o->voxel > 0.0) || o->nx < 1 || o->ny < 1 || o->nz < 1 || o->ntheta < 1 || o->nphi < 1)
        return ppb_fail(err, "%s: %s: an empty grid or no direction bins", o->name, id);
    for (int k = 1; k <= o->nmat; k++)
        if (!(o->material[k].sigma_t > 0.0) || !(o->material[k].albedo >= 0.0) ||
            !(o->material[k].albedo <= 1.0))
            return ppb_fail(err, "%s: %s: material %d: sigma_t %g, albedo %g out of range", o->name,
                            id, k, o->material[k].sigma_t, o->material[k].albedo);
    size_t nvox = (size_t)o->nx * o->ny * o->nz;
    for (size_t v = 0; o->albedo_tex && v < nvox; v++)
        if (o->mat[v] && !(o->albedo_tex[v] >= 0.0f && o->albedo_tex[v] <= 1.0f))
            return ppb_fail(err, "%s: %s: the albedo texture holds %g at voxel %zu (not in [0, 1])",
                            o->name, id, (double)o->albedo_tex[v], v);
    return 0;
}

static int run(ppb_run_ctx *ctx, const ppb_object *o, const ppb_object_patches *p,
               ppb_object_result *out, int with_tables, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    double t0 = ppb_now();
    if (pp3d_check(out->method, o, err))
        return -1;
    ppb_pp3d_map map;
    ppb_pp3d_tables tab;
    double map_bytes = ppb_pp3d_map_bytes(o);
    if (ppb_memory_check(map_bytes, cfg->memory_limit, out->method, "the light map", err) ||
        ppb_pp3d_map_build(o, &map, err))
        return -1;
    if (with_tables && ppb_pp3d_tables_build(o, &map, &cfg->pp, cfg->memory_limit, map_bytes,
                                             ctx->quiet, &tab, err)) {
        ppb_pp3d_map_free(&map);
        return -1;
    }
    double t1 = ppb_now();
    int rc = ppb_pp3d_render(o, p, &map, with_tables ? &tab : NULL, cfg->samples_dir,
                             cfg->samples_seg, cfg->pp.step, ctx->quiet, out, err);
    double t2 = ppb_now();
    /* The frame the paper times (Sec. 4.2: 0.17 s): the camera's image alone, traced once more
     * into a scratch image (the pre-process, map and tables, excluded), reported in
     * totals_<method>.csv beside the pre-process and the whole render. */
    size_t npix = (size_t)o->img_w * o->img_h;
    double *img = rc ? NULL : malloc(npix * sizeof *img), tf = ppb_now();
    if (!rc && !img)
        rc = ppb_fail(err, "%s: %s: out of memory for the timed frame", o->name, out->method);
    if (!rc)
        rc = ppb_pp3d_image(o, &map, with_tables ? &tab : NULL, cfg->samples_seg, cfg->pp.step, img,
                            err);
    double frame = ppb_now() - tf;
    free(img);
    char *csv = rc ? NULL : malloc(256);
    if (csv) {
        snprintf(csv, 256, "preprocess_s,render_s,frame_s,frame_rays\n%.4f,%.4f,%.4f,%zu\n",
                 t1 - t0, t2 - t1, frame, npix * (size_t)cfg->samples_seg * cfg->samples_seg);
        out->totals_csv = csv;
    }
    if (with_tables)
        ppb_pp3d_tables_free(&tab);
    ppb_pp3d_map_free(&map);
    out->seconds = ppb_now() - t0;
    return rc;
}

int ppb_pp3d_run_ss3d(ppb_run_ctx *ctx, const ppb_object *o, const ppb_object_patches *p,
                      ppb_object_result *out, ppb_err *err)
{
    return run(ctx, o, p, out, 0, err);
}

int ppb_pp3d_run_pp3d(ppb_run_ctx *ctx, const ppb_object *o, const ppb_object_patches *p,
                      ppb_object_result *out, ppb_err *err)
{
    return run(ctx, o, p, out, 1, err);
}

const ppb_object_method ppb_object_method_ss3d = {
    .id = "ss3d",
    .summary = "single scattering marched through the voxels, exact per crossing (paper Eq. 5)",
    .run = ppb_pp3d_run_ss3d,
};

const ppb_object_method ppb_object_method_pp3d = {
    .id = "pp3d",
    .summary = "the paper's plane-parallel ray marcher on the object (Sec. 3.4, Eq. 13-15)",
    .run = ppb_pp3d_run_pp3d,
};
