#include "drivers/mc_shard.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"
#include "drivers/experiment.h"
#include "methods/mc/method_mc.h"
#include "methods/registry.h"

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
    const char *ref = ppb_method_reference()->id;
    if (!ppb_config_has_method(cfg, ref))
        return ppb_fail(err, "%s: [experiment] methods has no %s to shard", cfg->path, ref);
    long long first, count;
    part_range(cfg->mc.photons, i, n, &first, &count);
    ppb_mc_tallies t;
    if (ppb_mc_tallies_init(&t, &cfg->scene, (uint64_t)cfg->mc.seed, cfg->mc.batches, err))
        return -1;
    /* The file says which photons it holds, so a merge can refuse duplicates, overlaps and
     * gaps (ppb_mc_shard_merge). */
    t.budget_first = (uint64_t)cfg->mc.first;
    t.budget_photons = (uint64_t)cfg->mc.photons;
    t.first = (uint64_t)(cfg->mc.first + first);
    t.count = (uint64_t)count;
    ppb_run_ctx ctx = {.cfg = cfg, .device_selector = device, .quiet = quiet};
    ppb_mc_trace_info info = {0};
    char path[1200];
    snprintf(path, sizeof path, "%s/mc_tallies.bin", cfg->out_dir);
    int rc = ppb_mc_trace(&ctx, cfg->mc.first + first, count, &t, &info, err);
    /* Interrupted: nothing is saved (a shard's file holds its whole range or does not exist);
     * the caller exits 130 when ppb_interrupted() says so. */
    if (rc == 0 && info.traced != count)
        rc = ppb_fail(err, "shard %d/%d interrupted after %lld of %lld photons: not saved", i, n,
                      info.traced, count);
    if (rc == 0)
        rc = ppb_mkdirs(cfg->out_dir, err) || ppb_mc_tallies_save(&t, path, err) ? -1 : 0;
    ppb_mc_tallies_free(&t);
    ppb_ctx_close(&ctx);
    return rc;
}

typedef struct shard_range {
    uint64_t first, count;
    int file; /* index into the paths */
} shard_range;

static int by_first(const void *a, const void *b)
{
    const shard_range *x = a, *y = b;
    if (x->first != y->first)
        return x->first < y->first ? -1 : 1;
    return x->count < y->count ? -1 : x->count > y->count ? 1 : x->file - y->file;
}

/* The shards' photon ranges must tile the config's budget [first, first + photons): no photon
 * twice (a duplicated or overlapping shard would count it twice), none missing. */
static int check_tiling(const ppb_config *cfg, shard_range *r, int n, char (*paths)[1200],
                        ppb_err *err)
{
    qsort(r, (size_t)n, sizeof *r, by_first);
    uint64_t at = (uint64_t)cfg->mc.first, end = at + (uint64_t)cfg->mc.photons;
    for (int k = 0; k < n; k++) {
        if (r[k].count == 0)
            continue;
        if (r[k].first < at) {
            const shard_range *p = NULL;
            for (int j = k - 1; j >= 0 && !p; j--)
                if (r[j].count && r[j].first + r[j].count > r[k].first)
                    p = &r[j];
            if (!p)
                return ppb_fail(err, "%s: photons from %llu, before the config's first photon",
                                paths[r[k].file], (unsigned long long)r[k].first);
            if (p->first == r[k].first && p->count == r[k].count)
                return ppb_fail(err,
                                "%s and %s hold the same photons [%llu, %llu): a shard given "
                                "twice",
                                paths[p->file], paths[r[k].file], (unsigned long long)r[k].first,
                                (unsigned long long)(r[k].first + r[k].count));
            return ppb_fail(err,
                            "%s (photons [%llu, %llu)) and %s (photons [%llu, %llu)) overlap: "
                            "shards of different --shard I/N",
                            paths[p->file], (unsigned long long)p->first,
                            (unsigned long long)(p->first + p->count), paths[r[k].file],
                            (unsigned long long)r[k].first,
                            (unsigned long long)(r[k].first + r[k].count));
        }
        if (r[k].first > at)
            return ppb_fail(err, "photons [%llu, %llu) are in none of the shards (the next is %s)",
                            (unsigned long long)at, (unsigned long long)r[k].first,
                            paths[r[k].file]);
        at = r[k].first + r[k].count;
        if (at > end)
            return ppb_fail(err, "%s: photons up to %llu, past the config's budget (to %llu)",
                            paths[r[k].file], (unsigned long long)at, (unsigned long long)end);
    }
    if (at < end)
        return ppb_fail(err, "photons [%llu, %llu) are in none of the shards",
                        (unsigned long long)at, (unsigned long long)end);
    return 0;
}

static int load_sum(const ppb_config *cfg, const char *const *dirs, int ndirs, ppb_mc_tallies *sum,
                    ppb_err *err)
{
    if (ppb_mc_tallies_init(sum, &cfg->scene, (uint64_t)cfg->mc.seed, cfg->mc.batches, err))
        return -1;
    char(*paths)[1200] = malloc(sizeof *paths * (size_t)ndirs);
    shard_range *r = malloc(sizeof *r * (size_t)ndirs);
    int rc = paths && r ? 0 : ppb_fail(err, "mc merge: out of memory for %d shards", ndirs);
    for (int d = 0; d < ndirs && rc == 0; d++) {
        ppb_mc_tallies t;
        snprintf(paths[d], sizeof paths[d], "%s/mc_tallies.bin", dirs[d]);
        if ((rc = ppb_mc_tallies_load(&t, paths[d], err)) != 0)
            break;
        ppb_err e = {{0}};
        if (t.budget_first != (uint64_t)cfg->mc.first ||
            t.budget_photons != (uint64_t)cfg->mc.photons)
            rc = ppb_fail(err,
                          "%s: a shard of %llu photons from photon %llu, the config asks for "
                          "%lld from %lld",
                          paths[d], (unsigned long long)t.budget_photons,
                          (unsigned long long)t.budget_first, cfg->mc.photons, cfg->mc.first);
        else if (!ppb_mc_tallies_range_matches(&t))
            rc = ppb_fail(err, "%s: its photons per batch are not those of its range [%llu, %llu)",
                          paths[d], (unsigned long long)t.first,
                          (unsigned long long)(t.first + t.count));
        else if (ppb_mc_tallies_add(sum, &t, &e))
            rc = ppb_fail(err, "%s: %s", paths[d], e.msg);
        r[d] = (shard_range){t.first, t.count, d};
        ppb_mc_tallies_free(&t);
    }
    if (rc == 0)
        rc = check_tiling(cfg, r, ndirs, paths, err);
    if (rc == 0 && (long long)ppb_mc_tallies_photons(sum) != cfg->mc.photons)
        rc = ppb_fail(err, "the shards hold %llu photons, the config asks for %lld",
                      (unsigned long long)ppb_mc_tallies_photons(sum), cfg->mc.photons);
    free(paths);
    free(r);
    return rc;
}

int ppb_mc_shard_merge(const ppb_config *cfg, const char *const *dirs, int ndirs, ppb_err *err)
{
    ppb_experiment ex = {0};
    ppb_mc_tallies sum = {0};
    if (load_sum(cfg, dirs, ndirs, &sum, err)) {
        ppb_mc_tallies_free(&sum);
        return PPB_MC_MERGE_BAD_SHARDS;
    }
    int rc = 0;
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    ex.cfg = cfg;
    ex.n = 0;
    const ppb_method *ref = ppb_method_reference();
    if (rc == 0 && (rc = ppb_result_init(&ex.res[0], ref->id, &lo, err)) == 0)
        ex.n = 1;
    if (rc == 0 && (rc = ppb_result_init(&ex.res[1], ref->also, &lo, err)) == 0)
        ex.n = 2;
    if (rc == 0) {
        ppb_mc_tallies_to_results(&sum, &cfg->scene, &ex.res[0], &ex.res[1]);
        ex.res[0].photons = ex.res[1].photons = cfg->mc.photons;
        rc = ppb_mc_tallies_attach_totals(&sum, &cfg->scene, &ex.res[0], err);
    }
    if (rc == 0) {
        rc = ppb_experiment_write(&ex, err);
    }
    if (rc == 0) /* the last line says where the results went, as `run` does */
        fprintf(stderr, "%s: wrote %s\n", cfg->name, cfg->out_dir);
    ppb_experiment_free(&ex);
    ppb_mc_tallies_free(&sum);
    return rc;
}
