/* Output sets, through the built binary ($PPBENCH): an experiment's output set is
 * committed whole or not at all, and a run owns its output directory. Each test reproduces a
 * defect of the earlier code (named in its comment) and checks the fixed behaviour:
 * - a re-run with fewer methods leaves none of the previous run's files;
 * - a directory holding files ppbench did not write is refused before any work (exit 2);
 * - a write failing midway (a file size limit, as a full disk) leaves the previous set as it was,
 *   and the message gives the path and the OS's reason;
 * - temporaries of dead processes are removed at start, a live process's never touched;
 * - `ppbench report` replaces only files it wrote and says what it wrote;
 * - an interrupted deterministic method writes none of its rows.
 * Expected values are facts of the file system (a file exists or not, two trees are equal byte
 * for byte: diff -r) and exit codes of README.md. Tiny grids and photon counts: bookkeeping,
 * not physics. */
#include "cliutil.h"

#include <errno.h>
#include <sys/stat.h>
#include <unistd.h>

static int exists(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int exists(const char *fmt, ...)
{
    char path[2400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(path, sizeof path, fmt, ap);
    va_end(ap);
    struct stat st;
    return lstat(path, &st) == 0;
}

#define assert_exists(...)                                                                         \
    do {                                                                                           \
        if (!exists(__VA_ARGS__))                                                                  \
            fail_msg("missing: " __VA_ARGS__);                                                     \
    } while (0)
#define assert_absent(...)                                                                         \
    do {                                                                                           \
        if (exists(__VA_ARGS__))                                                                   \
            fail_msg("still there: " __VA_ARGS__);                                                 \
    } while (0)

/* The run must exit with code and its output hold every needle (NULL-terminated). */
static void expect_all(const char *env, const char *args, int code, const char *const *needles)
{
    int rc = cli_run_env(env, args, cli_out, sizeof cli_out);
    for (int i = 0; needles[i]; i++)
        if (rc != code || !strstr(cli_out, needles[i]))
            fail_msg("ppbench %s: exit %d (want %d), output lacks '%s':\n%s", args, rc, code,
                     needles[i], cli_out);
}

/* Two methods that need little time: mc (with mc1: rms.csv, summary.csv, error images) and mp. */
static const char *tiny_cfg = "[experiment]\nname = tiny\nmethods = mc, mp\n"
                              "[tube]\nsegments_top = 8\nsegments_side = 2\n"
                              "[bins]\ntheta = 2\nphi = 2\n[mc]\nphotons = 2000\nbatches = 4\n";

static const char *tiny(void)
{
    return cli_config("outputs-cfg", tiny_cfg);
}

/* A pid no process has: a child's, after it exited and was reaped. */
static long dead_pid(void)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0)
        _exit(0);
    int st;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    assert_int_equal(kill(pid, 0), -1);
    assert_int_equal(errno, ESRCH);
    return (long)pid;
}

/* Before: `run` with fewer methods wrote radiance.csv anew and left the previous run's
 * summary.csv, rms.csv and error_*.png beside it. */
static void test_rerun_with_fewer_methods_leaves_nothing_stale(void **state)
{
    (void)state;
    const char *cfg = tiny();
    char d[1100], args[4000];
    snprintf(d, sizeof d, "%s/o", tu_scratch("outputs-rerun"));
    snprintf(args, sizeof args, "run --quiet --out %s %s", d, cfg);
    cli_expect(args, 0, "");
    assert_exists("%s/summary.csv", d);
    assert_exists("%s/mc_totals.csv", d);
    assert_exists("%s/images/error_mp.png", d);
    snprintf(args, sizeof args, "run --quiet --set experiment.methods=mp --out %s %s", d, cfg);
    cli_expect(args, 0, "");
    assert_exists("%s/radiance.csv", d);
    assert_exists("%s/images/mp.png", d);
    const char *stale[] = {"summary.csv",          "rms.csv",       "regions.csv",
                           "summary_mc1.csv",      "images/mc.png", "images/error_mp.png",
                           "images/error_mc1.png", "images/mc.exr", "mc_totals.csv"};
    for (size_t i = 0; i < sizeof stale / sizeof stale[0]; i++)
        assert_absent("%s/%s", d, stale[i]);
    /* radiance.csv holds mp's rows only (its first column is the method). */
    if (tu_sh("awk -F, 'NR > 1 && $1 != \"mp\" {exit 1}' %s/radiance.csv", d) != 0)
        fail_msg("%s/radiance.csv holds rows of a method that did not run", d);
}

/* A directory ppbench did not write is refused before any work, exit 2, untouched (before: the
 * outputs were written among the user's files; now the run replaces its directory whole, so
 * it must not take one that is not its own). An empty or new directory is taken. */
static void test_foreign_directory_is_refused_before_work(void **state)
{
    (void)state;
    const char *cfg = tiny();
    const char *s = tu_scratch("outputs-foreign");
    char d[1100], args[4000];
    snprintf(d, sizeof d, "%s/mine", s);
    assert_int_equal(tu_sh("mkdir -p %s && echo keep > %s/notes.txt", d, d), 0);
    /* Not --quiet: a method that started would say "tiny: mc ...". */
    snprintf(args, sizeof args, "run --out %s %s", d, cfg);
    const char *why[] = {d, "ppbench did not write", "notes.txt", NULL};
    expect_all("", args, 2, why);
    if (strstr(cli_out, "tiny: mc ..."))
        fail_msg("the run started before refusing:\n%s", cli_out);
    assert_int_equal(
        tu_sh("test \"$(cat %s/notes.txt)\" = keep && test \"$(ls %s)\" = notes.txt", d, d), 0);
    assert_int_equal(tu_sh("test -z \"$(ls %s | grep -v '^mine$')\"", s), 0); /* no staging left */
    /* mc-merge writes an output set too: refused before it reads a shard. */
    snprintf(args, sizeof args, "mc-merge --out %s %s %s/no-such-shard", d, cfg, s);
    expect_all("", args, 2, why);
    /* An empty directory is taken. */
    snprintf(d, sizeof d, "%s/empty", s);
    assert_int_equal(tu_sh("mkdir -p %s", d), 0);
    snprintf(args, sizeof args, "run --quiet --set experiment.methods=mp --out %s %s", d, cfg);
    cli_expect(args, 0, "");
    assert_exists("%s/radiance.csv", d);
}

/* Before: a write failing midway (here the mp.exr image, past a 5 KB file size limit: a full
 * disk without root) left the new CSVs beside the previous run's images, exit 1; and "write
 * failed" gave no reason. Now the previous set stays byte for byte, nothing new appears, and
 * the message names the file and the OS's reason (EFBIG under RLIMIT_FSIZE). */
static void test_failed_write_keeps_previous_set(void **state)
{
    (void)state;
    const char *cfg = tiny();
    const char *s = tu_scratch("outputs-full");
    char d[1100], args[4000], env[200];
    snprintf(d, sizeof d, "%s/o", s);
    snprintf(args, sizeof args, "run --quiet --out %s %s", d, cfg);
    cli_expect(args, 0, "");
    assert_int_equal(tu_sh("cp -r %s %s/saved", d, s), 0);
    /* The second run is mp alone: its radiance.csv differs from the first's (no mc rows). */
    snprintf(args, sizeof args, "run --quiet --set experiment.methods=mp --out %s %s", d, cfg);
    /* 10 blocks of 512 bytes: the CSVs fit (mp's radiance.csv is about 3.4 KB), the images do
     * not. SIGXFSZ ignored: the write fails with EFBIG instead of killing the process. The
     * images and figures are the least of the outputs (docs/reference.md: Outputs, "Figures"):
     * left out and said, the run's CSVs complete, exit 0. */
    snprintf(env, sizeof env, "sh -c 'trap \"\" XFSZ; ulimit -f 10; exec \"$0\" \"$@\"'");
    cli_expect_env(env, args, 0, "figure images not drawn");
    assert_int_equal(tu_sh("grep -q '^figure.images = not drawn: .*mp.exr' "
                           "%s/provenance.txt && test ! -e %s/images && grep -q '^mp,' "
                           "%s/radiance.csv",
                           d, d, d),
                     0);
    assert_int_equal(tu_sh("rm -r %s && cp -r %s/saved %s", d, s, d), 0);
    assert_int_equal(tu_sh("test \"$(ls %s)\" = \"$(printf 'o\\nsaved')\"", s), 0);
    /* 4 blocks: radiance.csv, the first file, fails; the message says where and why. */
    snprintf(env, sizeof env, "sh -c 'trap \"\" XFSZ; ulimit -f 4; exec \"$0\" \"$@\"'");
    char reason[300];
    snprintf(reason, sizeof reason, "radiance.csv: write failed: %s", strerror(EFBIG));
    cli_expect_env(env, args, 1, reason);
    if (tu_sh("diff -r %s %s/saved >&2", d, s) != 0)
        fail_msg("the previous output set changed:\n%s", cli_out);
    assert_int_equal(tu_sh("test \"$(ls %s)\" = \"$(printf 'o\\nsaved')\"", s), 0);
}

/* Before: a killed run left radiance.csv.tmp.<pid> (and now would leave staging directories)
 * behind forever. At start, those of dead processes are removed, in the output directory and
 * beside it; a live process's are never touched (the run refuses: it is writing there). */
static void test_stale_temporaries_of_dead_processes_removed(void **state)
{
    (void)state;
    const char *cfg = tiny();
    const char *s = tu_scratch("outputs-stale");
    char d[1100], args[4000];
    snprintf(d, sizeof d, "%s/o", s);
    snprintf(args, sizeof args, "run --quiet --set experiment.methods=mp --out %s %s", d, cfg);
    cli_expect(args, 0, "");
    long dead = dead_pid();
    assert_int_equal(
        tu_sh("touch %s/radiance.csv.tmp.%ld %s/images/mp.png.tmp.%ld && "
              "mkdir %s.tmp.%ld %s.old.%ld %s/new.tmp.%ld && touch %s.tmp.%ld/totals.csv",
              d, dead, d, dead, d, dead, d, dead, s, dead, d, dead),
        0);
    /* Removed at start, not with the previous directory when the new set is swapped in: this
     * run fails at its first file (a 2 KB file size limit), so no swap happens. */
    cli_expect_env("sh -c 'trap \"\" XFSZ; ulimit -f 4; exec \"$0\" \"$@\"'", args, 1,
                   "write failed");
    assert_exists("%s/radiance.csv", d);
    assert_absent("%s/radiance.csv.tmp.%ld", d, dead);
    assert_absent("%s/images/mp.png.tmp.%ld", d, dead);
    assert_absent("%s.tmp.%ld", d, dead);
    assert_absent("%s.old.%ld", d, dead);
    /* Also beside a directory that does not exist yet. */
    snprintf(args, sizeof args, "run --quiet --set experiment.methods=mp --out %s/new %s", s, cfg);
    cli_expect(args, 0, "");
    assert_absent("%s/new.tmp.%ld", s, dead);
    /* This test's own process is alive: its staging directory is left alone, the run refused. */
    long live = (long)getpid();
    assert_int_equal(tu_sh("mkdir %s.tmp.%ld && touch %s.tmp.%ld/radiance.csv", d, live, d, live),
                     0);
    char pid[32];
    snprintf(pid, sizeof pid, "process %ld", live);
    snprintf(args, sizeof args, "run --quiet --set experiment.methods=mp --out %s %s", d, cfg);
    const char *why[] = {d, pid, NULL};
    expect_all("", args, 2, why);
    assert_exists("%s.tmp.%ld/radiance.csv", d, live);
    assert_exists("%s/radiance.csv", d);
    assert_int_equal(tu_sh("rm -r %s.tmp.%ld", d, live), 0);
}

/* Before: `ppbench report . CASE` overwrote the repository's README.md, silently. Now a file
 * report did not write (its first line is not report's) is refused, exit 2, before anything is
 * written; what report writes it names, one line per file. */
static void test_report_replaces_only_its_own_files(void **state)
{
    (void)state;
    const char *cfg = tiny();
    const char *s = tu_scratch("outputs-report");
    char args[3000];
    snprintf(args, sizeof args, "run --quiet --out %s/case1 %s", s, cfg);
    cli_expect(args, 0, "");
    assert_int_equal(tu_sh("echo '# my project' > %s/README.md", s), 0);
    snprintf(args, sizeof args, "report %s case1", s);
    char readme[1200], csv[1200], md[1200];
    snprintf(readme, sizeof readme, "%s/README.md", s);
    snprintf(csv, sizeof csv, "%s/table2.csv", s);
    snprintf(md, sizeof md, "%s/table2.md", s);
    const char *refused_readme[] = {readme, "not written by ppbench report", NULL};
    expect_all("", args, 2, refused_readme);
    assert_int_equal(tu_sh("test \"$(cat %s)\" = '# my project'", readme), 0);
    assert_absent("%s", csv);
    assert_absent("%s", md);
    /* A table of someone else's is refused as well. */
    assert_int_equal(tu_sh("rm %s && printf 'a,b\\n1,2\\n' > %s", readme, csv), 0);
    const char *refused_csv[] = {csv, "not written by ppbench report", NULL};
    expect_all("", args, 2, refused_csv);
    assert_int_equal(tu_sh("test \"$(cat %s)\" = \"$(printf 'a,b\\n1,2')\"", csv), 0);
    assert_int_equal(tu_sh("rm %s", csv), 0);
    /* Its own files it writes, names, and replaces on the next report. */
    char w1[1300], w2[1300], w3[1300];
    snprintf(w1, sizeof w1, "wrote %s\n", csv);
    snprintf(w2, sizeof w2, "wrote %s\n", md);
    snprintf(w3, sizeof w3, "wrote %s\n", readme);
    const char *wrote[] = {w1, w2, w3, NULL};
    expect_all("", args, 0, wrote);
    expect_all("", args, 0, wrote);
    /* A README.md an earlier report wrote (its title line first) is its own too. */
    assert_int_equal(
        tu_sh("printf '# The accuracy study (written by `make bench`)\\nold\\n' > %s", readme), 0);
    expect_all("", args, 0, wrote);
    assert_int_equal(tu_sh("grep -q 'RMS error against the Monte Carlo' %s", readme), 0);
}

/* Before: an interrupted pp wrote the rows it never marched as 0 radiance, like data. Now an
 * incomplete deterministic method writes none of its rows; the run is marked partial (exit
 * 130, partial = 1) and provenance.txt says which method is incomplete. mp, which finished
 * before, keeps its rows. */
static void test_interrupted_pp_writes_no_rows(void **state)
{
    (void)state;
    /* A march far longer than the first progress line takes to appear (0.5 s on a terminal,
     * PPB_PROGRESS_LOG_SECONDS = 5 s in a log, as here): the R table steps every ray (the S
     * table's closed form makes the march take 0.5 s whatever the step), at step 0.002 tens of
     * seconds; SIGINT once that line shows the march under way. */
    const char *cfg =
        cli_config("outputs-pp-cfg", "[experiment]\nname = ppint\nmethods = mp, pp\n"
                                     "[pp]\ndirections = 16\ntable = R\nstep = 0.002\n");
    const char *s = tu_scratch("outputs-pp");
    const char *b = getenv("PPBENCH") ? getenv("PPBENCH") : "./ppbench";
    int rc = tu_sh("%s run --out %s/o %s 2> %s/err & pid=$!; i=0; "
                   "until grep -q 'pp: .*rows/s' %s/err || [ $i -ge 1200 ]; do sleep 0.1; "
                   "i=$((i + 1)); done; kill -INT $pid; wait $pid",
                   b, s, cfg, s, s);
    if (rc != 130)
        tu_sh("tr '\\r' '\\n' < %s/err >&2", s);
    assert_int_equal(rc, 130);
    assert_int_equal(tu_sh("grep -q 'pp: .*rows/s' %s/err", s), 0); /* interrupted while marching */
    if (tu_sh("awk -F, '$1 == \"pp\" {exit 1}' %s/o/radiance.csv", s) != 0)
        fail_msg("%s/o/radiance.csv holds rows of the interrupted pp", s);
    assert_int_equal(tu_sh("grep -q '^mp,' %s/o/radiance.csv", s), 0);
    assert_int_equal(tu_sh("awk -F, '$1 == \"pp\" {exit 1}' %s/o/totals.csv", s), 0);
    assert_int_equal(tu_sh("grep -q '^partial = 1$' %s/o/provenance.txt", s), 0);
    assert_int_equal(tu_sh("grep -q '^pp.incomplete = ' %s/o/provenance.txt", s), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rerun_with_fewer_methods_leaves_nothing_stale),
        cmocka_unit_test(test_foreign_directory_is_refused_before_work),
        cmocka_unit_test(test_failed_write_keeps_previous_set),
        cmocka_unit_test(test_stale_temporaries_of_dead_processes_removed),
        cmocka_unit_test(test_report_replaces_only_its_own_files),
        cmocka_unit_test(test_interrupted_pp_writes_no_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
