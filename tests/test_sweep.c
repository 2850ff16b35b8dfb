/* Sweeps and Monte Carlo shards, through the built binary ($PPBENCH):
 * - a 2 x 3 x 2 sweep run whole, as 3 shards under GNU parallel then merged, with --jobs 2, and
 *   killed midway then resumed, gives byte-identical sweep.csv files (expected: the whole
 *   run's bytes);
 * - one Monte Carlo run split into 4 shards and merged gives radiance.csv and totals.csv
 *   byte-identical to the single run (photon i's random numbers depend on i alone);
 * - bad sweep configs fail before any work starts;
 * - the reference cache serves sweep points: a 2-point sweep run again into another directory
 *   traces no photon (counted from what each point's mc says, not timed), by --ref-cache and by
 *   the default ($PPBENCH_CACHE), with the same sweep.csv;
 * - --jobs 2 reports the sweep's point count, not one worker's;
 * - a 1-D sweep of mc alone succeeds without a line plot (nothing is measured against mc), and
 *   with mp beside it draws sweep_rms.png;
 * - a sweep over the refractive index writes each point's `specular` column: the
 *   Fresnel reflectance of the beam at normal incidence, ((n - 1) / (n + 1))^2 (0 and 1/36 for
 *   n = 1 and 1.4), for every method. */
#include "cliutil.h"

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* Cheap methods and a small photon budget: the test is about bookkeeping, not physics. */
static const char *sweep_cfg =
    "[experiment]\nname = sw\nmethods = mc, mp\n[tube]\nsegments_top = 16\nsegments_side = 6\n"
    "[bins]\ntheta = 4\nphi = 4\n[medium]\ng = 0, 0.5\nalbedo = 0.5:0.9:0.2\n"
    "[light]\ntheta_deg = 0, 30\n[mc]\nphotons = 20000\nbatches = 4\n[mp]\npairs = 2\n";

static void same_bytes(const char *a, const char *b)
{
    if (tu_sh("cmp -s '%s' '%s'", a, b) != 0)
        fail_msg("%s and %s differ", a, b);
}

static void test_sweep_whole_shards_resume(void **state)
{
    (void)state;
    const char *d = tu_scratch("sweep");
    char cfg[1200];
    snprintf(cfg, sizeof cfg, "%s/sw.ini", d);
    tu_write_file(cfg, sweep_cfg);
    const char *b = tu_bin();
    assert_int_equal(tu_sh("%s sweep --quiet --out %s/whole %s", b, d, cfg), 0);
    /* Three shards under GNU parallel, each in its own directory, then merged. */
    assert_int_equal(tu_sh("parallel --will-cite -j 3 '%s sweep --quiet --shard {}/3 --out %s/s{} "
                           "%s' ::: 1 2 3",
                           b, d, cfg),
                     0);
    assert_int_equal(tu_sh("%s merge --out %s/merged %s/s1 %s/s2 %s/s3", b, d, d, d, d), 0);
    char w[1300], m[1300];
    snprintf(w, sizeof w, "%s/whole/sweep.csv", d);
    snprintf(m, sizeof m, "%s/merged/sweep.csv", d);
    same_bytes(w, m);
    /* Two processes on this machine (--jobs 2). */
    assert_int_equal(tu_sh("%s sweep --quiet --jobs 2 --out %s/jobs %s", b, d, cfg), 0);
    snprintf(m, sizeof m, "%s/jobs/sweep.csv", d);
    same_bytes(w, m);
    /* Killed once its first point is written, then resumed. */
    /* The wait gives up after 60 s, so a sweep that fails to start fails the test, not hangs it. */
    assert_int_equal(tu_sh("%s sweep --quiet --out %s/resumed %s & pid=$!; i=0; "
                           "while ! ls %s/resumed/points/*.csv >/dev/null 2>&1; do "
                           "i=$((i + 1)); [ $i -gt 1200 ] && exit 1; sleep 0.05; done; "
                           "kill -9 $pid; wait $pid; true",
                           b, d, cfg, d),
                     0);
    assert_int_equal(tu_sh("test ! -e %s/resumed/sweep.csv", d), 0);
    assert_int_equal(tu_sh("%s sweep --quiet --out %s/resumed %s", b, d, cfg), 0);
    snprintf(m, sizeof m, "%s/resumed/sweep.csv", d);
    same_bytes(w, m);
    /* 12 grid points x 3 results (mc, its companion mc1, mp) + the header. */
    assert_int_equal(tu_sh("test $(wc -l < %s) -eq 37", w), 0);
}

static void test_mc_shards_merge(void **state)
{
    (void)state;
    const char *d = tu_scratch("mcshard");
    char cfg[1200];
    snprintf(cfg, sizeof cfg, "%s/one.ini", d);
    tu_write_file(cfg, "[experiment]\nmethods = mc\n[tube]\nsegments_top = 16\nsegments_side = 6\n"
                       "[mc]\nphotons = 40001\nbatches = 8\nseed = 3\n");
    const char *b = tu_bin();
    assert_int_equal(tu_sh("%s run --quiet --out %s/single %s", b, d, cfg), 0);
    for (int i = 1; i <= 4; i++)
        assert_int_equal(tu_sh("%s mc-shard --quiet --shard %d/4 --out %s/p%d %s", b, i, d, i, cfg),
                         0);
    assert_int_equal(
        tu_sh("%s mc-merge --out %s/merged %s %s/p1 %s/p2 %s/p3 %s/p4", b, d, cfg, d, d, d, d), 0);
    const char *files[] = {"radiance.csv", "totals.csv"};
    for (int i = 0; i < 2; i++) {
        char a[1300], c[1300];
        snprintf(a, sizeof a, "%s/single/%s", d, files[i]);
        snprintf(c, sizeof c, "%s/merged/%s", d, files[i]);
        same_bytes(a, c);
    }
    /* A missing shard is refused: 3 of 4 parts do not make the budget. */
    assert_int_not_equal(
        tu_sh("%s mc-merge --out %s/bad %s %s/p1 %s/p2 %s/p3 2>/dev/null", b, d, cfg, d, d, d), 0);
}

static void test_bad_sweeps(void **state)
{
    (void)state;
    const char *d = tu_scratch("badsweep");
    char cfg[1200];
    const char *b = tu_bin();
    struct {
        const char *text, *needle;
    } cases[] = {
        {"[medium]\ng = 0,,0.5\n", "empty value in list"},
        {"[medium]\ng = 0:x:0.1\n", "is not a number"},
        {"[medium]\ng = 0\n", "nothing to sweep"},
        {"[medium]\ng = -0.9:0.9:0.01\nalbedo = 0:1:0.01\n", "over the limit"},
        /* The registry's check of the method ids (methods/registry.c) runs before any work. */
        {"[experiment]\nmethods = mc, xx\n[medium]\ng = 0, 0.5\n",
         ":2: .experiment. methods: unknown method .xx. (see ppbench --help)"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        snprintf(cfg, sizeof cfg, "%s/bad%zu.ini", d, i);
        tu_write_file(cfg, cases[i].text);
        if (tu_sh("%s sweep --quiet --out %s/o%zu %s 2>%s/err%zu.txt", b, d, i, cfg, d, i) != 2 ||
            tu_sh("grep -q -- '%s' %s/err%zu.txt", cases[i].needle, d, i) != 0)
            fail_msg("sweep config %zu: expected exit 2 and '%s'", i, cases[i].needle);
        /* Refused before any work: no output directory was made. */
        assert_int_equal(tu_sh("test ! -e %s/o%zu", d, i), 0);
    }
}

/* Two points, the Monte Carlo alone: the cache's bookkeeping. */
static const char *two_points =
    "[experiment]\nname = sw2\nmethods = mc, mp\n[mp]\npairs = 2\n[tube]\nsegments_top = "
    "8\nsegments_side = 3\n"
    "[bins]\ntheta = 2\nphi = 2\n[medium]\ng = 0, 0.5\n[mc]\nphotons = 20000\nbatches = 4\n";

/* How many times out holds needle. */
static int count_of(const char *out, const char *needle)
{
    int n = 0;
    for (const char *p = strstr(out, needle); p; p = strstr(p + 1, needle))
        n++;
    return n;
}

static void test_sweep_ref_cache(void **state)
{
    (void)state;
    const char *d = tu_scratch("sweepcache");
    char cfg[1200], args[4096], env[1400], w[1300], m[1300];
    snprintf(cfg, sizeof cfg, "%s/sw2.ini", d);
    tu_write_file(cfg, two_points);
    /* First run: both points trace (no point says it read the cache) and store. */
    snprintf(args, sizeof args, "sweep --ref-cache %s/cache --out %s/first %s", d, d, cfg);
    cli_expect(args, 0, "wrote");
    assert_int_equal(count_of(cli_out, "from the reference cache"), 0);
    assert_int_equal(tu_sh("test $(ls %s/cache/mc-*.bin | wc -l) -eq 2", d), 0);
    /* Again into a fresh directory (its points not done): every point reads the cache. */
    snprintf(args, sizeof args, "sweep --ref-cache %s/cache --out %s/second %s", d, d, cfg);
    cli_expect(args, 0, "wrote");
    assert_int_equal(count_of(cli_out, "20000 photons from the reference cache"), 2);
    assert_int_equal(count_of(cli_out, ", 0 traced"), 2);
    /* The default cache: $PPBENCH_CACHE, no option. */
    snprintf(env, sizeof env, "PPBENCH_CACHE=%s/cache", d);
    snprintf(args, sizeof args, "sweep --out %s/third %s", d, cfg);
    cli_expect_env(env, args, 0, "wrote");
    assert_int_equal(count_of(cli_out, ", 0 traced"), 2);
    /* --no-ref-cache: traced again. */
    snprintf(args, sizeof args, "sweep --no-ref-cache --out %s/fourth %s", d, cfg);
    cli_expect_env(env, args, 0, "wrote");
    assert_int_equal(count_of(cli_out, "from the reference cache"), 0);
    const char *dirs[] = {"second", "third", "fourth"};
    snprintf(w, sizeof w, "%s/first/sweep.csv", d);
    for (int i = 0; i < 3; i++) {
        snprintf(m, sizeof m, "%s/%s/sweep.csv", d, dirs[i]);
        same_bytes(w, m);
    }
}

/* --jobs 2 over 2 points: the completion line counts both (it was the first worker's own
 * line, "1 point"); the sweep's own count is the expected value. */
static void test_jobs_count(void **state)
{
    (void)state;
    const char *d = tu_scratch("sweepjobs");
    char cfg[1200], args[4096];
    snprintf(cfg, sizeof cfg, "%s/sw2.ini", d);
    tu_write_file(cfg, two_points);
    snprintf(args, sizeof args, "sweep --no-ref-cache --jobs 2 --out %s/j %s", d, cfg);
    cli_expect(args, 0, "sw2: 2 points in ");
    if (strstr(cli_out, "sw2: 1 point in "))
        fail_msg("a worker's count was printed:\n%s", cli_out);
    assert_int_equal(count_of(cli_out, " points in "), 1);
}

/* A 1-D sweep whose only method is the reference: no RMS curve exists, so no sweep_rms figure
 * (gnuplot failed on the empty plot and the sweep exited 1); with mp the figure is drawn. */
static void test_reference_only_sweep(void **state)
{
    (void)state;
    const char *d = tu_scratch("sweepmc");
    char cfg[1200], args[4096];
    snprintf(cfg, sizeof cfg, "%s/sw2.ini", d);
    tu_write_file(cfg, two_points);
    snprintf(args, sizeof args, "sweep --no-ref-cache --set experiment.methods=mc --out %s/mc %s",
             d, cfg);
    cli_expect(args, 0, "wrote");
    assert_int_equal(tu_sh("test -s %s/mc/sweep.csv", d), 0);
    assert_int_not_equal(tu_sh("test -e %s/mc/sweep_rms.png", d), 0);
    snprintf(args, sizeof args, "sweep --no-ref-cache --out %s/mp %s", d, cfg);
    cli_expect(args, 0, "wrote");
    assert_int_equal(tu_sh("test -s %s/mp/sweep_rms.png -a -s %s/mp/sweep_rms.pdf", d, d), 0);
}

static void test_sweep_over_n(void **state)
{
    (void)state;
    const char *d = tu_scratch("sweepn");
    char cfg[1200], args[4096], path[1300];
    snprintf(cfg, sizeof cfg, "%s/swn.ini", d);
    tu_write_file(cfg, "[experiment]\nname = swn\nmethods = mc, ss\n[tube]\nsegments_top = 16\n"
                       "segments_side = 6\n[bins]\ntheta = 4\nphi = 4\n[medium]\nn = 1, 1.4\n"
                       "[mc]\nphotons = 20000\nbatches = 4\n");
    snprintf(args, sizeof args, "sweep --quiet --no-ref-cache --out %s/out %s", d, cfg);
    cli_expect(args, 0, "");
    snprintf(path, sizeof path, "%s/out/sweep.csv", d);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[4096];
    assert_non_null(fgets(line, sizeof line, f));
    assert_non_null(strstr(line, "point,medium.n,method,"));
    assert_non_null(strstr(line, ",ballistic,specular\n"));
    int rows = 0;
    while (fgets(line, sizeof line, f)) {
        /* point,medium.n,method,...,specular */
        double n = atof(strchr(line, ',') + 1), specular = atof(strrchr(line, ',') + 1);
        double want = (n - 1) * (n - 1) / ((n + 1) * (n + 1));
        if (fabs(specular - want) > 1e-9)
            fail_msg("specular %.10g, want %.10g, in the row %s", specular, want, line);
        rows++;
    }
    fclose(f);
    assert_int_equal(rows, 6); /* 2 points x (mc, mc1, ss) */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_sweeps),
        cmocka_unit_test(test_mc_shards_merge),
        cmocka_unit_test(test_sweep_whole_shards_resume),
        cmocka_unit_test(test_sweep_ref_cache),
        cmocka_unit_test(test_jobs_count),
        cmocka_unit_test(test_reference_only_sweep),
        cmocka_unit_test(test_sweep_over_n),
    };
    return cmocka_run_group_tests_name("sweep", tests, NULL, NULL);
}
