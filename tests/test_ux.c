/* test_ux.c: the CLI and provenance items, through the built binary ($PPBENCH) where a
 * user sees them and through the library where the property is a function's:
 * - provenance.txt records the commit, compiler, OpenCL and library versions, and prints reals
 *   in their shortest round-trip form (0.95; expected from IEEE 754: %.17g of 0.95 is
 *   0.94999999999999996, which the old provenance printed);
 * - config.ini beside it repeats the run: `ppbench run DIR/config.ini` gives byte-identical
 *   result files (the Monte Carlo is seeded (Philox), so the same settings give the same bytes);
 *   ppb_config_write_ini reads back into the same doubles, even one that needs 17 digits;
 * - progress lines when stderr is not a terminal: no \r, at most one line per
 *   PPB_PROGRESS_LOG_SECONDS; on a terminal (a pty) the line is still rewritten with \r;
 *   a count of one takes the singular ("1 point");
 * - run --quiet prints nothing when it succeeds; mc-merge and report end with that
 *   line too;
 * - the study README (report): Table 2 wide (cases x methods), the noise floor from the
 *   Monte Carlo's own standard errors, the photon budget, a footer naming only files that
 *   exist and are committed (not radiance.csv).
 * - run and score end with the summary table on stdout (rms_excess and noise_rel per summary
 *   cell, summary.csv's numbers); --quiet leaves it out;
 * - the Python package's tests (python/tests) on a run of the binary;
 * - kernel build warnings go to the kernel build log, not stderr; a failed build's log is in
 *   its error;
 * - timings.csv's seconds are the ones stderr says; an interrupt after the last method
 *   finished does not mark the complete set partial;
 * - the study README opens with the summary figure and the findings paragraph.
 * Photon budgets and grids are tiny. */
#define _XOPEN_SOURCE 700 /* posix_openpt, grantpt, unlockpt, ptsname */
#include "cliutil.h"

#include <fcntl.h>
#include <math.h>
#include <unistd.h>

#include "base/progress.h"
#include "model/config.h"
#include "runtime/ocl.h"

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        fail_msg("cannot open %s", path);
    static char buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    if (len)
        *len = n;
    return buf;
}

static const char tiny[] = "[experiment]\nmethods = mc, ss\n[tube]\nsegments_top = 16\n"
                           "segments_side = 4\n[medium]\nstep = density\n[mc]\nphotons = 20000\n"
                           "batches = 4\n[bins]\ntheta = 4\nphi = 4\n";

static void test_provenance_versions_and_short_reals(void **state)
{
    (void)state;
    const char *cfg = cli_config("uxprov", tiny);
    char dir[1300], args[3000], path[1400];
    snprintf(dir, sizeof dir, "%s/out", tu_scratch("uxprov_out"));
    snprintf(args, sizeof args, "run %s --out %s", cfg, dir);
    cli_expect(args, 0, "wrote");
    snprintf(path, sizeof path, "%s/provenance.txt", dir);
    const char *p = slurp(path, NULL);
    const char *want[] = {"\nppbench.commit = ",
                          "\ncompiler = ",
                          "\nopencl.platform_version = ",
                          "\nopencl.device_version = ",
                          "\nopencl.driver_version = ",
                          "\nlib.openblas = OpenBLAS",
                          "\nlib.lapack = ",
                          "\nlib.openexr = ",
                          "\nlib.libpng = ",
                          "\nlib.xxhash = ",
                          "\nlib.inih = ",
                          "\nmedium.albedo = 0.95\n",
                          "\nmedium.sigma_t_right = 0.5\n"};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++)
        if (!strstr(p, want[i]))
            fail_msg("provenance.txt lacks '%s':\n%s", want[i] + 1, p);
    if (strstr(p, "0.94999999999999996"))
        fail_msg("provenance.txt prints 0.95 in 17 digits:\n%s", p);
}

/* The files of a set that a repeated run must reproduce byte for byte (timings.csv and
 * provenance.txt hold times and paths, docs/reference.md: Outputs). */
static const char *const result_files[] = {"radiance.csv",    "totals.csv",    "angular.csv",
                                           "rms.csv",         "summary.csv",   "regions.csv",
                                           "summary_mc1.csv", "images/mc.exr", "images/ss.exr",
                                           "config.ini",      "mc_totals.csv"};

static void test_config_ini_repeats_run(void **state)
{
    (void)state;
    const char *cfg = cli_config("uxrep", tiny);
    char a[1300], b[1300], args[3000];
    snprintf(a, sizeof a, "%s/a", tu_scratch("uxrep_a"));
    snprintf(b, sizeof b, "%s/b", tu_scratch("uxrep_b"));
    /* A --set real that needs all 17 digits, to show config.ini keeps the exact double. */
    snprintf(args, sizeof args, "run %s --set medium.step_x=0.30000000000000004 --out %s", cfg, a);
    cli_expect(args, 0, "wrote");
    snprintf(args, sizeof args, "run %s/config.ini --out %s", a, b);
    cli_expect(args, 0, "wrote");
    for (size_t i = 0; i < sizeof result_files / sizeof result_files[0]; i++) {
        /* config.ini names its output directory: the repeat's holds --out's, the rest is equal. */
        if (!strcmp(result_files[i], "config.ini"))
            assert_int_equal(
                tu_sh("grep -v '^dir = ' '%s/config.ini' > '%s.ini' && grep -v '^dir = ' "
                      "'%s/config.ini' > '%s.ini' && cmp -s '%s.ini' '%s.ini'",
                      a, a, b, b, a, b),
                0);
        else if (tu_sh("cmp -s '%s/%s' '%s/%s'", a, result_files[i], b, result_files[i]))
            fail_msg("%s differs between a run and its repeat from config.ini", result_files[i]);
    }
    char path[1400];
    snprintf(path, sizeof path, "%s/config.ini", a);
    if (!strstr(slurp(path, NULL), "\nstep_x = 0.30000000000000004\n"))
        fail_msg("config.ini lacks step_x = 0.30000000000000004:\n%s", slurp(path, NULL));
}

/* ppb_config_write_ini -> ppb_config_load gives the same settings: the canonical lines
 * (ppb_config_write_resolved, %.17g) of both are equal, with reals that need 15, 16 and 17
 * digits (0.95, 0.1 + 0.2, 1/3). */
static void test_ini_round_trip_exact(void **state)
{
    (void)state;
    ppb_config c, d;
    ppb_err err = {{0}};
    const char *cfg = cli_config("uxini", tiny);
    assert_int_equal(ppb_config_load(&c, cfg, &err), 0);
    c.scene.step_x = 0.1 + 0.2;
    c.scene.g = 1.0 / 3.0;
    char path[1300];
    snprintf(path, sizeof path, "%s/config.ini", tu_scratch("uxini2"));
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    ppb_config_write_ini(&c, f);
    fclose(f);
    if (ppb_config_load(&d, path, &err))
        fail_msg("config.ini does not load: %s", err.msg);
    char *t1 = NULL, *t2 = NULL;
    size_t n1 = 0, n2 = 0;
    FILE *f1 = open_memstream(&t1, &n1), *f2 = open_memstream(&t2, &n2);
    ppb_config_write_resolved(&c, f1);
    ppb_config_write_resolved(&d, f2);
    fclose(f1);
    fclose(f2);
    if (n1 != n2 || memcmp(t1, t2, n1))
        fail_msg("settings differ after the INI round trip:\n%s\n---\n%s", t1, t2);
    assert_non_null(strstr(t1, "medium.step_x = 0.30000000000000004\n"));
    free(t1);
    free(t2);
    /* The readable form: the shortest that round-trips (0.95; 1/3 needs 16 digits). */
    f1 = open_memstream(&t1, &n1);
    ppb_config_write_readable(&c, f1);
    fclose(f1);
    assert_non_null(strstr(t1, "medium.albedo = 0.95\n"));
    assert_non_null(strstr(t1, "medium.g = 0.3333333333333333\n"));
    free(t1);
}

/* Progress lines of p written to fd 2 pointing at `to` for `seconds`, updated every ms; the
 * bytes come back in out. */
static size_t progress_into(int to, int from, double seconds, const char *unit, double end,
                            char *out, size_t cap)
{
    fflush(stderr);
    int saved = dup(2);
    assert_true(saved >= 0);
    assert_true(dup2(to, 2) == 2);
    ppb_progress p;
    ppb_progress_begin(&p, "ux", unit, 100, 0);
    double t0 = ppb_now();
    while (ppb_now() - t0 < seconds) {
        ppb_progress_update(&p, 50);
        usleep(1000);
    }
    ppb_progress_end(&p, end);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    size_t n = 0;
    ssize_t r;
    lseek(from, 0, SEEK_SET);
    while (n + 1 < cap && (r = read(from, out + n, cap - 1 - n)) > 0)
        n += (size_t)r;
    out[n] = '\0';
    return n;
}

static int count_lines(const char *s)
{
    int n = 0;
    for (; *s; s++)
        n += *s == '\n';
    return n;
}

static void test_progress_plain_lines_off_terminal(void **state)
{
    (void)state;
    char path[1300], out[8192];
    snprintf(path, sizeof path, "%s/stderr", tu_scratch("uxprog"));
    int fd = open(path, O_RDWR | O_CREAT | O_TRUNC, 0600);
    assert_true(fd >= 0);
    /* 1.3 gaps of PPB_PROGRESS_LOG_SECONDS: one update line (at the gap) and the end line. */
    progress_into(fd, fd, 1.3 * PPB_PROGRESS_LOG_SECONDS, "points", 1, out, sizeof out);
    close(fd);
    if (strchr(out, '\r') || count_lines(out) != 2 || !strstr(out, "ux: 50.0%") ||
        !strstr(out, "ux: 1 point in "))
        fail_msg("off a terminal: want one plain update line and 'ux: 1 point in', no \\r:\n%s",
                 out);
}

static void test_progress_rewrites_on_terminal(void **state)
{
    (void)state;
    int m = posix_openpt(O_RDWR | O_NOCTTY);
    if (m < 0 || grantpt(m) || unlockpt(m))
        skip();
    int s = open(ptsname(m), O_RDWR | O_NOCTTY);
    assert_true(s >= 0);
    char out[8192];
    fcntl(m, F_SETFL, O_NONBLOCK);
    progress_into(s, m, 1.2, "points", 3, out, sizeof out);
    close(s);
    close(m);
    if (!strchr(out, '\r') || !strstr(out, "ux: 3 points in "))
        fail_msg("on a terminal: want \\r updates and 'ux: 3 points in':\n%s", out);
}

/* A whole run with stderr in a file: no \r in it, and progress lines bounded by the time. */
static void test_run_log_has_no_cr(void **state)
{
    (void)state;
    const char *cfg = cli_config("uxlog", tiny);
    char dir[1300], args[3000];
    snprintf(dir, sizeof dir, "%s/out", tu_scratch("uxlog_out"));
    snprintf(args, sizeof args, "run %s --out %s", cfg, dir);
    double t0 = ppb_now();
    cli_expect(args, 0, "wrote");
    double dt = ppb_now() - t0;
    int eta = 0;
    for (const char *s = cli_out; (s = strstr(s, "ETA")); s++)
        eta++;
    if (strchr(cli_out, '\r') || eta > 2 * (1 + (int)(dt / PPB_PROGRESS_LOG_SECONDS)))
        fail_msg("a run's log (%.1f s) holds \\r or %d progress lines:\n%s", dt, eta, cli_out);
}

/* --quiet means quiet (docs/reference.md: Exit codes, the paragraph on stderr): a run that
 * succeeds prints nothing, not even its "wrote" line or the reference cache's (both were
 * printed under --quiet before); errors still print. The second run takes mc from the cache. */
static void test_quiet_says_where(void **state)
{
    (void)state;
    const char *cfg = cli_config("uxquiet", tiny);
    const char *s = tu_scratch("uxquiet_out");
    char args[3000], env[1400];
    snprintf(env, sizeof env, "PPBENCH_CACHE=%s/cache", s);
    for (int i = 0; i < 2; i++) {
        snprintf(args, sizeof args, "run --quiet --set experiment.name=q %s --out %s/out", cfg, s);
        int rc = cli_run_env(env, args, cli_out, sizeof cli_out);
        if (rc != 0 || cli_out[0])
            fail_msg("run --quiet (%s): exit %d, want nothing printed, got:\n%s",
                     i ? "from the cache" : "first", rc, cli_out);
    }
    snprintf(args, sizeof args, "run --quiet %s --out /dev/null/x", cfg);
    cli_expect(args, 2, "ppbench: ");
}

/* The last line of the output: where cli_out's text ends, back to the line before. */
static const char *last_line(const char *s)
{
    size_t n = strlen(s);
    if (n > 0 && s[n - 1] == '\n')
        n--;
    while (n > 0 && s[n - 1] != '\n')
        n--;
    return s + n;
}

/* mc-merge (and mc-shard before it) end, like run, with the one line saying where the results
 * went: "NAME: wrote DIR". */
static void test_mc_merge_says_where(void **state)
{
    (void)state;
    const char *cfg = cli_config("uxmerge", tiny);
    const char *s = tu_scratch("uxmerge_out");
    char args[5000], want[1400];
    for (int i = 1; i <= 2; i++) {
        snprintf(args, sizeof args,
                 "mc-shard --quiet --set experiment.name=m --shard %d/2 --out %s/p%d %s", i, s, i,
                 cfg);
        cli_expect(args, 0, "");
    }
    snprintf(args, sizeof args, "mc-merge --set experiment.name=m --out %s/merged %s %s/p1 %s/p2",
             s, cfg, s, s);
    snprintf(want, sizeof want, "m: wrote %s/merged\n", s);
    int rc = cli_run_env("", args, cli_out, sizeof cli_out);
    if (rc != 0 || strcmp(last_line(cli_out), want))
        fail_msg("mc-merge: exit %d, want its last line '%s', got:\n%s", rc, want, cli_out);
}

/* A study of two small cases for the report tests: mc, ss and mp (cheap), 2e4 and 3e4
 * photons. */
static const char *small_study(void)
{
    static char s[1200];
    snprintf(s, sizeof s, "%s", tu_scratch("uxreport"));
    const char *cfg = cli_config("uxreport", tiny);
    char args[5000];
    const char *cases[2] = {"a", "b"};
    const char *photons[2] = {"2e4", "3e4"};
    for (int i = 0; i < 2; i++) {
        snprintf(args, sizeof args,
                 "run --quiet --set experiment.methods=mc,ss,mp --set mc.photons=%s --out %s/%s "
                 "%s",
                 photons[i], s, cases[i], cfg);
        cli_expect(args, 0, ""); /* --quiet: nothing printed */
    }
    return s;
}

/* report ends with "ppbench report: wrote DIR (3 files)"; its README gives Table 2 wide (a
 * column per method, the paper's methods in its order: MP before S), the noise floor from the
 * Monte Carlo's own standard errors (summary.csv's noise_rel at x = 0), the photon budget from
 * provenance.txt, and a footer naming only files that exist and never radiance.csv (not
 * committed: .gitignore). */
static void test_report_readme(void **state)
{
    (void)state;
    const char *s = small_study();
    char args[3000], want[1400], path[1400];
    snprintf(args, sizeof args, "report %s a b", s);
    snprintf(want, sizeof want, "ppbench report: wrote %s (3 files)\n", s);
    int rc = cli_run_env("", args, cli_out, sizeof cli_out);
    if (rc != 0 || strcmp(last_line(cli_out), want))
        fail_msg("report: exit %d, want its last line '%s', got:\n%s", rc, want, cli_out);
    snprintf(path, sizeof path, "%s/README.md", s);
    const char *readme = slurp(path, NULL);
    const char *lines[] = {"\n| case | cell | mp | ss | MC noise |\n|---|---|---|---|---|\n",
                           "\n| a | R_x0 | ",
                           "\n| a | T_x0 | ",
                           "\n| b | R_x0 | ",
                           "\n| b | T_x0 | ",
                           "\nMonte Carlo budget (mc.photons in each case's provenance.txt): "
                           "2e4 photons per case, 3e4 for b.\n",
                           "\n## Noise floor\n"};
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++)
        if (!strstr(readme, lines[i]))
            fail_msg("README.md lacks '%s':\n%s", lines[i], readme);
    /* The MC noise column at a's R_x0 is summary.csv's noise_rel there, in percent. */
    snprintf(path, sizeof path, "%s/a/summary.csv", s);
    const char *summary = slurp(path, NULL);
    const char *row = strstr(summary, "\nss,R_x0,");
    assert_non_null(row);
    double rms, noise;
    assert_int_equal(sscanf(row, "\nss,R_x0,%lf,%lf", &rms, &noise), 2);
    char cell[200];
    snprintf(cell, sizeof cell, "\n| a | R_x0 | ");
    readme = slurp(strcat(strcpy(path, s), "/README.md"), NULL);
    const char *r = strstr(readme, cell);
    assert_non_null(r);
    char ss_cell[64], noise_cell[64];
    snprintf(ss_cell, sizeof ss_cell, " %.1f |", 100 * rms);
    snprintf(noise_cell, sizeof noise_cell, " %.1f |\n", 100 * noise);
    const char *eol = strchr(r + 1, '\n');
    if (!strstr(r, ss_cell) || strstr(r, ss_cell) > eol || !strstr(r, noise_cell) ||
        strstr(r, noise_cell) > eol)
        fail_msg("row '%.*s' lacks ss's RMS%s or the noise%s of summary.csv", (int)(eol - r - 1),
                 r + 1, ss_cell, noise_cell);
    /* The footer: each file it names exists in both cases; radiance.csv (present) is not
     * named as one of them. */
    const char *foot = strstr(readme, "\nEach case's directory holds plots/ and images/");
    assert_non_null(foot);
    const char *list = strstr(foot, "version) and ");
    const char *end = strstr(foot, " (docs/reference.md, Outputs");
    assert_true(list && end && list < end);
    list += strlen("version) and ");
    char names[2000];
    snprintf(names, sizeof names, "%.*s", (int)(end - list), list);
    int named = 0;
    for (char *tok = strtok(names, ", "); tok; tok = strtok(NULL, ", ")) {
        if (!strcmp(tok, "and"))
            continue;
        named++;
        if (!strcmp(tok, "radiance.csv"))
            fail_msg("the footer names radiance.csv, which is not committed:\n%s", foot);
        for (int c = 0; c < 2; c++) {
            snprintf(path, sizeof path, "%s/%s/%s", s, c ? "b" : "a", tok);
            if (access(path, R_OK))
                fail_msg("the footer names %s, which %s lacks:\n%s", tok, c ? "b" : "a", foot);
        }
    }
    snprintf(path, sizeof path, "%s/a/radiance.csv", s);
    assert_int_equal(access(path, R_OK), 0);
    if (named < 5 || !strstr(foot, "summary.csv") || !strstr(foot, "provenance.txt"))
        fail_msg("the footer names %d files, want summary.csv and provenance.txt among them:\n%s",
                 named, foot);
}

/* The table a run and a score print on stdout (docs/reference.md: Outputs, "The table on
 * stdout"): a title, a header with the summary cells, one row per measured method with
 * "rms_excess (noise_rel)" in % at each cell. Expected values: the same run's summary.csv (the
 * metrics of docs/reference.md: Metrics, printed there to 6 digits), times 100, to the
 * table's 2 decimals (0.005 + the CSV's rounding). The reference (mc) and its companion (mc1)
 * have no row. --quiet prints nothing on stdout. */
static void check_table(const char *out, const char *summary_csv)
{
    static const char *const cells[] = {"R_x0", "T_x0", "S1_all", "S2_all", "S3_all", "S4_all"};
    if (!strstr(out, ": rms_excess against mc in % (noise_rel in parentheses; summary.csv)\n"))
        fail_msg("no table title on stdout:\n%s", out);
    const char *hdr = strstr(out, "\nmethod ");
    if (!hdr)
        fail_msg("no table header on stdout:\n%s", out);
    for (int c = 0; c < 6; c++)
        if (!strstr(hdr, cells[c]))
            fail_msg("the table header lacks %s:\n%s", cells[c], out);
    const char *row = strstr(out, "\nss ");
    if (!row || strstr(out, "\nmc ") || strstr(out, "\nmc1 "))
        fail_msg("want a row for ss and none for mc, mc1:\n%s", out);
    double ex[6], nz[6];
    if (sscanf(row + 4, " %lf (%lf) %lf (%lf) %lf (%lf) %lf (%lf) %lf (%lf) %lf (%lf)", &ex[0],
               &nz[0], &ex[1], &nz[1], &ex[2], &nz[2], &ex[3], &nz[3], &ex[4], &nz[4], &ex[5],
               &nz[5]) != 12)
        fail_msg("the ss row does not hold 6 'excess (noise)' pairs:\n%s", out);
    const char *csv = tu_read_text(summary_csv);
    for (int c = 0; c < 6; c++) {
        char key[64];
        snprintf(key, sizeof key, "\nss,%s,", cells[c]);
        const char *l = strstr(csv, key);
        double rms, noise, excess;
        if (!l || sscanf(l + strlen(key), "%lf,%lf,%lf", &rms, &noise, &excess) != 3)
            fail_msg("summary.csv lacks %s:\n%s", key + 1, csv);
        assert_close(ex[c], 100.0 * excess, 0.0051);
        assert_close(nz[c], 100.0 * noise, 0.0051);
    }
}

static void test_run_and_score_print_summary_table(void **state)
{
    (void)state;
    const char *cfg = cli_config("uxtable", tiny);
    char s[1100], dir[1300], path[1400];
    snprintf(s, sizeof s, "%s", tu_scratch("uxtable_out"));
    snprintf(dir, sizeof dir, "%s/out", s);
    assert_int_equal(tu_sh("%s run --no-ref-cache %s --out %s > %s/stdout 2> %s/stderr", tu_bin(),
                           cfg, dir, s, s),
                     0);
    snprintf(path, sizeof path, "%s/summary.csv", dir);
    char csvpath[1400];
    snprintf(csvpath, sizeof csvpath, "%s", path);
    snprintf(path, sizeof path, "%s/stdout", s);
    check_table(slurp(path, NULL), csvpath);
    /* score: the same numbers, from the run's radiance.csv read back (10 digits). */
    assert_int_equal(tu_sh("%s score --ref %s --out %s/sc %s/radiance.csv > %s/stdout 2> %s/stderr",
                           tu_bin(), dir, s, dir, s, s),
                     0);
    check_table(slurp(path, NULL), csvpath);
    /* --quiet: nothing on stdout, from either. */
    assert_int_equal(tu_sh("%s score --quiet --ref %s --out %s/sc2 %s/radiance.csv > %s/stdout "
                           "2> %s/stderr",
                           tu_bin(), dir, s, dir, s, s),
                     0);
    if (slurp(path, NULL)[0])
        fail_msg("score --quiet printed on stdout:\n%s", slurp(path, NULL));
    assert_int_equal(tu_sh("%s run --quiet --no-ref-cache %s --out %s > %s/stdout 2> %s/stderr",
                           tu_bin(), cfg, dir, s, s),
                     0);
    if (slurp(path, NULL)[0])
        fail_msg("run --quiet printed on stdout:\n%s", slurp(path, NULL));
}

/* The Python package (python/ppbench) against a run of the built binary: python/tests/
 * test_ppbench.py (its expected values: the set's own summary.csv and CSV files, and the
 * documented ValueErrors of docs/external.md: Python) on a tiny tube run of mc and ss. */
static void test_python_package(void **state)
{
    (void)state;
    if (system("python3 -c 'import sys; sys.exit(sys.version_info < (3, 8))'") != 0)
        fail_msg("python3 >= 3.8 is needed for the Python package");
    char root[4096];
    assert_non_null(realpath("python", root));
    const char *cfg = cli_config("uxpy", tiny);
    char dir[1300];
    snprintf(dir, sizeof dir, "%s/out", tu_scratch("uxpy_out"));
    assert_int_equal(
        tu_sh("%s run --quiet --no-ref-cache %s --out %s 2>/dev/null", tu_bin(), cfg, dir), 0);
    if (tu_sh("PYTHONDONTWRITEBYTECODE=1 PYTHONPATH='%s' PPB_TEST_RUN='%s' python3 -m unittest "
              "discover -s '%s/tests' 2>&1",
              root, dir, root) != 0)
        fail_msg("python/tests/test_ppbench.py failed (its output above)");
}

/* Kernel build warnings (docs/reference.md: Outputs, "The kernel build log"): a kernel that
 * builds with warnings says nothing on stderr (PoCL's clang printed "2 warnings generated."
 * there) and its diagnostics land in $PPBENCH_BUILD_LOG; a kernel that fails to build still
 * reports its log in the error. Expected text: the two conversions below are warnings clang
 * gives by default (an out-of-range double to int, 300 to char), the third line an error. */
static char *stderr_during_build(const char *file, int *rc, ppb_err *err, const char *out)
{
    ppb_ocl ocl;
    assert_int_equal(ppb_ocl_open(&ocl, NULL, err), 0);
    fflush(stderr);
    int saved = dup(2), fd = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    assert_true(saved >= 0 && fd >= 0);
    dup2(fd, 2);
    close(fd);
    cl_program prog = NULL;
    *rc = ppb_ocl_build(&ocl, file, "", &prog, err);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    if (prog)
        clReleaseProgram(prog);
    ppb_ocl_close(&ocl);
    return tu_read_text(out);
}

static void test_kernel_warnings_to_log(void **state)
{
    (void)state;
    char s[1100], path[1300], logp[1300], out[1300];
    snprintf(s, sizeof s, "%s", tu_scratch("uxkw"));
    snprintf(path, sizeof path, "%s/warn.cl", s);
    tu_write_file(path, "__kernel void k(__global int *o)\n{\n    int x = 1.5e40;\n"
                        "    char c = 300;\n    o[0] = x + c;\n}\n");
    snprintf(path, sizeof path, "%s/bad.cl", s);
    tu_write_file(path, "__kernel void k(__global int *o) { o[0] = undeclared_name; }\n");
    snprintf(logp, sizeof logp, "%s/log/kernel-build.log", s);
    snprintf(out, sizeof out, "%s/stderr", s);
    snprintf(path, sizeof path, "%s/pocl-cache", s);
    setenv("PPBENCH_SOURCE", s, 1);
    setenv("PPBENCH_BUILD_LOG", logp, 1);
    setenv("POCL_CACHE_DIR", path, 1); /* a fresh cache: the compiler runs */
    ppb_err err = {{0}};
    int rc;
    const char *said = stderr_during_build("warn.cl", &rc, &err, out);
    assert_int_equal(rc, 0);
    if (said[0])
        fail_msg("a build with warnings printed on stderr:\n%s", said);
    const char *log = tu_read_text(logp);
    if (!strstr(log, "warn.cl (options ") || !strstr(log, "300"))
        fail_msg("the kernel build log lacks the build's warnings:\n%s", log);
    said = stderr_during_build("bad.cl", &rc, &err, out);
    assert_int_equal(rc, -1);
    if (!strstr(err.msg, "building ") || !strstr(err.msg, "undeclared_name"))
        fail_msg("a failed build's error lacks its log:\n%s", err.msg);
    unsetenv("PPBENCH_SOURCE");
    unsetenv("PPBENCH_BUILD_LOG");
    unsetenv("POCL_CACHE_DIR");
}

/* timings.csv and stderr time the same thing (docs/reference.md: Outputs, timings.csv): each
 * method's whole run, said on stderr as "NAME: ID done in X s" when it finishes. Expected: the
 * same number, to the line's 2 decimals (timings.csv prints 4). Before, stderr said only the
 * trace's time (mc: 1.98 s) where timings.csv had the whole method's (4.69 s). */
static void test_timings_agree_with_stderr(void **state)
{
    (void)state;
    const char *cfg = cli_config("uxtime", tiny);
    char s[1100], dir[1300], path[1400];
    snprintf(s, sizeof s, "%s", tu_scratch("uxtime_out"));
    snprintf(dir, sizeof dir, "%s/out", s);
    assert_int_equal(tu_sh("%s run --no-ref-cache --set experiment.name=tm %s --out %s "
                           "> /dev/null 2> %s/stderr",
                           tu_bin(), cfg, dir, s),
                     0);
    snprintf(path, sizeof path, "%s/stderr", s);
    char err[1 << 15];
    snprintf(err, sizeof err, "%s", tu_read_text(path));
    snprintf(path, sizeof path, "%s/timings.csv", dir);
    const char *csv = tu_read_text(path);
    static const char *const ids[] = {"mc", "ss"};
    for (int i = 0; i < 2; i++) {
        char key[64];
        snprintf(key, sizeof key, "\n%s,", ids[i]);
        const char *l = strstr(csv, key);
        double want, got;
        if (!l || sscanf(l + strlen(key), "%lf", &want) != 1)
            fail_msg("timings.csv lacks %s:\n%s", ids[i], csv);
        snprintf(key, sizeof key, "tm: %s done in ", ids[i]);
        l = strstr(err, key);
        if (!l || sscanf(l + strlen(key), "%lf", &got) != 1)
            fail_msg("stderr lacks '%s':\n%s", key, err);
        assert_close(got, want, 0.0051);
    }
}

/* An interrupt that arrives while the last method runs, in a method that finishes regardless
 * (mp has no interruption point), leaves no row missing: provenance.txt says partial = 0 and no
 * method incomplete, the exit code is 130 (the interrupt was received) and stderr says the set
 * is complete (docs/reference.md: Exit codes). Before, every interrupted run was marked
 * partial = 1. mp.samples = 24 makes mp take several seconds (9 s on a loaded 2-core machine);
 * the interrupt comes after 1 s. */
static void test_interrupt_after_last_method_not_partial(void **state)
{
    (void)state;
    char s[1100], dir[1300], path[1400];
    snprintf(s, sizeof s, "%s", tu_scratch("uxlate"));
    snprintf(dir, sizeof dir, "%s/out", s);
    int rc = tu_sh("%s run --set experiment.methods=mp --set mp.samples=24 --out %s "
                   "configs/uniform_g0_normal.ini > /dev/null 2> %s/stderr & pid=$!; sleep 1; "
                   "kill -INT $pid; wait $pid",
                   tu_bin(), dir, s);
    snprintf(path, sizeof path, "%s/stderr", s);
    char err[1 << 15];
    snprintf(err, sizeof err, "%s", tu_read_text(path));
    if (rc != 130 || !strstr(err, "(interrupted after every method finished: complete)"))
        fail_msg("exit %d (want 130), stderr:\n%s", rc, err);
    snprintf(path, sizeof path, "%s/provenance.txt", dir);
    const char *p = tu_read_text(path);
    if (!strstr(p, "\npartial = 0\n") || strstr(p, ".incomplete"))
        fail_msg("a complete set marked partial:\n%s", p);
}

/* The study README opens with the summary figure when the study has one (summary.png, drawn by
 * scripts/summary_plot.sh as scripts/bench.sh does) and the findings in one paragraph: per
 * method, the range of rms_excess over the Table 2 cells of every case. Expected values: the
 * cases' summary.csv (R_x0 and T_x0 rows of a and b), in percent to the paragraph's 1 decimal;
 * the figure's file is a PNG (its 8-byte signature). */
static void test_report_opens_with_summary(void **state)
{
    (void)state;
    const char *s = small_study();
    char dir[1200], path[1400];
    snprintf(dir, sizeof dir, "%s", s);
    assert_int_equal(tu_sh("bash scripts/summary_plot.sh %s a b 2>/dev/null", dir), 0);
    snprintf(path, sizeof path, "%s/summary.png", dir);
    assert_int_equal(tu_sh("head -c 8 %s | od -An -tx1 | tr -d ' \\n' | grep -qx "
                           "89504e470d0a1a0a",
                           path),
                     0);
    assert_int_equal(tu_sh("%s report %s a b 2>/dev/null", tu_bin(), dir), 0);
    snprintf(path, sizeof path, "%s/README.md", dir);
    char readme[1 << 15];
    snprintf(readme, sizeof readme, "%s", tu_read_text(path));
    const char *fig = strstr(readme, "\n![The excess RMS at the Table 2 cells");
    const char *find = strstr(readme, "\n**Findings.** At the Table 2 cells of the 2 cases");
    const char *table = strstr(readme, "\n## Table 2\n");
    if (!fig || !find || !table || !(fig < find && find < table))
        fail_msg("README.md does not open with the figure, then the findings:\n%s", readme);
    static const char *const methods[] = {"ss", "mp"};
    for (int m = 0; m < 2; m++) {
        double lo = INFINITY, hi = -INFINITY;
        for (int c = 0; c < 2; c++) {
            snprintf(path, sizeof path, "%s/%s/summary.csv", dir, c ? "b" : "a");
            const char *csv = tu_read_text(path);
            for (int k = 0; k < 2; k++) {
                char key[64];
                snprintf(key, sizeof key, "\n%s,%s,", methods[m], k ? "T_x0" : "R_x0");
                const char *l = strstr(csv, key);
                double rms, noise, excess;
                if (!l || sscanf(l + strlen(key), "%lf,%lf,%lf", &rms, &noise, &excess) != 3)
                    fail_msg("%s lacks %s", path, key + 1);
                lo = excess < lo ? excess : lo;
                hi = excess > hi ? excess : hi;
            }
        }
        char want[128];
        snprintf(want, sizeof want, "`%s` %.1f-%.1f %% (median ", methods[m], 100 * lo, 100 * hi);
        const char *w = strstr(find, want);
        if (!w || w > table)
            fail_msg("the findings lack '%s':\n%.*s", want, (int)(table - find), find);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_provenance_versions_and_short_reals),
        cmocka_unit_test(test_config_ini_repeats_run),
        cmocka_unit_test(test_ini_round_trip_exact),
        cmocka_unit_test(test_progress_plain_lines_off_terminal),
        cmocka_unit_test(test_progress_rewrites_on_terminal),
        cmocka_unit_test(test_run_log_has_no_cr),
        cmocka_unit_test(test_quiet_says_where),
        cmocka_unit_test(test_mc_merge_says_where),
        cmocka_unit_test(test_report_readme),
        cmocka_unit_test(test_run_and_score_print_summary_table),
        cmocka_unit_test(test_python_package),
        cmocka_unit_test(test_kernel_warnings_to_log),
        cmocka_unit_test(test_timings_agree_with_stderr),
        cmocka_unit_test(test_interrupt_after_last_method_not_partial),
        cmocka_unit_test(test_report_opens_with_summary),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
