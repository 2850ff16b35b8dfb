/* test_shards.c: the sweep and Monte Carlo shard defects, each through the built binary
 * ($PPBENCH) unless it is a library function's, every one failing on the code before its fix:
 * - sweep --jobs 2: killed with -9, its workers die too (they ran on as orphans); interrupted
 *   (SIGINT to its process group as a Ctrl-C sends it, or to the parent alone), it exits 130
 *   saying how many points were done (it exited 1, "1 of 2 jobs failed");
 * - a sweep re-run into its directory with a value or an axis added gives the sweep.csv of a
 *   fresh run of the grown grid (expected: that run's bytes; the point column was wrong and the
 *   rows ragged);
 * - merge refuses shards of another grid (value order, settings, keys), exit 2 naming the shard;
 * - mc-merge refuses (exit 2) duplicated, overlapping and missing photon ranges naming the files, a
 *   tally file with one flipped bit, and names the shard of another scene in an exact message;
 *   an interrupted mc-shard exits 130 and leaves no file;
 * - ppb_mc_tallies_totals gives the true statistics when memory is exhausted (it gave zeros).
 * Grids and photon budgets are tiny; the slow configs exist only to be interrupted. */
#include "cliutil.h"

#include <math.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "methods/mc/mc_tally.h"

/* Soft checks: each failure is printed and counted, and the test fails at its end, so one run
 * shows every check that fails (on the code before the fixes: all of them). */
static int failures;

static void same_bytes(const char *a, const char *b)
{
    if (tu_sh("cmp -s '%s' '%s'", a, b) != 0) {
        tu_sh("diff '%s' '%s' | head -8 >&2", a, b);
        print_error("FAIL: %s and %s differ\n", a, b);
        failures++;
    }
}

static void expect(const char *args, int code, const char *needle)
{
    int rc = cli_run_env("", args, cli_out, sizeof cli_out);
    if (rc != code || !strstr(cli_out, needle)) {
        print_error("FAIL: ppbench %s: exit %d (want %d), output lacks '%s':\n%s\n", args, rc, code,
                    needle, cli_out);
        failures++;
    }
}

static void expect_sh(int ok, const char *what)
{
    if (!ok) {
        print_error("FAIL: %s\n", what);
        failures++;
    }
}

static void end_checks(void)
{
    int n = failures;
    failures = 0;
    if (n)
        fail_msg("%d check(s) failed (above)", n);
}

/* Two points whose Monte Carlo never ends in a test's time: there only to be interrupted. */
static const char *slow_sweep = "[experiment]\nmethods = mc\n[tube]\nsegments_top = 4\n"
                                "segments_side = 2\n[bins]\ntheta = 2\nphi = 2\n"
                                "[medium]\ng = 0, 0.5\n[mc]\nphotons = 2000000000\nbatches = 4\n";

/* Starts `sweep --jobs 2` of the slow config (under `wrap`: "" or "setsid", which makes it a
 * process group of its own, so a signal to the group reaches nobody else), waits for its two
 * workers and a second more, then runs `then` (shell text seeing $pid and $kids); its exit code.
 * The workers still alive at the end are killed, whatever happened, so a failing run leaves no
 * orphan behind. */
static int jobs_then(const char *d, const char *cfg, const char *name, const char *wrap,
                     const char *then)
{
    return tu_sh("%s %s sweep --quiet --jobs 2 --out %s/%s %s > %s/%s.log 2>&1 & pid=$!; i=0; "
                 "while [ $(ps -o pid= --ppid $pid | wc -l) -lt 2 ]; do i=$((i + 1)); "
                 "[ $i -gt 600 ] && { kill -9 $pid; exit 90; }; sleep 0.05; done; "
                 "kids=$(ps -o pid= --ppid $pid); sleep 1; %s; rc=$?; kill -9 $kids 2>/dev/null; "
                 "exit $rc",
                 wrap, tu_bin(), d, name, cfg, d, name, then);
}

/* Shell text: exit 0 once no pid of $kids is alive (a zombie is dead), 1 after 20 s. */
#define KIDS_GONE                                                                                  \
    "i=0; while :; do alive=0; for k in $kids; do ps -o stat= -p $k | grep -qv Z && alive=1; "     \
    "done; [ $alive = 0 ] && exit 0; i=$((i + 1)); [ $i -gt 400 ] && exit 1; sleep 0.05; done"

/* Shell text: waits for $pid (a zombie has ended), its exit code; after 30 s kills it (137). */
#define WAIT_PID                                                                                   \
    "i=0; while ps -o stat= -p $pid | grep -qv Z && [ $i -lt 600 ]; do i=$((i + 1)); "             \
    "sleep 0.05; done; "                                                                           \
    "kill -9 $pid 2>/dev/null; wait $pid"

static void test_jobs_die_with_sweep(void **state)
{
    (void)state;
    const char *d = tu_scratch("shards-orphans");
    char cfg[1200];
    snprintf(cfg, sizeof cfg, "%s/slow.ini", d);
    tu_write_file(cfg, slow_sweep);
    /* kill -9 of the sweep: its workers must be gone within 20 s (before: they ran on). */
    int rc = jobs_then(d, cfg, "k9", "", "kill -9 $pid; wait $pid; (" KIDS_GONE ")");
    if (rc != 0)
        fail_msg("after kill -9 of sweep --jobs 2 its workers still ran 20 s later (rc %d)", rc);
}

static void test_jobs_interrupted_exit_130(void **state)
{
    (void)state;
    const char *d = tu_scratch("shards-sigint");
    char cfg[1200];
    snprintf(cfg, sizeof cfg, "%s/slow.ini", d);
    tu_write_file(cfg, slow_sweep);
    /* A Ctrl-C: SIGINT to the whole process group. setsid makes the sweep a group leader. */
    const char *kinds[2] = {"group", "parent"};
    const char *sig[2] = {"kill -INT -$pid", "kill -INT $pid"};
    for (int k = 0; k < 2; k++) {
        char then[512], log[1300];
        snprintf(then, sizeof then, "%s; " WAIT_PID "; code=$?; (" KIDS_GONE ") && exit $code",
                 sig[k]);
        char out[64];
        snprintf(out, sizeof out, "int_%s", kinds[k]);
        int rc = jobs_then(d, cfg, out, "setsid", then);
        snprintf(log, sizeof log, "%s/%s.log", d, out);
        const char *text = tu_read_text(log);
        if (rc != 130 || !strstr(text, "interrupted: 0 of 2 points done"))
            fail_msg("SIGINT to the %s of sweep --jobs 2: exit %d (want 130 and 'interrupted: 0 "
                     "of 2 points done'):\n%s",
                     kinds[k], rc, text);
        if (tu_sh("test ! -e %s/%s/sweep.csv", d, out) != 0)
            fail_msg("an interrupted sweep wrote sweep.csv");
    }
}

/* A deterministic method only (mp), so each grid is cheap and its bytes reproducible. */
static const char *grid_cfg(const char *g, const char *extra)
{
    static char text[1024];
    snprintf(text, sizeof text,
             "[experiment]\nname = grow\nmethods = mp\n[tube]\nsegments_top = 8\n"
             "segments_side = 4\n[bins]\ntheta = 2\nphi = 2\n[medium]\ng = %s\n%s[mp]\npairs = 2\n",
             g, extra);
    return text;
}

static void test_grown_grid_reuses_points(void **state)
{
    (void)state;
    const char *d = tu_scratch("shards-grow");
    const char *b = tu_bin();
    struct {
        const char *name, *g, *extra;
    } steps[] = {
        {"a", "0, 0.5", ""},
        {"b", "0, 0.25, 0.5", ""},                     /* a value added between the others */
        {"c", "0, 0.25, 0.5", "albedo = 0.95, 0.5\n"}, /* an axis (0.95: the default) */
    };
    for (int s = 0; s < 3; s++) {
        char cfg[1200], grown[1300], fresh[1300];
        snprintf(cfg, sizeof cfg, "%s/%s.ini", d, steps[s].name);
        tu_write_file(cfg, grid_cfg(steps[s].g, steps[s].extra));
        /* The same directory each time (the grown grid reuses the finished points), and a fresh
         * one: the expected bytes. */
        assert_int_equal(tu_sh("%s sweep --quiet --out %s/same %s", b, d, cfg), 0);
        assert_int_equal(tu_sh("%s sweep --quiet --out %s/fresh_%s %s", b, d, steps[s].name, cfg),
                         0);
        snprintf(grown, sizeof grown, "%s/same/sweep.csv", d);
        snprintf(fresh, sizeof fresh, "%s/fresh_%s/sweep.csv", d, steps[s].name);
        same_bytes(grown, fresh);
    }
    /* The last grid: 3 x 2 points, one mp row each, every row as long as the header. */
    expect_sh(tu_sh("test $(wc -l < %s/same/sweep.csv) -eq 7", d) == 0, "7 lines in sweep.csv");
    expect_sh(tu_sh("test $(awk -F, '{print NF}' %s/same/sweep.csv | sort -u | wc -l) -eq 1", d) ==
                  0,
              "every row of sweep.csv has the header's fields");
    end_checks();
}

static void test_merge_refuses_other_grids(void **state)
{
    (void)state;
    const char *d = tu_scratch("shards-mergegrid");
    const char *b = tu_bin();
    struct {
        const char *name, *g, *extra;
    } cfgs[] = {
        {"base", "0, 0.5", ""},
        {"order", "0.5, 0", ""},               /* the same values in another order */
        {"other", "0, 0.5", "albedo = 0.9\n"}, /* the same grid, another setting */
        {"keys", "0, 0.5", "albedo = 0.5, 0.9\n"},
    };
    for (int c = 0; c < 4; c++) {
        char cfg[1200];
        snprintf(cfg, sizeof cfg, "%s/%s.ini", d, cfgs[c].name);
        tu_write_file(cfg, grid_cfg(cfgs[c].g, cfgs[c].extra));
        for (int s = 1; s <= 2; s++)
            assert_int_equal(tu_sh("%s sweep --quiet --shard %d/2 --out %s/%s%d %s", b, s, d,
                                   cfgs[c].name, s, cfg),
                             0);
    }
    /* Shards of one grid merge (the control). */
    char args[4096];
    snprintf(args, sizeof args, "merge --out %s/ok %s/base1 %s/base2", d, d, d);
    expect(args, 0, "");
    const char *why[] = {"", "other values or another value order",
                         "the same points hold other settings", "other swept keys"};
    for (int c = 1; c < 4; c++) {
        char needle[4096];
        snprintf(args, sizeof args, "merge --out %s/bad%d %s/base1 %s/%s2", d, c, d, d,
                 cfgs[c].name);
        snprintf(needle, sizeof needle, "%s/%s2: its grid differs from %s/base1's (%s", d,
                 cfgs[c].name, d, why[c]);
        expect(args, 2, needle);
        expect_sh(tu_sh("test ! -e %s/bad%d/sweep.csv", d, c) == 0,
                  "no sweep.csv from a refused merge");
    }
    end_checks();
}

/* A tiny Monte Carlo: the tests are about bookkeeping, not physics. */
static const char *mc_cfg(const char *albedo)
{
    static char text[512];
    snprintf(text, sizeof text,
             "[experiment]\nmethods = mc\n[tube]\nsegments_top = 4\nsegments_side = 2\n"
             "[bins]\ntheta = 2\nphi = 2\n[medium]\nalbedo = %s\n[mc]\nphotons = 3996\n"
             "batches = 4\nseed = 5\n",
             albedo);
    return text;
}

static void shard(const char *d, const char *cfg, const char *part, const char *dir)
{
    assert_int_equal(
        tu_sh("%s mc-shard --quiet --shard %s --out %s/%s %s", tu_bin(), part, d, dir, cfg), 0);
}

static void flip_bit(const char *path, long at)
{
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    assert_int_equal(fseek(f, at, SEEK_SET), 0);
    int c = fgetc(f);
    assert_true(c != EOF);
    assert_int_equal(fseek(f, at, SEEK_SET), 0);
    fputc(c ^ 0x10, f);
    fclose(f);
}

static void test_mc_merge_checks_shards(void **state)
{
    (void)state;
    const char *d = tu_scratch("shards-mc");
    char cfg[1200], other[1200], args[8192], needle[8192];
    snprintf(cfg, sizeof cfg, "%s/one.ini", d);
    snprintf(other, sizeof other, "%s/other.ini", d);
    tu_write_file(cfg, mc_cfg("0.95"));
    tu_write_file(other, mc_cfg("0.5"));
    const char *parts[][2] = {{"1/3", "p1"}, {"2/3", "p2"}, {"3/3", "p3"}, {"1/2", "h1"},
                              {"2/4", "q2"}, {"4/4", "q4"}, {"1/4", "q1"}};
    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++)
        shard(d, cfg, parts[i][0], parts[i][1]);
    shard(d, other, "3/3", "x3");
    /* The control: the three thirds merge. */
    snprintf(args, sizeof args, "mc-merge --out %s/ok %s %s/p1 %s/p2 %s/p3", d, cfg, d, d, d);
    expect(args, 0, "");
    /* A shard given twice: the photon count is right (2/3 + 1/3), the photons are not. */
    snprintf(args, sizeof args, "mc-merge --out %s/dup %s %s/p1 %s/p1 %s/p3", d, cfg, d, d, d);
    snprintf(needle, sizeof needle,
             "%s/p1/mc_tallies.bin and %s/p1/mc_tallies.bin hold the same photons [0, 1332)", d, d);
    expect(args, 2, needle); /* bad input: docs/reference.md, Exit codes */
    /* Overlapping shards of different N: 1/2 + 2/4 + 4/4 also counts 3996 photons. */
    snprintf(args, sizeof args, "mc-merge --out %s/ovl %s %s/h1 %s/q2 %s/q4", d, cfg, d, d, d);
    snprintf(needle, sizeof needle,
             "%s/h1/mc_tallies.bin (photons [0, 1998)) and %s/q2/mc_tallies.bin (photons [999, "
             "1998)) overlap",
             d, d);
    expect(args, 2, needle); /* bad input: docs/reference.md, Exit codes */
    /* A gap: 1/4 + 2/4 + 4/4 misses [1998, 2997). */
    snprintf(args, sizeof args, "mc-merge --out %s/gap %s %s/q1 %s/q2 %s/q4", d, cfg, d, d, d);
    snprintf(needle, sizeof needle,
             "photons [1998, 2997) are in none of the shards (the next is %s/q4/mc_tallies.bin)",
             d);
    expect(args, 2, needle); /* bad input: docs/reference.md, Exit codes */
    /* A shard of another scene: the message names it once, unmangled. */
    snprintf(args, sizeof args, "mc-merge --out %s/scene %s %s/p1 %s/p2 %s/x3", d, cfg, d, d, d);
    snprintf(needle, sizeof needle,
             "%s: %s/x3/mc_tallies.bin: mc merge: tallies come from different scenes or bin "
             "settings\n",
             cfg, d);
    expect(args, 2, needle); /* bad input: docs/reference.md, Exit codes */
    /* One flipped bit in the middle of p2's file (a tally): refused, the file named. */
    char p2[1300];
    snprintf(p2, sizeof p2, "%s/p2/mc_tallies.bin", d);
    struct stat st;
    assert_int_equal(stat(p2, &st), 0);
    flip_bit(p2, (long)st.st_size / 2);
    snprintf(args, sizeof args, "mc-merge --out %s/flip %s %s/p1 %s/p2 %s/p3", d, cfg, d, d, d);
    snprintf(needle, sizeof needle, "%s: corrupt or truncated tally file", p2);
    expect(args, 2, needle); /* bad input: docs/reference.md, Exit codes */
    for (const char *o = "dup\0ovl\0gap\0scene\0flip\0"; *o; o += strlen(o) + 1)
        expect_sh(tu_sh("test ! -e %s/%s/radiance.csv", d, o) == 0,
                  "no radiance.csv from a refused merge");
    end_checks();
}

static void test_mc_shard_interrupted_130(void **state)
{
    (void)state;
    const char *d = tu_scratch("shards-mcint");
    char cfg[1200];
    snprintf(cfg, sizeof cfg, "%s/slow.ini", d);
    tu_write_file(cfg, "[experiment]\nmethods = mc\n[tube]\nsegments_top = 4\nsegments_side = 2\n"
                       "[bins]\ntheta = 2\nphi = 2\n[mc]\nphotons = 2000000000\nbatches = 4\n");
    /* Interrupted once it has started tracing (its progress line says so). */
    int rc = tu_sh("%s mc-shard --shard 1/2 --out %s/part %s > %s/log 2>&1 & pid=$!; i=0; "
                   "while ! grep -qs photons %s/log; do i=$((i + 1)); "
                   "[ $i -gt 600 ] && { kill -9 $pid; exit 90; }; sleep 0.05; done; "
                   "kill -INT $pid; " WAIT_PID,
                   tu_bin(), d, cfg, d, d);
    char log[1300];
    snprintf(log, sizeof log, "%s/log", d);
    const char *text = tu_read_text(log);
    if (rc != 130 || !strstr(text, "shard 1/2 interrupted after"))
        fail_msg("interrupted mc-shard: exit %d (want 130, 'shard 1/2 interrupted after'):\n%s", rc,
                 text);
    /* Nothing half-written: no tally file, no temporary. */
    assert_int_equal(tu_sh("test -z \"$(ls -A %s/part 2>/dev/null)\"", d), 0);
}

/* ppb_mc_tallies_totals under memory exhaustion: a forked child caps its address space, takes
 * every byte left, and computes the totals; they must be those computed with memory to spare,
 * which are checked against the hand sum of the tallies (R = sum of the S1 cells over the
 * photons, in fixed point). Before, a failed scratch calloc returned all zeros. */
static void test_totals_without_memory(void **state)
{
    (void)state;
#if defined(__SANITIZE_ADDRESS__)
    skip(); /* ASan reserves terabytes of shadow: an address-space cap cannot apply there */
#else
    ppb_scene sc = tu_tube();
    sc.segments_top = 2, sc.segments_side = 1, sc.ntheta = 1, sc.nphi = 1;
    ppb_layout lo = ppb_scene_layout(&sc);
    ppb_mc_tallies t;
    ppb_err err;
    /* 4096 batches: the old scratch arrays (128 KB) come from mmap, never from a free list. */
    if (ppb_mc_tallies_init(&t, &sc, 1, 4096, &err))
        fail_msg("%s", err.msg);
    uint64_t s1 = 0, photons = 0;
    for (int b = 0; b < t.batches; b++) {
        t.photons[b] = 10 + (uint64_t)(b % 3);
        photons += t.photons[b];
        uint64_t *c = t.cells + (size_t)b * PPB_MC_NTALLY * t.ncells;
        for (int seg = 0; seg < lo.nseg[PPB_S1]; seg++) {
            uint64_t v = (uint64_t)(b % 7 + 1 + seg) * (uint64_t)PPB_MC_FIXED_SCALE;
            c[ppb_cell(&lo, PPB_S1, seg, 0)] = v;
            s1 += v;
        }
    }
    ppb_mc_totals_stats ref;
    ppb_mc_tallies_totals(&t, &sc, 0, &ref);
    assert_close(ref.mean.R, (double)s1 / PPB_MC_FIXED_SCALE / (double)photons, 1e-12);
    int fd[2];
    assert_int_equal(pipe(fd), 0);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        long pages = 0;
        FILE *f = fopen("/proc/self/statm", "r");
        if (!f || fscanf(f, "%ld", &pages) != 1)
            _exit(3);
        fclose(f);
        rlim_t cap = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + (1 << 20);
        struct rlimit rl = {cap, cap};
        if (setrlimit(RLIMIT_AS, &rl) != 0)
            _exit(4);
        /* Everything the allocator still has: big blocks, then ever smaller ones. */
        for (size_t sz = 1 << 16; sz >= 16; sz /= 4)
            while (malloc(sz))
                ;
        if (malloc(4096))
            _exit(5); /* memory is not exhausted: the test would prove nothing */
        ppb_mc_totals_stats st;
        ppb_mc_tallies_totals(&t, &sc, 0, &st);
        _exit(write(fd[1], &st, sizeof st) == (ssize_t)sizeof st ? 0 : 6);
    }
    close(fd[1]);
    ppb_mc_totals_stats st;
    memset(&st, 0, sizeof st);
    ssize_t n = read(fd[0], &st, sizeof st);
    close(fd[0]);
    int status;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || n != (ssize_t)sizeof st)
        fail_msg("the child failed (status %d, %zd bytes)", status, n);
    assert_close(st.mean.R, ref.mean.R, 0.0);
    assert_close(st.se.R, ref.se.R, 0.0);
    assert_close(st.mean.absorbed, ref.mean.absorbed, 0.0);
    ppb_mc_tallies_free(&t);
#endif
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_totals_without_memory),
        cmocka_unit_test(test_grown_grid_reuses_points),
        cmocka_unit_test(test_merge_refuses_other_grids),
        cmocka_unit_test(test_mc_merge_checks_shards),
        cmocka_unit_test(test_mc_shard_interrupted_130),
        cmocka_unit_test(test_jobs_die_with_sweep),
        cmocka_unit_test(test_jobs_interrupted_exit_130),
    };
    if (getenv("SHARDS_TEST")) /* one test by name (or a cmocka pattern) */
        cmocka_set_test_filter(getenv("SHARDS_TEST"));
    return cmocka_run_group_tests_name("shards", tests, NULL, NULL);
}
