/* The command line's options ("Options", "--help", "a bad --device", "output and
 * device problems found only after computing"): each test reproduces a defect of the earlier
 * src/drivers/main.c and checks the fixed behaviour. A bad command line is exit 2 with a
 * message naming the option (and the command), before any work starts: where the old binary
 * computed first, the test checks that nothing was written. Runs the built binary ($PPBENCH). */
#include "cliutil.h"

#include <sys/stat.h>

/* The scratch directories below are copied out of tu_scratch's buffer, which the next
 * cli_config reuses. */
static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* A config that runs in well under a second: mp alone (no OpenCL), a small tube. */
static const char *cheap_config(const char *name, const char *extra)
{
    char text[1024];
    snprintf(text, sizeof text,
             "[experiment]\nname = %s\nmethods = mp\n\n[tube]\nsegments_top = 8\n"
             "segments_side = 4\n\n[bins]\ntheta = 2\nphi = 2\n%s",
             name, extra);
    return cli_config(name, text);
}

/* Integers are parsed whole: atoi took "2x" and "2.9" as 2, and sscanf("%d/%d") took "1/2x" as
 * 1/2 and wrapped 99999999999 (the old binary went on to the config, whose missing file was
 * the only error it reported). */
static void test_integers_are_strict(void **state)
{
    (void)state;
    const char *bad[][2] = {
        {"--jobs 2x", "--jobs 2x"},
        {"--jobs 2.9", "--jobs 2.9"},
        {"--jobs ' 2'", "--jobs  2"},
        {"--jobs -1", "--jobs -1"},
        {"--jobs 65", "--jobs 65"},
        {"--jobs 99999999999999999999", "--jobs 99999999999999999999"},
        {"--shard 1/2x", "--shard 1/2x"},
        {"--shard 1x/2", "--shard 1x/2"},
        {"--shard 1/99999999999", "--shard 1/99999999999"},
        {"--shard 3/2", "--shard 3/2"},
        {"--shard 0/2", "--shard 0/2"},
        {"--shard /2", "--shard /2"},
    };
    char args[256];
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(args, sizeof args, "sweep %s /nonexistent/cfg.ini", bad[i][0]);
        cli_expect(args, 2, bad[i][1]);
        if (strstr(cli_out, "cannot open config"))
            fail_msg("ppbench %s: went on to the config:\n%s", args, cli_out);
    }
    /* The accepted forms still reach the config (whose absence is then the error). */
    cli_expect("sweep --jobs 64 --shard 2147483647/2147483647 /nonexistent/cfg.ini", 2,
               "/nonexistent/cfg.ini: cannot open config");
}

/* An --out longer than the 1023 characters a config holds was cut silently, so the results
 * landed in another directory; now it is refused. */
static void test_out_too_long(void **state)
{
    (void)state;
    static char args[4096];
    char longdir[1101];
    memset(longdir, 'd', sizeof longdir - 1);
    longdir[sizeof longdir - 1] = '\0';
    longdir[0] = '/';
    snprintf(args, sizeof args, "run --out %s /nonexistent/cfg.ini", longdir);
    cli_expect(args, 2, "--out: too long (1100 characters");
    /* 1023 characters fit: the run goes on to the config. */
    longdir[1023] = '\0';
    snprintf(args, sizeof args, "run --out %s /nonexistent/cfg.ini", longdir);
    cli_expect(args, 2, "cannot open config");
}

/* More than 64 --set options: the 65th was reported as "unknown option or missing value".
 * Here the 70th sets an unknown key, so the error proves it was applied. */
static void test_many_sets(void **state)
{
    (void)state;
    static char args[8192];
    const char *p = cheap_config("opt-sets", "");
    int n = snprintf(args, sizeof args, "run --quiet");
    for (int i = 0; i < 69; i++)
        n += snprintf(args + n, sizeof args - (size_t)n, " --set medium.g=0");
    snprintf(args + n, sizeof args - (size_t)n, " --set medium.gg=1 --out /nonexistent-dir/x %s",
             p);
    cli_expect(args, 2, "--set medium.gg: unknown key");
}

/* An option a command does not use was ignored (`merge --jobs 2` merged serially, `devices
 * --out x` listed devices with exit 0); now it is an error naming the option and the command. */
static void test_options_apply_to_their_commands(void **state)
{
    (void)state;
    char dir[1100];
    snprintf(dir, sizeof dir, "%s", tu_scratch("opt-apply"));
    const char *cases[][2] = {
        {"merge --jobs 2 --out %s/m %s/none", "ppbench merge: --jobs does not apply"},
        {"merge --device 0 --out %s/m %s/none", "ppbench merge: --device does not apply"},
        {"devices --out %s/x", "ppbench devices: --out does not apply"},
        {"devices --quiet", "ppbench devices: --quiet does not apply"},
        {"keys --set medium.g=0", "ppbench keys: --set does not apply"},
        {"run --jobs 2 --out %s/r /nonexistent/cfg.ini", "ppbench run: --jobs does not apply"},
        {"run --shard 1/2 --out %s/r /nonexistent/cfg.ini", "ppbench run: --shard does not apply"},
        {"run --yes --out %s/r /nonexistent/cfg.ini", "ppbench run: --yes does not apply"},
        {"mc-merge --shard 1/2 --out %s/m /nonexistent/cfg.ini %s/p",
         "ppbench mc-merge: --shard does not apply"},
        {"mc-shard --jobs 2 --out %s/m /nonexistent/cfg.ini", "ppbench mc-shard: --jobs does not"},
        {"report --device 0 %s/study case", "ppbench report: --device does not apply"},
        {"devices extra", "ppbench devices: unexpected argument 'extra'"},
        {"keys extra", "ppbench keys: unexpected argument 'extra'"},
    };
    char args[3000];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        snprintf(args, sizeof args, cases[i][0], dir, dir);
        cli_expect(args, 2, cases[i][1]);
    }
    /* Nothing was made by the refused commands. */
    assert_false(exists(strcat(strcpy(args, dir), "/m")));
}

/* `ppbench CMD --help` was an error for every command ("--help: unknown option", exit 2); it
 * prints that command's usage (synopsis, the options that apply, one example) with exit 0, and
 * lists no option the command refuses. */
static void test_command_help(void **state)
{
    (void)state;
    const struct {
        const char *cmd, *has[4], *lacks;
    } cases[] = {
        {"run",
         {"usage: ppbench run [options] CONFIG...", "--device SEL", "--set", "--out"},
         "--jobs"},
        {"sweep", {"usage: ppbench sweep", "--jobs J", "--shard I/N", "--yes"}, NULL},
        {"merge", {"usage: ppbench merge --out DIR SHARD_DIR...", "--out DIR"}, "--jobs"},
        {"mc-shard", {"usage: ppbench mc-shard --out DIR", "--shard I/N", "--device"}, "--jobs"},
        {"mc-merge", {"usage: ppbench mc-merge --out DIR", "CONFIG SHARD_DIR..."}, "--device"},
        {"devices", {"usage: ppbench devices\n"}, "--out"},
        {"keys", {"usage: ppbench keys\n"}, "--set"},
        {"perf", {"usage: ppbench perf [options]", "--device SEL"}, "--out"},
        {"report", {"usage: ppbench report STUDY_DIR CASE..."}, "--out"},
        {"version", {"usage: ppbench version"}, "--out"},
    };
    char args[256], want[256];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *forms[] = {"%s --help", "%s -h", "help %s"};
        for (size_t f = 0; f < 3; f++) {
            snprintf(args, sizeof args, forms[f], cases[i].cmd);
            snprintf(want, sizeof want, "example:\n  ");
            cli_expect(args, 0, want);
            snprintf(want, sizeof want, "\n  %sppbench %s",
                     !strcmp(cases[i].cmd, "devices") ? "PPBENCH_DEVICE=pthread " : "",
                     cases[i].cmd);
            cli_expect(args, 0, want); /* the example runs this command */
            for (int k = 0; k < 4 && cases[i].has[k]; k++)
                cli_expect(args, 0, cases[i].has[k]);
            if (cases[i].lacks && strstr(cli_out, cases[i].lacks))
                fail_msg("ppbench %s lists '%s':\n%s", args, cases[i].lacks, cli_out);
        }
    }
    /* --help wins over missing operands: `merge --help` alone is not a usage error. */
    cli_expect("merge --help", 0, "usage: ppbench merge");
    if (strstr(cli_out, "ppbench merge: usage"))
        fail_msg("merge --help also ran merge:\n%s", cli_out);
    cli_expect("help frobnicate", 2, "frobnicate: unknown command");
}

/* `ppbench --version` and `ppbench version` print the version the Makefile passed as
 * PPB_VERSION; the build writes the same string to version.txt beside the binary. */
static void test_version(void **state)
{
    (void)state;
    const char *bin = getenv("PPBENCH");
    char path[1200], version[256] = "", want[300];
    const char *file = getenv("PPB_VERSION_FILE"); /* make unit names it: $(BUILD)/version.txt */
    if (file) {
        snprintf(path, sizeof path, "%s", file);
    } else { /* else beside the binary, as when BIN is inside the build directory */
        snprintf(path, sizeof path, "%s", bin ? bin : "build/ppbench");
        char *slash = strrchr(path, '/');
        assert_non_null(slash);
        snprintf(slash + 1, sizeof path - (size_t)(slash + 1 - path), "version.txt");
    }
    FILE *f = fopen(path, "r");
    if (!f)
        fail_msg("cannot read %s (written by the build)", path);
    assert_non_null(fgets(version, sizeof version, f));
    fclose(f);
    snprintf(want, sizeof want, "ppbench %s", version); /* version ends in '\n' */
    cli_expect("--version", 0, want);
    cli_expect("version", 0, want);
    assert_string_equal(cli_out, want);
    cli_expect("version --out x", 2, "ppbench version: --out does not apply");
}

/* A bad --device was found only at the first OpenCL use (exit 1 after the CPU methods had
 * run) and was ignored when no method needed OpenCL (mp alone ran, exit 0); it is resolved
 * right after parsing: exit 2, naming --device or $PPBENCH_DEVICE, nothing written. */
static void test_bad_device_before_work(void **state)
{
    (void)state;
    const char *p = cheap_config("opt-dev", "");
    char dir[1100];
    snprintf(dir, sizeof dir, "%s", tu_scratch("opt-dev-out"));
    char args[3000];
    snprintf(args, sizeof args, "run --quiet --device no-such-device-xyz --out %s/a %s", dir, p);
    cli_expect(args, 2, "--device no-such-device-xyz: no device name contains it");
    snprintf(args, sizeof args, "run --quiet --device 999 --out %s/a %s", dir, p);
    cli_expect(args, 2, "--device 999: no such device");
    snprintf(args, sizeof args, "run --quiet --out %s/a %s", dir, p);
    cli_expect_env("PPBENCH_DEVICE=no-such-device-xyz", args, 2,
                   "$PPBENCH_DEVICE no-such-device-xyz: no device name contains it");
    snprintf(args, sizeof args, "mc-shard --quiet --device no-such-device-xyz --out %s/a %s", dir,
             p);
    cli_expect(args, 2, "--device no-such-device-xyz");
    snprintf(args, sizeof args, "sweep --quiet --device no-such-device-xyz --out %s/a %s", dir, p);
    cli_expect(args, 2, "--device no-such-device-xyz");
    char out[1200];
    snprintf(out, sizeof out, "%s/a", dir);
    if (exists(out))
        fail_msg("%s was written before the device was refused", out);
    /* A good selector still runs (device 0 exists wherever the suite runs: test_cli lists it). */
    snprintf(args, sizeof args, "run --quiet --device 0 --out %s/a %s", dir, p);
    cli_expect(args, 0, "");
    /* `devices` is how one finds a selector: a bad $PPBENCH_DEVICE does not stop it. */
    cli_expect_env("PPBENCH_DEVICE=no-such-device-xyz", "devices", 0, "0: ");
}

/* --out naming an existing file: the old binary traced every photon and failed (exit 1) when
 * it came to write; now exit 2 before any work, for every command that writes a directory. */
static void test_out_is_a_file(void **state)
{
    (void)state;
    char dir[1100];
    snprintf(dir, sizeof dir, "%s", tu_scratch("opt-file"));
    char file[1200], args[4000];
    snprintf(file, sizeof file, "%s/plain", dir);
    FILE *f = fopen(file, "w");
    assert_non_null(f);
    fputs("not a directory\n", f);
    fclose(f);
    char cfg[1200];
    snprintf(cfg, sizeof cfg, "%s", cheap_config("opt-file-cfg", ""));
    const char *cmds[] = {"run --quiet --set experiment.methods=mc --set mc.photons=1e5 "
                          "--out %s %s",
                          "run --quiet --out %s/sub %s",
                          "sweep --quiet --out %s %s",
                          "mc-shard --quiet --out %s %s",
                          "mc-merge --out %s %s /nonexistent/p1",
                          "merge --out %s /nonexistent/p1"};
    for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
        snprintf(args, sizeof args, cmds[i], file, cfg);
        cli_expect(args, 2, "is not a directory");
        cli_expect(args, 2, "--out ");
    }
    /* An [output] dir from the config is checked the same way, named as the config's. */
    snprintf(args, sizeof args, "%s", cheap_config("opt-file-dir", ""));
    f = fopen(args, "a");
    assert_non_null(f);
    fprintf(f, "\n[output]\ndir = %s\n", file);
    fclose(f);
    char run[4100];
    snprintf(run, sizeof run, "run --quiet %s", args);
    cli_expect(run, 2, ": [output] dir ");
    cli_expect(run, 2, "is not a directory");
}

/* Every config is loaded and checked before the first runs: with `run a.ini b.ini`, b's error
 * appeared after a had been computed and written. */
static void test_all_configs_checked_first(void **state)
{
    (void)state;
    char dir[1100];
    snprintf(dir, sizeof dir, "%s", tu_scratch("opt-two"));
    char a[1200], b[1200], args[4000], out_a[1200];
    snprintf(out_a, sizeof out_a, "%s/a", dir);
    char extra[1300];
    snprintf(extra, sizeof extra, "\n[output]\ndir = %s\n", out_a);
    snprintf(a, sizeof a, "%s", cheap_config("opt-two-a", extra));
    snprintf(b, sizeof b, "%s", cli_config("opt-two-b", "[medium]\nalbedo = 2\n"));
    snprintf(args, sizeof args, "run --quiet %s %s", a, b);
    cli_expect(args, 2, ":2: [medium] albedo: 2 is out of range");
    if (exists(out_a))
        fail_msg("%s was computed before %s was found bad", out_a, b);
}

/* Two configs never share one output directory: `run --out D a.ini b.ini` wrote the second
 * over the first, and so did two configs naming the same [output] dir. */
static void test_two_configs_one_out(void **state)
{
    (void)state;
    char dir[1100];
    snprintf(dir, sizeof dir, "%s", tu_scratch("opt-share"));
    char a[1200], b[1200], args[4000], out[1200], extra[1300];
    snprintf(out, sizeof out, "%s/d", dir);
    snprintf(a, sizeof a, "%s", cheap_config("opt-share-a", ""));
    snprintf(b, sizeof b, "%s", cheap_config("opt-share-b", ""));
    snprintf(args, sizeof args, "run --quiet --out %s %s %s", out, a, b);
    cli_expect(args, 2, "2 configs would share it");
    if (exists(out))
        fail_msg("%s was written though two configs were refused", out);
    snprintf(extra, sizeof extra, "\n[output]\ndir = %s\n", out);
    snprintf(a, sizeof a, "%s", cheap_config("opt-share-c", extra));
    snprintf(extra, sizeof extra, "\n[output]\ndir = %s/\n", out);
    snprintf(b, sizeof b, "%s", cheap_config("opt-share-d", extra));
    snprintf(args, sizeof args, "run --quiet %s %s", a, b);
    cli_expect(args, 2, "two configs never share one output directory");
    if (exists(out))
        fail_msg("%s was written though two configs were refused", out);
    /* Each its own directory: both run. */
    snprintf(extra, sizeof extra, "\n[output]\ndir = %s/e\n", dir);
    snprintf(b, sizeof b, "%s", cheap_config("opt-share-e", extra));
    snprintf(args, sizeof args, "run --quiet %s %s", a, b);
    cli_expect(args, 0, "");
    snprintf(args, sizeof args, "%s/radiance.csv", out);
    assert_true(exists(args));
    snprintf(args, sizeof args, "%s/e/radiance.csv", dir);
    assert_true(exists(args));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_integers_are_strict),
        cmocka_unit_test(test_out_too_long),
        cmocka_unit_test(test_many_sets),
        cmocka_unit_test(test_options_apply_to_their_commands),
        cmocka_unit_test(test_command_help),
        cmocka_unit_test(test_version),
        cmocka_unit_test(test_bad_device_before_work),
        cmocka_unit_test(test_out_is_a_file),
        cmocka_unit_test(test_all_configs_checked_first),
        cmocka_unit_test(test_two_configs_one_out),
    };
    return cmocka_run_group_tests_name("options", tests, NULL, NULL);
}
