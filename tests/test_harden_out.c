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

/* The report's item 1: an --out holding a quote and gnuplot's system() once ran it as a command
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

/* The report's case: medium.albedo = 0 puts NaN in rms.csv and gnuplot refused the figure;
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_out_path_never_runs_as_gnuplot),
        cmocka_unit_test(test_name_from_file_checked),
        cmocka_unit_test(test_tmpdir_with_quote),
        cmocka_unit_test(test_failed_figures_keep_the_run),
        cmocka_unit_test(test_albedo_zero_run_written),
        cmocka_unit_test(test_full_disk_never_commits_incomplete_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
