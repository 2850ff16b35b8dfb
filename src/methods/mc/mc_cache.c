#include "methods/mc/mc_cache.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/hash.h"

/* The device and its driver, hashed: "platform / device" and CL_DRIVER_VERSION. */
static int device_hash(ppb_run_ctx *ctx, uint64_t *h, ppb_err *err)
{
    ppb_ocl *ocl;
    if (ppb_ctx_ocl(ctx, &ocl, err))
        return -1;
    char text[1024];
    size_t n = (size_t)snprintf(text, sizeof text, "%s\n", ocl->name);
    if (n < sizeof text && ppb_cl_check(clGetDeviceInfo(ocl->device, CL_DRIVER_VERSION,
                                                        sizeof text - n, text + n, NULL),
                                        "clGetDeviceInfo(CL_DRIVER_VERSION)", err))
        return -1;
    *h = ppb_hash64(text, strlen(text));
    return 0;
}

/* DIR/mc-<key>.bin (mc_cache.h lists what the key holds). */
static int cache_path(ppb_run_ctx *ctx, char *buf, size_t cap, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    uint64_t key[9] = {PPB_MC_CACHE_VERSION,
                       ppb_mc_scene_fingerprint(&cfg->scene),
                       (uint64_t)cfg->mc.seed,
                       (uint64_t)cfg->mc.batches,
                       (uint64_t)cfg->mc.first,
                       (uint64_t)cfg->mc.photons,
                       0,
                       0,
                       0};
    memcpy(&key[6], &cfg->mc.target_noise, sizeof key[6]);
    if (ppb_ocl_source_hash(PPB_MC_KERNEL, &key[7], err) || device_hash(ctx, &key[8], err))
        return -1;
    snprintf(buf, cap, "%s/mc-%016llx.bin", ctx->ref_cache,
             (unsigned long long)ppb_hash64(key, sizeof key));
    return 0;
}

int ppb_mc_cache_get(ppb_run_ctx *ctx, ppb_mc_tallies *t)
{
    const ppb_config *cfg = ctx->cfg;
    char path[PPB_PATH_MAX + 64];
    ppb_err err = {{0}};
    if (!ctx->ref_cache)
        return 0;
    if (cache_path(ctx, path, sizeof path, &err)) {
        fprintf(stderr, "%s: mc: reference cache: %s: not used\n", cfg->name, err.msg);
        return 0;
    }
    if (access(path, F_OK) != 0)
        return 0;
    ppb_mc_tallies c;
    if (ppb_mc_tallies_load(&c, path, &err)) {
        fprintf(stderr, "%s: mc: reference cache: %s: not used\n", cfg->name, err.msg);
        return 0;
    }
    int full = cfg->mc.target_noise > 0 || c.count == (uint64_t)cfg->mc.photons;
    if (c.fingerprint != ppb_mc_scene_fingerprint(&cfg->scene) ||
        c.seed != (uint64_t)cfg->mc.seed || c.batches != cfg->mc.batches ||
        c.first != (uint64_t)cfg->mc.first || c.budget_photons != (uint64_t)cfg->mc.photons ||
        !full || !ppb_mc_tallies_range_matches(&c)) {
        fprintf(stderr, "%s: mc: reference cache: %s holds another reference: not used\n",
                cfg->name, path);
        ppb_mc_tallies_free(&c);
        return 0;
    }
    *t = c;
    return 1;
}

void ppb_mc_cache_put(ppb_run_ctx *ctx, ppb_mc_tallies *t, long long traced)
{
    const ppb_config *cfg = ctx->cfg;
    char path[PPB_PATH_MAX + 64];
    ppb_err err = {{0}};
    if (!ctx->ref_cache)
        return;
    t->budget_first = t->first = (uint64_t)cfg->mc.first;
    t->budget_photons = (uint64_t)cfg->mc.photons;
    t->count = (uint64_t)traced;
    if (cache_path(ctx, path, sizeof path, &err) || ppb_mkdirs(ctx->ref_cache, &err) ||
        ppb_mc_tallies_save(t, path, &err))
        fprintf(stderr, "%s: mc: reference cache: not stored: %s\n", cfg->name, err.msg);
}
