/* test_cache_keys.c: the Monte Carlo reference cache's key against the config key table
 * (methods/mc/mc_cache.h; docs/external.md, "The reference cache").
 *
 * The expected outcomes come from the table's own flags (model/config.h, ppb_mc_key), not from
 * the cache code: every key the table marks PPB_MC_KEY, changed alone to another valid value of
 * its range, must be a miss (another file, and nothing loaded); every other key changed alone
 * must be a hit (the same file, loaded). The tests iterate the table, so a key added later is
 * covered by its flag, and a key whose flag is neither value fails here. With a target noise
 * the run stops between launches, so the photons per launch (mc.chunk, or the device's size
 * with $PPBENCH_MC_LANES) set how many photons it traces: the end-to-end case shows two chunk
 * sizes tracing different counts, and that the second is not served the first's tallies. */
#include "cliutil.h"

#include <unistd.h>

#include "methods/mc/mc_cache.h"
#include "methods/mc/mc_tally.h"
#include "methods/mc/method_mc.h"
#include "model/config.h"

/* The defaults with a small layout, so the stored tallies are a few KB. */
static void small_config(ppb_config *cfg)
{
    ppb_err err;
    if (ppb_config_defaults(cfg, &err))
        fail_msg("%s", err.msg);
    const char *sets[][3] = {{"tube", "segments_top", "8"}, {"tube", "segments_side", "3"},
                             {"bins", "theta", "2"},        {"bins", "phi", "2"},
                             {"mc", "photons", "20000"},    {"mc", "batches", "4"}};
    for (size_t i = 0; i < sizeof sets / sizeof sets[0]; i++)
        if (ppb_config_set(cfg, sets[i][0], sets[i][1], sets[i][2], &err))
            fail_msg("%s", err.msg);
}

static void key_line(const ppb_config *cfg, int k, char *buf, size_t cap)
{
    FILE *f = fmemopen(buf, cap, "w");
    assert_non_null(f);
    ppb_config_write_key(cfg, k, f);
    fclose(f);
}

/* Sets key k of *cfg to a valid value other than its current one, taken from the table: the
 * range's ends, its middle, the default, an enum's other names; a name, path or method list gets
 * another text. Fails the test when the table offers none the config accepts. */
static void change_key(ppb_config *cfg, int k)
{
    ppb_key_info in;
    ppb_config_key_info(k, &in);
    char before[2048], after[2048], cand[12][64];
    int n = 0;
    key_line(cfg, k, before, sizeof before);
    if (in.number) {
        snprintf(cand[n++], 64, "%.17g", in.min);
        snprintf(cand[n++], 64, "%.17g", in.max);
        snprintf(cand[n++], 64, in.integer ? "%.0f" : "%.17g", floor((in.min + in.max) / 2));
        snprintf(cand[n++], 64, "%.17g", (in.min + in.max) / 2);
        snprintf(cand[n++], 64, "%s", in.def);
    } else if (in.enums[0]) {
        for (int i = 0; in.enums[i] && n < 12; i++)
            snprintf(cand[n++], 64, "%s", in.enums[i]);
    } else if (strcmp(in.section, "experiment") == 0 && strcmp(in.key, "methods") == 0) {
        snprintf(cand[n++], 64, "mp");
    } else { /* a name or a path */
        snprintf(cand[n++], 64, "other_name");
        snprintf(cand[n++], 64, "/elsewhere/other");
    }
    ppb_err err;
    /* [medium] material takes a name of the table and unit = mm (a key that alone changes
     * nothing, so a hit by this same test); channel also needs a material, so its change comes
     * with one here: that each channel has its own reference is test_materials.c's
     * (test_cache_paths_distinct, every material and channel). */
    ppb_config pre = *cfg;
    int material = strcmp(in.section, "medium") == 0 && strcmp(in.key, "material") == 0;
    if (material || (strcmp(in.section, "medium") == 0 && strcmp(in.key, "channel") == 0)) {
        if (ppb_config_set(&pre, "experiment", "unit", "mm", &err) ||
            (!material && ppb_config_set(&pre, "medium", "material", "skimmilk", &err)))
            fail_msg("%s", err.msg);
        if (material) {
            n = 0;
            snprintf(cand[n++], 64, "skimmilk");
        }
    }
    for (int i = 0; i < n; i++) {
        ppb_config c = pre;
        if (ppb_config_set(&c, in.section, in.key, cand[i], &err))
            continue;
        key_line(&c, k, after, sizeof after);
        if (strcmp(before, after) != 0) {
            *cfg = c;
            return;
        }
    }
    fail_msg("%s.%s: no other valid value among the table's range and names", in.section, in.key);
}

/* Every key states whether it changes the Monte Carlo (0 is no decision). */
static void test_every_key_decided(void **state)
{
    (void)state;
    int nmc = 0;
    assert_true(ppb_config_nkeys() > 0);
    for (int k = 0; k < ppb_config_nkeys(); k++) {
        ppb_key_info in;
        ppb_config_key_info(k, &in);
        if (in.mc != PPB_MC_KEY && in.mc != PPB_NOT_MC_KEY)
            fail_msg("%s.%s: the key table says neither PPB_MC_KEY nor PPB_NOT_MC_KEY (%d)",
                     in.section, in.key, (int)in.mc);
        nmc += in.mc == PPB_MC_KEY;
    }
    /* The scene, light, bins and the photon range are the Monte Carlo's: more than a handful. */
    assert_true(nmc >= 10);
}

/* Each key changed alone, against one stored reference. The keys the table marks PPB_MC_KEY
 * miss (another path, and get finds nothing), the others hit (the same path, and get loads the
 * tallies). */
static void test_keys_hit_miss(void **state)
{
    (void)state;
    ppb_err err;
    ppb_config base;
    small_config(&base);
    char dir[1100];
    snprintf(dir, sizeof dir, "%s/cache", tu_scratch("cache_keys"));
    ppb_run_ctx ctx = {.cfg = &base, .quiet = 1, .ref_cache = dir};
    /* A stored reference: zero tallies over the whole photon range, as a finished trace. */
    ppb_mc_tallies t;
    if (ppb_mc_tallies_init(&t, &base.scene, (uint64_t)base.mc.seed, base.mc.batches, &err))
        fail_msg("%s", err.msg);
    ppb_mc_tallies_count_range(&t, (uint64_t)base.mc.first, (uint64_t)base.mc.photons);
    ppb_mc_cache_put(&ctx, 0, &t, base.mc.photons);
    ppb_mc_tallies_free(&t);
    char path0[1300], path[1300];
    if (ppb_mc_cache_path(&ctx, 0, path0, sizeof path0, &err))
        fail_msg("%s", err.msg);
    assert_int_equal(access(path0, F_OK), 0);
    assert_int_equal(ppb_mc_cache_get(&ctx, 0, &t), 1); /* the unchanged config: a hit */
    ppb_mc_tallies_free(&t);
    int bad = 0;
    for (int k = 0; k < ppb_config_nkeys(); k++) {
        ppb_key_info in;
        ppb_config_key_info(k, &in);
        ppb_config c = base;
        change_key(&c, k);
        ctx.cfg = &c;
        if (ppb_mc_cache_path(&ctx, 0, path, sizeof path, &err))
            fail_msg("%s", err.msg);
        int hit = ppb_mc_cache_get(&ctx, 0, &t);
        if (hit)
            ppb_mc_tallies_free(&t);
        int same = strcmp(path, path0) == 0;
        int want = in.mc == PPB_NOT_MC_KEY;
        if (hit != want || same != want) {
            char line[2048];
            key_line(&c, k, line, sizeof line);
            print_message("%s.%s changed (%.*s): %s, %s path; the table says %s\n", in.section,
                          in.key, (int)strcspn(line, "\n"), line, hit ? "hit" : "miss",
                          same ? "same" : "another",
                          want ? "it does not change the Monte Carlo" : "it changes it");
            bad++;
        }
    }
    ctx.cfg = &base;
    ppb_ctx_close(&ctx);
    assert_int_equal(bad, 0);
}

/* The tallies' own scene fingerprint (mc_tally.h: what a shard merge checks) changes with every
 * key the table marks PPB_MC_KEY outside [mc] (the photon range, seed and batches are checked
 * apart): a scene key added to the table and flagged is caught here if the fingerprint misses
 * it. */
static void test_scene_fingerprint_keys(void **state)
{
    (void)state;
    ppb_config base;
    small_config(&base);
    uint64_t f0 = ppb_mc_scene_fingerprint(&base.scene);
    int bad = 0;
    for (int k = 0; k < ppb_config_nkeys(); k++) {
        ppb_key_info in;
        ppb_config_key_info(k, &in);
        if (in.mc != PPB_MC_KEY || strcmp(in.section, "mc") == 0)
            continue;
        ppb_config c = base;
        change_key(&c, k);
        if (ppb_mc_scene_fingerprint(&c.scene) == f0) {
            print_message("%s.%s changed: the tallies' scene fingerprint did not\n", in.section,
                          in.key);
            bad++;
        }
    }
    assert_int_equal(bad, 0);
}

/* With a target noise the photons per launch are in the key: mc.chunk and, when it is 0,
 * $PPBENCH_MC_LANES (the device's size: compute units x 1024 x lanes x 64 on a CPU). Without
 * one they are not: the tallies of a whole budget do not depend on them (test_mc.c). */
static void test_noise_chunk_key(void **state)
{
    (void)state;
    ppb_err err;
    ppb_config cfg;
    small_config(&cfg);
    ppb_run_ctx ctx = {.cfg = &cfg, .quiet = 1, .ref_cache = "/nonexistent"};
    char p[4][1300];
    long long chunk;
    for (int noise = 0; noise < 2; noise++) {
        cfg.mc.target_noise = noise ? 0.05 : 0;
        cfg.mc.chunk = 0;
        setenv("PPBENCH_MC_LANES", "8", 1);
        if (ppb_mc_chunk(&ctx, &chunk, &err) ||
            ppb_mc_cache_path(&ctx, chunk, p[0], sizeof p[0], &err))
            fail_msg("%s", err.msg);
        setenv("PPBENCH_MC_LANES", "16", 1);
        if (ppb_mc_chunk(&ctx, &chunk, &err) ||
            ppb_mc_cache_path(&ctx, chunk, p[1], sizeof p[1], &err))
            fail_msg("%s", err.msg);
        cfg.mc.chunk = 3000;
        if (ppb_mc_chunk(&ctx, &chunk, &err) ||
            ppb_mc_cache_path(&ctx, chunk, p[2], sizeof p[2], &err))
            fail_msg("%s", err.msg);
        cfg.mc.chunk = 7000;
        if (ppb_mc_chunk(&ctx, &chunk, &err) ||
            ppb_mc_cache_path(&ctx, chunk, p[3], sizeof p[3], &err))
            fail_msg("%s", err.msg);
        unsetenv("PPBENCH_MC_LANES");
        for (int i = 1; i < 4; i++)
            if ((strcmp(p[0], p[i]) == 0) != !noise)
                fail_msg("target_noise %g, variant %d: %s vs %s", cfg.mc.target_noise, i, p[0],
                         p[i]);
    }
    ppb_ctx_close(&ctx);
}

/* The photons a run traced (provenance.txt's mc.photons_traced), or -1 when it took them from
 * the cache (it writes no such line then, and says so on stderr: the run is not --quiet, which
 * says nothing on success). */
static long long run_traced(const char *cache, const char *out, long long chunk)
{
    char args[4096];
    snprintf(args, sizeof args, "run --ref-cache %s --set mc.chunk=%lld --out %s %s", cache, chunk,
             out,
             cli_config("cache_noise", "[experiment]\nmethods = mc\n[tube]\nsegments_top = 8\n"
                                       "segments_side = 3\n[bins]\ntheta = 2\nphi = 2\n[mc]\n"
                                       "photons = 400000\ntarget_noise = 0.05\n"));
    int rc = cli_run_env("", args, cli_out, sizeof cli_out);
    if (rc != 0)
        fail_msg("ppbench %s: exit %d:\n%s", args, rc, cli_out);
    char prov[1300];
    snprintf(prov, sizeof prov, "%s/provenance.txt", out);
    const char *line = strstr(tu_read_text(prov), "mc.photons_traced = ");
    if (!line) {
        if (!strstr(cli_out, "from the reference cache"))
            fail_msg("ppbench %s: neither traced nor cached:\n%s", args, cli_out);
        return -1;
    }
    return atoll(line + strlen("mc.photons_traced = "));
}

/* End to end: a target-noise run stops at a multiple of its chunk, so chunks of 3000 and 7000
 * trace different counts; the second is therefore traced, not served the first's tallies; the
 * first's settings again are served from the cache. */
static void test_noise_chunk_run(void **state)
{
    (void)state;
    char dir[1100], cache[1200], out[1200];
    snprintf(dir, sizeof dir, "%s", tu_scratch("cache_noise_run"));
    snprintf(cache, sizeof cache, "%s/cache", dir);
    snprintf(out, sizeof out, "%s/a", dir);
    long long a = run_traced(cache, out, 3000);
    snprintf(out, sizeof out, "%s/b", dir);
    long long b = run_traced(cache, out, 7000);
    print_message("target noise 0.05: %lld photons at chunk 3000, %lld at chunk 7000\n", a, b);
    assert_true(a > 0 && a < 400000 && a % 3000 == 0); /* stopped early, after whole chunks */
    assert_true(b > 0);                                /* traced: not the chunk-3000 reference */
    assert_true(a != b);
    snprintf(out, sizeof out, "%s/c", dir);
    assert_int_equal(run_traced(cache, out, 3000), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_key_decided),      cmocka_unit_test(test_keys_hit_miss),
        cmocka_unit_test(test_scene_fingerprint_keys), cmocka_unit_test(test_noise_chunk_key),
        cmocka_unit_test(test_noise_chunk_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
