/* The command line's error paths and exit codes (documented in `ppbench --help` and the README):
 * 0 success, 1 run failure, 2 bad command line or config. Runs the built binary ($PPBENCH). */
#include "testutil.h"

#include <sys/wait.h>

/* Runs ppbench with args, captures stdout+stderr into out, returns the exit code. */
static int run(const char *args, char *out, size_t cap)
{
    const char *bin = getenv("PPBENCH");
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s %s 2>&1", bin ? bin : "./ppbench", args);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = fread(out, 1, cap - 1, p);
    out[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static char buf[65536];

static void expect(const char *args, int code, const char *needle)
{
    int rc = run(args, buf, sizeof buf);
    if (rc != code || !strstr(buf, needle))
        fail_msg("ppbench %s: exit %d (want %d), output lacks '%s':\n%s", args, rc, code, needle,
                 buf);
}

static const char *config(const char *name, const char *text)
{
    static char path[1200];
    snprintf(path, sizeof path, "%s/%s.ini", tu_scratch(name), name);
    FILE *f = fopen(path, "w");
    fputs(text, f);
    fclose(f);
    return path;
}

static void test_help_and_usage(void **state)
{
    (void)state;
    expect("--help", 0, "examples:");
    expect("--help", 0, "exit codes:");
    expect("", 2, "usage: ppbench");
    expect("frobnicate", 2, "frobnicate: unknown command");
    expect("run", 2, "no config given");
    expect("run --bogus x.ini", 2, "--bogus: unknown option");
    expect("sweep --shard 4/3 x.ini", 2, "--shard 4/3: expected I/N");
}

static void test_config_errors(void **state)
{
    (void)state;
    char args[1400];
    expect("run /nonexistent/a.ini", 2, "/nonexistent/a.ini: cannot open config");
    const char *p = config("cli-bad", "[medium]\nalbedo = 2\n");
    snprintf(args, sizeof args, "run %s", p);
    expect(args, 2, ":2: [medium] albedo: 2 is out of range [0, 1]");
    p = config("cli-list", "[medium]\ng = 0, 0.5\n");
    snprintf(args, sizeof args, "run %s", p);
    expect(args, 2, "use `ppbench sweep`");
    p = config("cli-set", "[experiment]\nmethods = mp\n");
    snprintf(args, sizeof args, "run --set medium.g %s", p);
    expect(args, 2, "expected SECTION.KEY=VALUE");
    snprintf(args, sizeof args, "run --set medium.gg=1 %s", p);
    expect(args, 2, "--set medium.gg: unknown key");
}

/* The method ids are checked by the registry on every path that loads a config (run, sweep,
 * mc-shard, mc-merge), before any work, with exit code 2; the expected text is the config's
 * own line and ids. */
static void test_method_errors(void **state)
{
    (void)state;
    const char *cmds[] = {"run", "sweep", "mc-shard --out /nonexistent-dir/x",
                          "mc-merge --out /nonexistent-dir/x"};
    char args[1400], want[1400], path[1200];
    for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
        snprintf(path, sizeof path, "%s",
                 config("cli-unknown", "[experiment]\nmethods = mc, xx\n"));
        snprintf(args, sizeof args, "%s %s%s", cmds[i], path, i == 3 ? " /nonexistent-dir/p" : "");
        snprintf(want, sizeof want,
                 "ppbench: %s:2: [experiment] methods: unknown method 'xx' (see ppbench --help)\n",
                 path);
        expect(args, 2, want);
        snprintf(path, sizeof path, "%s",
                 config("cli-slabonly", "[experiment]\nname = a\n\nmethods = ppslab\n"));
        snprintf(args, sizeof args, "%s %s%s", cmds[i], path, i == 3 ? " /nonexistent-dir/p" : "");
        snprintf(want, sizeof want,
                 "ppbench: %s:4: [experiment] methods: method 'ppslab' runs in slab mode only\n",
                 path);
        expect(args, 2, want);
    }
    snprintf(path, sizeof path, "%s", config("cli-tube", "[tube]\nwidth = 5\n"));
    snprintf(args, sizeof args, "run --set experiment.methods=mc,zz %s", path);
    expect(args, 2,
           "ppbench: --set experiment.methods: unknown method 'zz' (see ppbench --help)\n");
    snprintf(args, sizeof args, "run --set experiment.methods=ppslab %s", path);
    expect(args, 2, "ppbench: --set experiment.methods: method 'ppslab' runs in slab mode only\n");
}

/* "Did you mean" (docs/reference.md: Keys, Exit codes): a mistyped key, section or method id is
 * refused as before (exit 2, file:line: [section] key: reason, or --set section.key: reason)
 * with the nearest known name added when one is close. Expected names: the key table
 * (`ppbench keys`: light.theta_deg, mc.photons, medium.albedo) and the method ids of
 * `ppbench --help` (pp, mp+ss, rte2d); "theta" is a prefix of theta_deg, the others 1 or 2
 * edits away; "zz" is 2 edits from every key of [medium] (none longer than 2 is that close),
 * so nothing is suggested. */
static void test_did_you_mean(void **state)
{
    (void)state;
    char args[1400], want[1400], path[1200];
    snprintf(path, sizeof path, "%s", config("cli-dym", "[tube]\nwidth = 5\n"));
    snprintf(args, sizeof args, "run --set light.theta=3 %s", path);
    expect(args, 2, "ppbench: --set light.theta: unknown key (did you mean light.theta_deg?)\n");
    snprintf(args, sizeof args, "run --set mc.photon=3 %s", path);
    expect(args, 2, "ppbench: --set mc.photon: unknown key (did you mean mc.photons?)\n");
    snprintf(args, sizeof args, "run --set tube.photons=3 %s", path);
    expect(args, 2, "ppbench: --set tube.photons: unknown key (did you mean mc.photons?)\n");
    snprintf(args, sizeof args, "run --set ligth.theta_deg=3 %s", path);
    expect(args, 2,
           "ppbench: --set ligth.theta_deg: unknown section (did you mean light.theta_deg?)\n");
    snprintf(args, sizeof args, "run --set medium.zz=3 %s", path);
    expect(args, 2, "ppbench: --set medium.zz: unknown key\n");
    snprintf(args, sizeof args, "run --set experiment.methods=mc,ppp %s", path);
    expect(args, 2,
           "ppbench: --set experiment.methods: unknown method 'ppp' (did you mean pp? see "
           "ppbench --help)\n");
    snprintf(args, sizeof args, "run --set experiment.methods=mc,mp_ss %s", path);
    expect(args, 2, "unknown method 'mp_ss' (did you mean mp+ss? see ppbench --help)\n");
    snprintf(path, sizeof path, "%s", config("cli-dym", "[medium]\n\nalbdo = 0.9\n"));
    snprintf(args, sizeof args, "run %s", path);
    snprintf(want, sizeof want,
             "ppbench: %s:3: [medium] albdo: unknown key (did you mean albedo?)\n", path);
    expect(args, 2, want);
    snprintf(path, sizeof path, "%s", config("cli-dym", "[ligth]\ntheta_deg = 3\n"));
    snprintf(args, sizeof args, "run %s", path);
    snprintf(want, sizeof want,
             "ppbench: %s:2: [ligth] theta_deg: unknown section (did you mean [light] "
             "theta_deg?)\n",
             path);
    expect(args, 2, want);
    snprintf(path, sizeof path, "%s", config("cli-dym", "[experiment]\nmethods = mc, rte3d\n"));
    snprintf(args, sizeof args, "run %s", path);
    snprintf(want, sizeof want,
             "ppbench: %s:2: [experiment] methods: unknown method 'rte3d' (did you mean rte2d? "
             "see ppbench --help)\n",
             path);
    expect(args, 2, want);
}

static void test_devices_and_keys(void **state)
{
    (void)state;
    expect("devices", 0, "0: ");
    expect("keys", 0, "| mc | photons |");
    /* configs/README.md documents every key: it must hold the table `ppbench keys` prints
     * (the source of both is the key table in src/model/config.c). */
    char cmd[1400];
    const char *b = getenv("PPBENCH");
    snprintf(cmd, sizeof cmd,
             "%s keys | while IFS= read -r l; do grep -qxF -- \"$l\" configs/README.md || "
             "{ echo \"configs/README.md lacks: $l\"; exit 1; }; done",
             b ? b : "./ppbench");
    assert_int_equal(system(cmd), 0);
    expect("run --device no-such-device-xyz --quiet --set experiment.methods=mc "
           "--set mc.photons=1000 --out /nonexistent-dir/x configs/uniform_g0_normal.ini",
           2, "--device no-such-device-xyz: no device name contains it");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_help_and_usage),   cmocka_unit_test(test_config_errors),
        cmocka_unit_test(test_method_errors),    cmocka_unit_test(test_did_you_mean),
        cmocka_unit_test(test_devices_and_keys),
    };
    return cmocka_run_group_tests_name("cli", tests, NULL, NULL);
}
