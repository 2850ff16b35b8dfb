#include "drivers/mc_shard.h"

#include <stdio.h>

#include "base/atomic_file.h"
#include "drivers/experiment.h"
#include "methods/method_mc.h"

/* Photons of part i of n: a contiguous range, the remainder spread over the first parts. */
static void part_range(long long total, int i, int n, long long *first, long long *count)
{
    long long base = total / n, extra = total % n;
    long long k = i - 1;
    *first = k * base + (k < extra ? k : extra);
    *count = base + (k < extra ? 1 : 0);
}

int ppb_mc_shard_run(const ppb_config *cfg, const char *device, int quiet, int i, int n,
                     ppb_err *err)
{
    if (!ppb_config_has_method(cfg, "mc"))
        return ppb_fail(err, "%s: [experiment] methods has no mc to shard", cfg->path);
    long long first, count;
    part_range(cfg->mc.photons, i, n, &first, &count);
    ppb_mc_tallies t;
    if (ppb_mc_tallies_init(&t, &cfg->scene, (uint64_t)cfg->mc.seed, cfg->mc.batches, err))
        return -1;
    ppb_run_ctx ctx = {.cfg = cfg, .device_selector = device, .quiet = quiet};
    ppb_mc_trace_info info = {0};
    char path[1200];
    snprintf(path, sizeof path, "%s/mc_tallies.bin", cfg->out_dir);
    int rc = ppb_mc_trace(&ctx, cfg->mc.first + first, count, &t, &info, err);
    if (rc == 0 && info.traced != count)
        rc = ppb_fail(err, "shard %d/%d interrupted after %lld of %lld photons: not saved", i, n,
                      info.traced, count);
    if (rc == 0)
        rc = ppb_mkdirs(cfg->out_dir, err) || ppb_mc_tallies_save(&t, path, err) ? -1 : 0;
    ppb_mc_tallies_free(&t);
    ppb_ctx_close(&ctx);
    return rc;
}

static int load_sum(const ppb_config *cfg, const char *const *dirs, int ndirs, ppb_mc_tallies *sum,
                    ppb_err *err)
{
    if (ppb_mc_tallies_init(sum, &cfg->scene, (uint64_t)cfg->mc.seed, cfg->mc.batches, err))
        return -1;
    for (int d = 0; d < ndirs; d++) {
        char path[1200];
        ppb_mc_tallies t;
        snprintf(path, sizeof path, "%s/mc_tallies.bin", dirs[d]);
        if (ppb_mc_tallies_load(&t, path, err))
            return -1;
        int rc = ppb_mc_tallies_add(sum, &t, err);
        ppb_mc_tallies_free(&t);
        if (rc)
            return ppb_fail(err, "%s: %s", path, err->msg);
    }
    if ((long long)ppb_mc_tallies_photons(sum) != cfg->mc.photons)
        return ppb_fail(err, "the shards hold %llu photons, the config asks for %lld",
                        (unsigned long long)ppb_mc_tallies_photons(sum), cfg->mc.photons);
    return 0;
}

int ppb_mc_shard_merge(const ppb_config *cfg, const char *const *dirs, int ndirs, ppb_err *err)
{
    ppb_experiment ex = {0};
    ppb_mc_tallies sum = {0};
    int rc = load_sum(cfg, dirs, ndirs, &sum, err);
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    ex.cfg = cfg;
    ex.n = 0;
    if (rc == 0 && (rc = ppb_result_init(&ex.res[0], "mc", &lo, err)) == 0)
        ex.n = 1;
    if (rc == 0 && (rc = ppb_result_init(&ex.res[1], "mc1", &lo, err)) == 0)
        ex.n = 2;
    if (rc == 0) {
        ppb_mc_tallies_to_results(&sum, &cfg->scene, &ex.res[0], &ex.res[1]);
        ex.res[0].photons = ex.res[1].photons = cfg->mc.photons;
        rc = ppb_experiment_write(&ex, err);
    }
    ppb_experiment_free(&ex);
    ppb_mc_tallies_free(&sum);
    return rc;
}
