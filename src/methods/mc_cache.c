#include "methods/mc_cache.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/hash.h"

static void cache_path(const char *dir, const ppb_config *cfg, char *buf, size_t cap)
{
    uint64_t key[6] = {ppb_mc_scene_fingerprint(&cfg->scene),
                       (uint64_t)cfg->mc.seed,
                       (uint64_t)cfg->mc.batches,
                       (uint64_t)cfg->mc.first,
                       (uint64_t)cfg->mc.photons,
                       0};
    memcpy(&key[5], &cfg->mc.target_noise, sizeof key[5]);
    snprintf(buf, cap, "%s/mc-%016llx.bin", dir, (unsigned long long)ppb_hash64(key, sizeof key));
}

int ppb_mc_cache_get(const char *dir, const ppb_config *cfg, ppb_mc_tallies *t)
{
    char path[PPB_PATH_MAX + 64];
    cache_path(dir, cfg, path, sizeof path);
    if (access(path, F_OK) != 0)
        return 0;
    ppb_err err = {{0}};
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

void ppb_mc_cache_put(const char *dir, const ppb_config *cfg, ppb_mc_tallies *t, long long traced)
{
    char path[PPB_PATH_MAX + 64];
    ppb_err err = {{0}};
    cache_path(dir, cfg, path, sizeof path);
    t->budget_first = t->first = (uint64_t)cfg->mc.first;
    t->budget_photons = (uint64_t)cfg->mc.photons;
    t->count = (uint64_t)traced;
    if (ppb_mkdirs(dir, &err) || ppb_mc_tallies_save(t, path, &err))
        fprintf(stderr, "%s: mc: reference cache: not stored: %s\n", cfg->name, err.msg);
}
