/* test_harden_out.c: what draws or writes an output set, under hostile names, failing figures
 * and a full disk (docs/reference.md: Outputs, "Figures" and "Exit codes"). Paths and names
 * reach gnuplot only as data; a figure that cannot be drawn is said and left out while the
 * CSVs are written and the run exits 0; no incomplete file is ever put in place. */
/* _GNU_SOURCE: memmem */
#define _GNU_SOURCE
#include "cliutil.h"

#include <sys/stat.h>
#include <unistd.h>

static const char *small = "run --quiet --set mc.photons=2e4 --set pp.directions=16 "
                           "--set bins.samples_dir=2 --set tube.segments_top=32 "
                           "--set tube.segments_side=8 --set experiment.methods=mc,pp";

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Whether the file at path is complete as its kind shows (the rule of ppb_file_complete,
 * restated here from the PNG and PDF formats so the test does not trust the code under test):
 * non-empty; a PNG ends with its IEND chunk (PNG spec 11.2.5: length 0, "IEND", CRC AE 42 60
 * 82); a PDF ends with %%EOF (PDF 1.7, 7.5.5). */
static int file_ok(const char *path)
{
    static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    unsigned char tail[64] = {0};
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    long n = size < 64 ? size : 64;
    fseek(f, size - n, SEEK_SET);
    size_t got = fread(tail, 1, (size_t)n, f);
    fclose(f);
    size_t len = strlen(path);
    if (size <= 0 || got != (size_t)n)
        return 0;
    if (len > 4 && !strcmp(path + len - 4, ".png"))
        return n >= 12 && !memcmp(tail + n - 12, iend, 12);
    if (len > 4 && !strcmp(path + len - 4, ".pdf"))
        return memmem(tail, (size_t)n, "%%EOF", 5) != NULL;
    return 1;
}

/* Fails naming the first file under dir that is not complete; returns how many files. */
static int assert_all_complete(const char *dir)
{
    char cmd[2400], line[4200];
    snprintf(cmd, sizeof cmd, "find '%s' -type f", dir);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    int n = 0;
    while (fgets(line, sizeof line, p)) {
        line[strcspn(line, "\n")] = '\0';
        if (!file_ok(line))
            fail_msg("%s: incomplete (0 bytes or cut short)", line);
        n++;
    }
    pclose(p);
    return n;
}

/* An --out holding a quote and gnuplot's system() once ran it as a command
 * (plots.sh wrote `set output '$out...'`), and exited 1 with no outputs. Now the path is data:
 * nothing runs, the figures are drawn into that very directory, exit 0. */
static void test_out_path_never_runs_as_gnuplot(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_quote");
    char out[2600], mark[1200], args[4096], path[4200];
    snprintf(mark, sizeof mark, "%s/X", dir);
    snprintf(out, sizeof out, "%s/o/a';system('touch %s');'", dir, mark);
    snprintf(args, sizeof args, "%s --out \"%s\" configs/density_step.ini", small, out);
    cli_expect_env("PPBENCH_CACHE=", args, 0, "");
    if (exists(mark))
        fail_msg("gnuplot ran a command from the --out path:\n%s", cli_out);
    snprintf(path, sizeof path, "%s/plots/rms_vs_x.png", out);
    assert_true(file_ok(path));
    snprintf(path, sizeof path, "%s/images/all.pdf", out);
    assert_true(file_ok(path));
}

/* A config file with no `name =` lends its base name to the experiment: that name obeys the
 * rule of `name =` ([A-Za-z0-9_.+-], docs/reference.md: Config keys), so a file named with a
 * backquote is refused before any work (exit 2) and nothing runs. Before, the name went
 * unchecked into a double-quoted gnuplot title and `touch X` ran, exit 0. */
static void test_name_from_file_checked(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_name");
    char ini[2600], args[4096];
    /* gnuplot's system() and the shell run `touch X` in the working directory (the repo's) */
    assert_false(exists("X"));
    snprintf(ini, sizeof ini, "%s/b`touch X`.ini", dir);
    assert_int_equal(tu_sh("grep -v '^name *=' configs/density_step.ini > '%s'", ini), 0);
    snprintf(args, sizeof args, "%s --out '%s/o' '%s'", small, dir, ini);
    cli_expect_env("PPBENCH_CACHE=", args, 2, "may hold only letters, digits and _-.+");
    assert_false(exists("X"));
}

/* $TMPDIR holding a quote: plots.sh's data files live there and were named inside the gnuplot
 * script, which then failed (exit 1, no outputs). */
static void test_tmpdir_with_quote(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_tmpdir");
    char env[2400], args[4096], path[2400];
    snprintf(env, sizeof env, "PPBENCH_CACHE= TMPDIR=\"%s/t'mp\"", dir);
    assert_int_equal(tu_sh("mkdir -p \"%s/t'mp\"", dir), 0);
    snprintf(args, sizeof args, "%s --out '%s/o' configs/density_step.ini", small, dir);
    cli_expect_env(env, args, 0, "");
    snprintf(path, sizeof path, "%s/o/plots/rms_vs_x.png", dir);
    assert_true(file_ok(path));
}

/* A plot style gnuplot cannot load makes every figure fail: the run still writes every CSV,
 * exits 0, says each figure on stderr with gnuplot's reason and lists it in provenance.txt
 * (docs/reference.md: Outputs, "Figures"). Before, the first failing figure ended the run:
 * exit 1, "is gnuplot installed?", no output directory. */
static void test_failed_figures_keep_the_run(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_figfail");
    char env[2400], args[4096], path[2400];
    assert_int_equal(tu_sh("mkdir -p '%s/scripts' && cp scripts/plots.sh '%s/scripts/' && "
                           "echo 'this is not gnuplot' > '%s/scripts/plot_style.gp'",
                           dir, dir, dir),
                     0);
    snprintf(env, sizeof env, "PPBENCH_CACHE= PPBENCH_SCRIPTS='%s/scripts'", dir);
    snprintf(args, sizeof args, "%s --out '%s/o' configs/density_step.ini", small, dir);
    cli_expect_env(env, args, 0, "figure plots/rms_vs_x not drawn");
    assert_non_null(strstr(cli_out, "invalid command")); /* gnuplot's own reason */
    const char *csv[] = {"radiance.csv", "rms.csv", "summary.csv", "totals.csv", "regions.csv"};
    for (int i = 0; i < 5; i++) {
        snprintf(path, sizeof path, "%s/o/%s", dir, csv[i]);
        assert_true(file_ok(path));
    }
    snprintf(path, sizeof path, "%s/o/provenance.txt", dir);
    char *prov = tu_read_text(path);
    assert_non_null(strstr(prov, "figure.plots/rms_vs_x = not drawn: "));
    assert_non_null(strstr(prov, "figure.images/all = not drawn: "));
    snprintf(path, sizeof path, "%s/o/plots/rms_vs_x.png", dir);
    assert_false(exists(path));
}

/* medium.albedo = 0 puts NaN in rms.csv and gnuplot refused the figure;
 * the run exited 1 with nothing written. Now: exit 0, rms.csv written. */
static void test_albedo_zero_run_written(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_albedo0");
    char args[4096], path[2400];
    snprintf(args, sizeof args, "%s --set medium.albedo=0 --out '%s/o' configs/density_step.ini",
             small, dir);
    cli_expect_env("PPBENCH_CACHE=", args, 0, "");
    snprintf(path, sizeof path, "%s/o/rms.csv", dir);
    assert_true(file_ok(path));
    snprintf(path, sizeof path, "%s/o", dir);
    assert_all_complete(path);
}

/* A nearly full disk (a 4 MB tmpfs, a previous 1.2 MB set in it, then filled to leave 500 to
 * 1100 KB): each run either fails and leaves the previous set exactly as it was, or succeeds
 * with every file complete and every missing figure listed in provenance.txt. Before, exit 0
 * with "wrote" and PNG/PDF files of 0 bytes, the previous set discarded. Needs root (mount);
 * skipped without. */
static void test_full_disk_never_commits_incomplete_files(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_disk");
    char mnt[1200], args[4096], path[2400];
    snprintf(mnt, sizeof mnt, "%s/mnt", dir);
    if (tu_sh("mkdir -p '%s' && mount -t tmpfs -o size=4m tmpfs '%s' 2>/dev/null", mnt, mnt))
        skip();
    snprintf(args, sizeof args, "%s --set mc.seed=1 --out '%s/o' configs/density_step.ini", small,
             mnt);
    int rc = cli_run_env("PPBENCH_CACHE=", args, cli_out, sizeof cli_out);
    if (rc != 0) {
        tu_sh("umount '%s'", mnt);
        fail_msg("the first run on an empty tmpfs failed:\n%s", cli_out);
    }
    snprintf(path, sizeof path, "%s/o", mnt);
    int nfiles = assert_all_complete(path);
    const int free_kb[] = {500, 700, 900, 1100};
    for (int i = 0; i < 4; i++) {
        tu_sh("cd '%s' && cp o/provenance.txt ../before.txt && rm -f fill && "
              "dd if=/dev/zero of=fill bs=1k count=$(( $(df -k --output=avail . | tail -1) - %d )) "
              "2>/dev/null",
              mnt, free_kb[i]);
        snprintf(args, sizeof args, "%s --set mc.seed=%d --out '%s/o' configs/density_step.ini",
                 small, i + 2, mnt);
        rc = cli_run_env("PPBENCH_CACHE=", args, cli_out, sizeof cli_out);
        int same = tu_sh("cmp -s '%s/o/provenance.txt' '%s/before.txt'", mnt, dir) == 0;
        int complete = tu_sh("find '%s/o' -type f -size 0 | grep -q .", mnt) != 0;
        if (complete)
            assert_all_complete(path);
        else
            tu_sh("find '%s/o' -type f -size 0 >&2", mnt);
        if (!complete || (rc != 0 && !same) || (rc == 0 && same)) {
            tu_sh("umount '%s'", mnt);
            fail_msg("%d KB free: exit %d, previous set %s, files %s:\n%s", free_kb[i], rc,
                     same ? "kept" : "replaced", complete ? "complete" : "incomplete", cli_out);
        }
        if (rc != 0) /* refused whole: the previous set is all there */
            assert_int_equal(assert_all_complete(path), nfiles);
    }
    tu_sh("umount '%s'", mnt);
}

/* Two finished runs, A and B, under one scratch directory, made once for the tests below. */
static const char *finished_runs(void)
{
    static char dir[1200];
    if (dir[0])
        return dir;
    snprintf(dir, sizeof dir, "%s", tu_scratch("harden_runs"));
    char args[4096];
    for (int i = 0; i < 2; i++) {
        snprintf(args, sizeof args, "%s --out '%s/%c' configs/density_step.ini", small, dir,
                 "AB"[i]);
        cli_expect_env("PPBENCH_CACHE=", args, 0, "");
    }
    return dir;
}

/* score's --out is its own output set (docs/reference.md: Outputs, score): another finished
 * run, a user's directory or a file is refused with exit 2, untouched; its own earlier set is
 * replaced whole. Before: B's summary/rms/regions/totals were replaced (exit 0), a user's
 * directory written into, and a file gave exit 1. */
static void test_score_claims_only_its_own_set(void **state)
{
    (void)state;
    const char *d = finished_runs();
    char args[4096];
    assert_int_equal(tu_sh("cd '%s' && rm -rf saved U F S && cp -r B saved && mkdir U && "
                           "echo mine > U/notes.txt && touch F",
                           d),
                     0);
    const char *outs[] = {"B", "U", "F"};
    for (int i = 0; i < 3; i++) {
        snprintf(args, sizeof args, "score --ref '%s/A' --out '%s/%s' '%s/A/radiance.csv'", d, d,
                 outs[i], d);
        cli_expect(args, 2, "ppbench score: --out ");
    }
    assert_int_equal(tu_sh("cd '%s' && diff -r B saved && test \"$(ls U)\" = notes.txt", d), 0);
    for (int i = 0; i < 2; i++) { /* new, then its own set replaced */
        snprintf(args, sizeof args, "score --quiet --ref '%s/A' --out '%s/S' '%s/A/radiance.csv'",
                 d, d, d);
        cli_expect(args, 0, "");
        assert_int_equal(tu_sh("cd '%s' && head -1 S/provenance.txt | grep -q '^# ppbench score "
                               "provenance:' && test -s S/summary.csv && ! ls -d S.* 2>/dev/null",
                               d),
                         0);
    }
}

/* Bad input is exit 2 everywhere (docs/reference.md: Exit codes): a report naming a case that
 * is not there (was 1) and an mc-merge given a directory holding no shard (was 1; merge's
 * equivalent was 2 already). */
static void test_bad_input_exits_2(void **state)
{
    (void)state;
    const char *d = finished_runs();
    char args[4096];
    snprintf(args, sizeof args, "report '%s' A nosuchcase", d);
    cli_expect(args, 2, "nosuchcase");
    assert_int_equal(tu_sh("test ! -e '%s/table2.csv'", d), 0);
    snprintf(args, sizeof args, "mc-merge --out '%s/M' configs/density_step.ini '%s/A'", d, d);
    cli_expect(args, 2, "mc_tallies.bin");
}

/* `ppbench scene` without --out writes into the config's [output] dir: there a finished run's
 * set was (scene.json added into it, exit 0). Now refused, exit 2, the set untouched. */
static void test_scene_never_writes_into_a_set(void **state)
{
    (void)state;
    const char *d = finished_runs();
    char args[4096];
    snprintf(args, sizeof args, "scene --set output.dir='%s/A' configs/density_step.ini", d);
    cli_expect(args, 2, "give --out DIR");
    assert_int_equal(tu_sh("test ! -e '%s/A/scene.json'", d), 0);
}

/* A dangling symbolic link as --out was replaced by a directory, silently (exit 0): now
 * refused before any work (exit 2), the link kept. */
static void test_dangling_symlink_refused(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_link");
    char args[4096];
    assert_int_equal(tu_sh("ln -s '%s/nowhere' '%s/L'", dir, dir), 0);
    snprintf(args, sizeof args, "%s --out '%s/L' configs/density_step.ini", small, dir);
    cli_expect_env("PPBENCH_CACHE=", args, 2, "a symbolic link to nothing");
    assert_int_equal(tu_sh("test -L '%s/L' && test ! -e '%s/nowhere'", dir, dir), 0);
}

/* A scripts folder whose plots.sh first runs `pre` (shell text) and then the real script. */
static void wrap_plots(const char *dir, const char *pre)
{
    char text[4096], path[1300];
    char *here = realpath("scripts", NULL);
    assert_non_null(here);
    snprintf(text, sizeof text, "%s\nexec bash '%s/plots.sh' \"$@\"\n", pre, here);
    free(here);
    snprintf(path, sizeof path, "%s/scripts", dir);
    assert_int_equal(tu_sh("mkdir -p '%s' && cp scripts/plot_style.gp '%s/'", path, path), 0);
    snprintf(path, sizeof path, "%s/scripts/plots.sh", dir);
    tu_write_file(path, text);
}

/* Two runs on one --out: both computed and the loser failed at its end. Now the second is
 * refused at its start (exit 2), naming the lock, while the first holds it (here: kept in its
 * plotting by a plots.sh that waits), and the first still succeeds. */
static void test_second_run_on_one_out_refused(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_lock");
    char pre[1400], env[2400], args[4096];
    snprintf(pre, sizeof pre, "touch '%s/plotting'; sleep 4", dir);
    wrap_plots(dir, pre);
    snprintf(env, sizeof env, "PPBENCH_CACHE= PPBENCH_SCRIPTS='%s/scripts'", dir);
    assert_int_equal(tu_sh("(%s %s %s --out '%s/o' configs/density_step.ini > '%s/first.log' "
                           "2>&1; echo $? > '%s/first.rc') &",
                           env, tu_bin(), small, dir, dir, dir),
                     0);
    assert_int_equal(tu_sh("for i in $(seq 600); do test -e '%s/plotting' && exit 0; "
                           "sleep 0.1; done; exit 1",
                           dir),
                     0);
    snprintf(args, sizeof args, "%s --out '%s/o' configs/density_step.ini", small, dir);
    cli_expect_env("PPBENCH_CACHE=", args, 2, "another ppbench is writing it");
    assert_int_equal(tu_sh("for i in $(seq 600); do test -s '%s/first.rc' && exit 0; "
                           "sleep 0.1; done; exit 1",
                           dir),
                     0);
    assert_int_equal(tu_sh("test \"$(cat '%s/first.rc')\" = 0 && test -s '%s/o/rms.csv'", dir, dir),
                     0);
}

/* SIGTERM while the set is being written (here: sent by plots.sh to ppbench, its parent)
 * exited 0 though the command was stopped; an interrupt earlier exits 130 (docs/reference.md:
 * Exit codes). Now 130 too; the set is whole. */
static void test_sigterm_while_writing_exits_130(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_term");
    char env[2400], args[4096], path[1400];
    /* ppbench itself (the script runs under its guard, base/child.h: PPBENCH_OWNER names it) */
    wrap_plots(dir, "kill -TERM ${PPBENCH_OWNER%%:*}");
    snprintf(env, sizeof env, "PPBENCH_CACHE= PPBENCH_SCRIPTS='%s/scripts'", dir);
    snprintf(args, sizeof args, "%s --out '%s/o' configs/density_step.ini", small, dir);
    cli_expect_env(env, args, 130, "");
    snprintf(path, sizeof path, "%s/o/rms.csv", dir);
    assert_true(file_ok(path));
}

/* --out relative, its parent not there yet: the run makes the parent and takes its lock once.
 * Before, the lock was taken under the relative name at the check and again under the absolute
 * one at the write, and the process refused itself ("another ppbench is writing it"), exit 1. */
static void test_relative_out_new_parent(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_rel");
    assert_int_equal(tu_sh("cd '%s' && PPBENCH_CACHE= \"$PPBENCH\" %s --out rel/sub/x "
                           "'%s/configs/density_step.ini' && test -f rel/sub/x/rms.csv",
                           dir, small, PPB_SOURCE_DIR),
                     0);
}

/* The same run twice gives the same PDFs: cairo wrote the wall-clock /CreationDate into each,
 * so two runs a second apart differed. Now the date is fixed (docs/reference.md: Outputs). */
static void test_same_run_same_pdfs(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_pdf");
    char args[4096];
    for (int i = 0; i < 2; i++) {
        if (i)
            sleep(1); /* cairo's date has whole seconds */
        snprintf(args, sizeof args, "%s --out '%s/r%d' configs/density_step.ini", small, dir, i);
        cli_expect_env("PPBENCH_CACHE=", args, 0, "");
    }
    assert_int_equal(tu_sh("cd '%s' && n=0 && for f in $(cd r0 && find . -name '*.pdf'); do "
                           "cmp r0/$f r1/$f >&2 || exit 1; n=$((n + 1)); done; test $n -ge 6",
                           /* rms_vs_x, angular_x0(_polar), all, error_pp, error_mc1 */
                           dir),
                     0);
}

/* report's three files go in place together: a README that cannot be written (a 1 KB file
 * size limit, which the two tables fit) leaves all three as they were, never new tables beside
 * the old README. Before, the tables were renamed into place first, then the README failed:
 * new tables with an old README, exit 1. */
static void test_report_files_replaced_together(void **state)
{
    (void)state;
    const char *d = finished_runs();
    char args[4096];
    snprintf(args, sizeof args, "report '%s' A B", d);
    cli_expect(args, 0, "");
    assert_int_equal(
        tu_sh("cd '%s' && mkdir -p saved_report && cp table2.csv table2.md README.md saved_report/",
              d),
        0);
    snprintf(args, sizeof args, "report '%s' A", d);
    cli_expect_env("sh -c 'trap \"\" XFSZ; ulimit -f 2; exec \"$0\" \"$@\"'", args, 1, "README.md");
    assert_int_equal(tu_sh("cd '%s' && for f in table2.csv table2.md README.md; do "
                           "cmp $f saved_report/$f || exit 1; done",
                           d),
                     0);
}

/* A sweep's heat maps under a 10 KB file size limit (the points already computed, so only the
 * figures are drawn): gnuplot's cairo wrote them cut short and exited 0, and the sweep put the
 * 10240-byte PNG and PDF in place. Now each is checked complete (ppb_file_complete) and left
 * out, said on stderr; exit 0, sweep.csv written. */
static void test_sweep_heatmap_cut_short_left_out(void **state)
{
    (void)state;
    const char *dir = tu_scratch("harden_sweep");
    char ini[1300], args[4096], path[1400];
    snprintf(ini, sizeof ini, "%s/s.ini", dir);
    snprintf(args, sizeof args,
             "[experiment]\nname = s\ngeometry = slab\nmethods = mc, ss\n[medium]\ng = 0, 0.5\n"
             "albedo = 0.5, 0.9\n[mc]\nphotons = 2e4\n[pp]\ndirections = 16\n[output]\n"
             "dir = %s/out\n",
             dir);
    tu_write_file(ini, args);
    snprintf(args, sizeof args, "sweep --quiet '%s'", ini);
    cli_expect_env("PPBENCH_CACHE=", args, 0, "");
    cli_expect_env("PPBENCH_CACHE= sh -c 'trap \"\" XFSZ; ulimit -f 20; exec \"$0\" \"$@\"'", args,
                   0, "figure heatmap_ss not drawn");
    snprintf(path, sizeof path, "%s/out/sweep.csv", dir);
    assert_true(file_ok(path));
    for (int t = 0; t < 2; t++) {
        snprintf(path, sizeof path, "%s/out/heatmap_ss.%s", dir, t ? "pdf" : "png");
        if (exists(path) && !file_ok(path))
            fail_msg("%s: put in place cut short", path);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_out_path_never_runs_as_gnuplot),
        cmocka_unit_test(test_name_from_file_checked),
        cmocka_unit_test(test_tmpdir_with_quote),
        cmocka_unit_test(test_failed_figures_keep_the_run),
        cmocka_unit_test(test_albedo_zero_run_written),
        cmocka_unit_test(test_full_disk_never_commits_incomplete_files),
        cmocka_unit_test(test_score_claims_only_its_own_set),
        cmocka_unit_test(test_bad_input_exits_2),
        cmocka_unit_test(test_scene_never_writes_into_a_set),
        cmocka_unit_test(test_dangling_symlink_refused),
        cmocka_unit_test(test_second_run_on_one_out_refused),
        cmocka_unit_test(test_sigterm_while_writing_exits_130),
        cmocka_unit_test(test_relative_out_new_parent),
        cmocka_unit_test(test_same_run_same_pdfs),
        cmocka_unit_test(test_report_files_replaced_together),
        cmocka_unit_test(test_sweep_heatmap_cut_short_left_out),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
