/* Hostile and mistaken input to the config reader and the sweep grid (part "input"):
 * each test reproduces a defect of the earlier code and checks the fixed behaviour. Bad input
 * is refused before any work starts, with exit code 2 and a message naming file:line: [section]
 * key (or the --set option). Expected values are the literal text of each config (its lines,
 * keys and values), IEEE 754 facts (integers are exact in a double below 2^53) and the limits
 * of model/grid.h. The command-line tests run the built binary ($PPBENCH), under a KILL timeout
 * where the earlier code hung. */
#include "cliutil.h"

#include <sys/stat.h>

#include "model/config.h"
#include "model/grid.h"

static ppb_config cfg;

/* Writes n bytes to <scratch of name>/<name>.ini (text may hold NUL bytes). */
static const char *write_bytes(const char *name, const char *text, size_t n)
{
    static char path[1200];
    snprintf(path, sizeof path, "%s/%s.ini", tu_scratch(name), name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, n, f), n);
    fclose(f);
    return path;
}

/* A string literal, NUL bytes included. */
#define LIT(name, s) write_bytes(name, s, sizeof(s) - 1)

/* The config must be refused with a message holding needle and its path. */
static void expect_refused(const char *path, const char *needle)
{
    ppb_err err = {{0}};
    if (ppb_config_load(&cfg, path, &err) != -1)
        fail_msg("%s was accepted (want '%s')", path, needle);
    if (!strstr(err.msg, needle) || !strstr(err.msg, path))
        fail_msg("error '%s' lacks '%s' or the path", err.msg, needle);
}

/* A message never carries a raw byte outside printable ASCII. */
static void assert_printable(const char *msg)
{
    for (const unsigned char *c = (const unsigned char *)msg; *c; c++)
        if ((*c < 0x20 && *c != '\n') || *c >= 0x7f)
            fail_msg("message holds raw byte 0x%02x: '%s'", *c, msg);
}

/* A copy of a study config with one line replaced (sed expression), for the CLI tests. */
static const char *study_copy(const char *name, const char *sed)
{
    static char path[1200];
    snprintf(path, sizeof path, "%s/%s.ini", tu_scratch(name), name);
    char cmd[3000];
    snprintf(cmd, sizeof cmd, "sed '%s' '%s/configs/density_step.ini' > '%s'", sed, PPB_SOURCE_DIR,
             path);
    assert_int_equal(system(cmd), 0);
    return path;
}

/* 1. The first error is reported under its own key (the handler used to overwrite the key it
 * reported with the file's last one: "[output] dir"), and reading stops there. density_step.ini
 * holds `g = 0` on line 12 and `albedo = 0.95` on line 11. */
static void test_first_error_names_its_key(void **state)
{
    (void)state;
    char args[3000];
    const char *p = study_copy("gg", "s/^g = 0$/gg = 0/");
    snprintf(args, sizeof args, "run --quiet --out /nonexistent/never '%s'", p);
    cli_expect(args, 2, ":12: [medium] gg: unknown key");
    p = study_copy("albedo15", "s/^albedo = 0.95$/albedo = 1.5/");
    snprintf(args, sizeof args, "run --quiet --out /nonexistent/never '%s'", p);
    cli_expect(args, 2, ":11: [medium] albedo: 1.5 is out of range [0, 1]");
    /* Two errors: the first is the one reported, a syntax error as well as a key error. */
    expect_refused(LIT("two", "[medium]\ng = 5\n[tube]\nwidth = -1\n"),
                   ":2: [medium] g: 5 is out of range");
    expect_refused(LIT("syn", "[medium]\ng\nalbedo = 2\n"), ":2: syntax error");
}

/* 2. Files that are no config: refused up front with exit 2. A directory used to run the whole
 * default experiment (exit 0); /dev/zero, /dev/urandom and a FIFO used to hang (and ignore
 * SIGTERM): the earlier binary is killed by the timeout here (exit 137). */
static void test_not_a_regular_file(void **state)
{
    (void)state;
    const char *dir = tu_scratch("cfgdir");
    char args[3000];
    snprintf(args, sizeof args, "run --quiet --set mc.photons=1000 --out '%s/out' '%s'", dir, dir);
    cli_expect_env("timeout -s KILL 20", args, 2, "is a directory, not a config file");
    cli_expect_env("timeout -s KILL 10", "run --quiet --out /nonexistent/x /dev/zero", 2,
                   "/dev/zero: not a regular file");
    cli_expect_env("timeout -s KILL 10", "sweep --quiet --out /nonexistent/x /dev/urandom", 2,
                   "/dev/urandom: not a regular file");
    char fifo[1200];
    snprintf(fifo, sizeof fifo, "%s/fifo.ini", tu_scratch("cfgfifo"));
    assert_int_equal(mkfifo(fifo, 0600), 0);
    snprintf(args, sizeof args, "run --quiet --out /nonexistent/x '%s'", fifo);
    cli_expect_env("timeout -s KILL 10", args, 2, "not a regular file");
}

/* 2. Lines of any length: inih's 200-byte line buffer cut a long line in two and shifted every
 * line number after it. Comments of any length are skipped; a line still too long is an error
 * naming its line. */
static void test_long_lines(void **state)
{
    (void)state;
    char text[2000], pad[601];
    memset(pad, 'x', 600);
    pad[600] = '\0';
    /* Line 1 a long comment, line 3 a long inline comment, line 4 out of range. */
    snprintf(text, sizeof text, "; %s\n[medium]\nalbedo = 0.5 ; %s\ng = 7\n", pad, pad);
    expect_refused(write_bytes("longc", text, strlen(text)), ":4: [medium] g: 7 is out of range");
    /* The same without the error: the values and the line of each key are the file's. */
    snprintf(text, sizeof text, "; %s\n[medium]\nalbedo = 0.5 ; %s\n# %s\ng = 0.25\n", pad, pad,
             pad);
    const char *p = write_bytes("longok", text, strlen(text));
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    assert_true(cfg.scene.albedo == 0.5 && cfg.scene.g == 0.25);
    char want[1400];
    ppb_config_key_fail(&cfg, "medium", "g", &err, "x");
    snprintf(want, sizeof want, "%s:5: [medium] g: x", p);
    assert_string_equal(err.msg, want);
    /* A 100 KB value: a clear error on its line, the value not echoed. */
    size_t n = 100 * 1024;
    char *big = malloc(n + 64);
    assert_non_null(big);
    int head = snprintf(big, 64, "[medium]\n\ng = ");
    memset(big + head, '1', n);
    big[head + n] = '\n';
    p = write_bytes("bigvalue", big, (size_t)head + n + 1);
    free(big);
    expect_refused(p, ":3: a line of 102404 characters (without comments); a line holds at most");
}

/* 2. NUL bytes and binary data: a NUL after a value was ignored (inih saw "g = 0.5"), and
 * garbage was echoed raw into the terminal. Now: an error naming the line, escaped text. */
static void test_binary_input(void **state)
{
    (void)state;
    expect_refused(LIT("nul", "[medium]\ng = 0.5\0junk\n"), ":2: a NUL byte");
    expect_refused(LIT("ctl", "[medium]\n\ng = \x1b[2J0.5\n"), ":3: control character \\x1b");
    /* Bytes above 0x7f may be UTF-8 text (in a comment, say): quoted escaped. */
    ppb_err err = {{0}};
    const char *p = LIT("hi", "; caf\xc3\xa9\n[medium]\n\xff\xfe = 1\n");
    assert_int_equal(ppb_config_load(&cfg, p, &err), -1);
    assert_non_null(strstr(err.msg, ":3: [medium] \\xff\\xfe: unknown key"));
    assert_printable(err.msg);
    /* 4 KB of pseudo-random bytes (a fixed LCG, Numerical Recipes' constants). */
    char junk[4096];
    unsigned state32 = 12345;
    for (size_t i = 0; i < sizeof junk; i++) {
        state32 = state32 * 1664525u + 1013904223u;
        junk[i] = (char)(state32 >> 24);
    }
    p = write_bytes("junk", junk, sizeof junk);
    assert_int_equal(ppb_config_load(&cfg, p, &err), -1);
    assert_printable(err.msg);
    /* Through the binary too (the message is what reaches the terminal). */
    char args[3000];
    snprintf(args, sizeof args, "run --quiet --out /nonexistent/x '%s'", p);
    cli_expect(args, 2, p);
    assert_printable(cli_out);
    /* A right-to-left override (U+202E, UTF-8 e2 80 ae) in a name or a method id: refused, shown
     * escaped (it reversed the rest of the line on a terminal). */
    p = LIT("rlo", "[experiment]\nname = a\xe2\x80\xae"
                   "b\n");
    assert_int_equal(ppb_config_load(&cfg, p, &err), -1);
    assert_non_null(strstr(err.msg, ":2: [experiment] name: 'a\\xe2\\x80\\xaeb' may hold only"));
    assert_printable(err.msg);
    p = LIT("rlo_m", "[experiment]\nmethods = mp, x\xe2\x80\xae\n");
    assert_int_equal(ppb_config_load(&cfg, p, &err), -1);
    assert_non_null(strstr(err.msg, ":2: [experiment] methods: method id 'x\\xe2\\x80\\xae'"));
    assert_printable(err.msg);
    /* A value given through --set is quoted escaped as well. */
    assert_int_equal(ppb_config_load(&cfg, LIT("plain", "[medium]\n"), &err), 0);
    assert_int_equal(ppb_config_set(&cfg, "medium", "g", "\x1b]0;title\x07", &err), -1);
    assert_non_null(strstr(err.msg, "'\\x1b]0;title\\x07' is not a number"));
    assert_printable(err.msg);
}

/* Memory that cannot be had (base/memory.h) is an error that names it, exit 1, within moments:
 * under ulimit -v 100000 (100 MB) the earlier code spun in OpenBLAS's allocator for ever, deaf
 * to SIGTERM (killed by the timeout: exit 137), and under 300 MB it said "OpenCL: no platform
 * found". The limits are below what the run needs on any machine (OpenBLAS's buffer alone is
 * 134 MB); the message is base/memory.h's. */
static void test_memory_exhaustion(void **state)
{
    (void)state;
    const char *p = LIT("mem", "[experiment]\nmethods = pp\n[tube]\nsegments_top = 8\n"
                               "segments_side = 3\n[bins]\ntheta = 2\nphi = 2\n");
    char args[3000], out[1200];
    snprintf(out, sizeof out, "%s/out", tu_scratch("mem_out"));
    snprintf(args, sizeof args, "run --out %s %s", out, p);
    cli_expect_env("ulimit -v 100000; timeout -k 5 120", args, 1,
                   "out of memory: the linear-algebra library's (OpenBLAS) work buffer needs");
    int rc = cli_run_env("ulimit -v 300000; timeout -k 5 120", args, cli_out, sizeof cli_out);
    if (strstr(cli_out, "no platform found") || (rc != 0 && !strstr(cli_out, "out of memory")))
        fail_msg("under 300 MB: exit %d:\n%s", rc, cli_out);
}

/* 3. The point count: a grid over PPB_GRID_MAX_POINTS is refused at load, --yes or not (at the
 * axis that crosses it). 1e12 points with --yes hung in the sweep's grid check (killed by the
 * timeout: exit 137); 8 axes of 256 values (2^64 points) overflowed the count (signed overflow) and
 * were accepted without
 * --yes. The third axis of 256 values makes 2^24 > 1e7 points. */
static void test_grid_point_limit(void **state)
{
    (void)state;
    const char *dir = tu_scratch("huge");
    char text[1600], args[3000];
    snprintf(text, sizeof text,
             "[tube]\nwidth = 1:1000:1\nheight = 1:1000:1\n[medium]\nsigma_t = 1:1000:1\n"
             "[mc]\nseed = 1:1000:1\n[output]\ndir = %s/out\n",
             dir);
    const char *p = cli_config("huge", text);
    snprintf(args, sizeof args, "sweep --quiet --yes '%s'", p);
    cli_expect_env("timeout -s KILL 20", args, 2,
                   ":5: [medium] sigma_t: 1000 values make a grid of 1000000000 points, over the "
                   "hard limit of 10000000 (--yes does not lift it)");
    snprintf(text, sizeof text,
             "[tube]\nwidth = 1:256:1\nheight = 1:256:1\n[medium]\nsigma_t = 1:256:1\n"
             "g = 0:0.255:0.001\n[light]\ntheta_deg = 0:25.5:0.1\n[mc]\nphotons = 1:256:1\n"
             "seed = 0:255:1\n[pp]\ndirections = 2:257:1\n[output]\ndir = %s/out\n",
             dir);
    p = cli_config("axes8", text);
    snprintf(args, sizeof args, "sweep --quiet '%s'", p);
    cli_expect_env("timeout -s KILL 20", args, 2,
                   ":5: [medium] sigma_t: 256 values make a grid of 16777216 points");
    /* At the limit itself: 10 x 1000 x 1000 points load, and the count is exact. */
    ppb_grid *grid = ppb_grid_new();
    assert_non_null(grid);
    ppb_err err = {{0}};
    p = cli_config("atlimit", "[tube]\nwidth = 1:10:1\nheight = 1:1000:1\n[medium]\n"
                              "sigma_t = 0.5:500:0.5\n");
    assert_int_equal(ppb_config_load_grid(&cfg, grid, p, &err), 0);
    assert_true(ppb_grid_npoints(grid) == PPB_GRID_MAX_POINTS);
    ppb_grid_free(grid);
}

static void expect_grid_error(const char *name, const char *text, const char *needle)
{
    ppb_grid *grid = ppb_grid_new();
    assert_non_null(grid);
    const char *p = cli_config(name, text);
    ppb_err err = {{0}};
    int rc = ppb_config_load_grid(&cfg, grid, p, &err);
    ppb_grid_free(grid);
    if (rc != -1)
        fail_msg("config '%s' was accepted (want '%s')", name, needle);
    if (!strstr(err.msg, needle) || !strstr(err.msg, p))
        fail_msg("error '%s' lacks '%s' or the path", err.msg, needle);
}

/* The values of the one axis a config makes. */
static int axis_values(const char *name, const char *text, double *vals, int cap)
{
    ppb_grid *grid = ppb_grid_new();
    assert_non_null(grid);
    ppb_err err = {{0}};
    if (ppb_config_load_grid(&cfg, grid, cli_config(name, text), &err))
        fail_msg("%s: %s", name, err.msg);
    assert_int_equal(grid->naxes, 1);
    int n = grid->axes[0].n;
    assert_true(n <= cap);
    memcpy(vals, grid->axes[0].values, (size_t)n * sizeof *vals);
    ppb_grid_free(grid);
    return n;
}

/* 3. Ranges: a tiny step overflowed the value count (reported as "empty value" or dropped);
 * generated values were not range-checked, and 0:1:0.3333333333333337 yielded
 * 1.0000000000000011 (3 x 0.3333333333333337 in binary64), refused only after three points had
 * run. The rule (configs/README.md): values start + i step up to stop, the last snapped to stop
 * when within 1e-9 step of it. */
static void test_ranges(void **state)
{
    (void)state;
    expect_grid_error("tiny", "[medium]\nalbedo = 0:1:1e-19\n",
                      ":2: [medium] albedo: range 0:1:1e-19 has more than 1024 values");
    expect_grid_error("tiny2", "[medium]\ng = 0, 0.5, 0:0.9:1e-300\n",
                      "range 0:0.9:1e-300 has more than 1024 values");
    double v[PPB_MAX_LIST];
    int n = axis_values("third", "[medium]\nalbedo = 0:1:0.3333333333333337\n", v, PPB_MAX_LIST);
    assert_int_equal(n, 4);
    assert_true(v[3] == 1.0); /* snapped: 1.0000000000000011 before */
    assert_true(v[1] == 0.3333333333333337);
    /* Snapped from below as well: 3 x 0.3 is 0.8999999999999999 in binary64. */
    n = axis_values("below", "[medium]\ng = 0:0.9:0.3\n", v, PPB_MAX_LIST);
    assert_int_equal(n, 4);
    assert_true(v[3] == 0.9);
    /* Not snapped when the step lands far from stop: 0:1:0.3 ends at 0.9 (3 x 0.3). */
    n = axis_values("short", "[medium]\nalbedo = 0:1:0.3\n", v, PPB_MAX_LIST);
    assert_int_equal(n, 4);
    assert_true(v[3] == 3 * 0.3);
    /* The longest list: 1024 values, all in range. */
    n = axis_values("max", "[medium]\nalbedo = 0:1:0.0009775171065493646\n", v, PPB_MAX_LIST);
    assert_int_equal(n, 1024);
    assert_true(v[1023] == 1.0);
}

/* 4. --set: a list given through --set was blamed on the file ("x.ini: keys hold lists"); the
 * overrides were checked one by one, so their order mattered; a conflict named only one side.
 * `sweep` on a config without lists stops with "nothing to sweep" once the config is accepted. */
static void test_set_overrides(void **state)
{
    (void)state;
    char args[3000];
    const char *out = tu_scratch("set-out");
    const char *p = cli_config("setlist", "[experiment]\nmethods = mp\n");
    snprintf(args, sizeof args, "run --quiet --out /nonexistent/x --set medium.g=0,0.5 '%s'", p);
    cli_expect(args, 2, "--set medium.g: holds a list (a sweep): use `ppbench sweep`");
    /* A list in the file is named at its line. */
    p = cli_config("filelist", "[experiment]\nmethods = mp\n[medium]\ng = 0, 0.5\n");
    snprintf(args, sizeof args, "run --quiet --out /nonexistent/x '%s'", p);
    cli_expect(args, 2, ":4: [medium] g: holds a list (a sweep)");
    /* Order: slab with a step is refused only if it remains after every --set. */
    p = cli_config("order", "[medium]\nstep = density\n");
    snprintf(args, sizeof args,
             "sweep --quiet --out '%s' --set experiment.geometry=slab --set medium.step=none '%s'",
             out, p);
    cli_expect(args, 2, "nothing to sweep");
    snprintf(args, sizeof args,
             "sweep --quiet --out '%s' --set experiment.methods=ppslab --set "
             "experiment.geometry=slab '%s'",
             out, cli_config("order2", "[experiment]\n"));
    cli_expect(args, 2, "nothing to sweep");
    /* A conflict names both sides: the key it fails and where the other was set. */
    p = cli_config("conflict", "[tube]\nwidth = 6\n");
    snprintf(args, sizeof args,
             "sweep --quiet --out '%s' --set medium.step_x=4 --set medium.step=density '%s'", out,
             p);
    cli_expect(args, 2,
               "--set medium.step_x: the step must lie inside the tube (|step_x| < "
               "width / 2 = 3, width from line 2)");
    assert_null(strstr(cli_out, ":0:"));
    snprintf(args, sizeof args, "sweep --quiet --out '%s' --set experiment.geometry=slab '%s'", out,
             cli_config("conflict2", "[medium]\nstep = shadow\n"));
    cli_expect(args, 2,
               ":2: [medium] step: steps are refused in slab mode (docs/reference.md, Geometry; "
               "geometry = slab "
               "from --set experiment.geometry)");
    assert_null(strstr(cli_out, ":0:"));
}

/* 5. Integer keys are read as integers: a seed of 2^53 + 1 was read through a double and
 * became 2^53. Floating-point forms stay accepted below 2^53, where they are exact. */
static void test_integer_keys(void **state)
{
    (void)state;
    ppb_err err = {{0}};
    const char *p = cli_config("seed", "[mc]\nseed = 9007199254740993\nphotons = 1e7\n");
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    assert_true(cfg.mc.seed == 9007199254740993LL); /* 2^53 + 1 */
    assert_true(cfg.mc.photons == 10000000LL);
    assert_int_equal(ppb_config_set(&cfg, "mc", "seed", "9199999999999999999", &err), 0);
    assert_true(cfg.mc.seed == 9199999999999999999LL); /* the key's maximum is 9.2e18 */
    /* The resolved config (hashed for resume, recorded in provenance) keeps every digit. */
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    ppb_config_write_resolved(&cfg, f);
    fclose(f);
    assert_non_null(strstr(text, "mc.seed = 9199999999999999999\n"));
    free(text);
    /* Above 2^53 a floating-point form is not exact: refused. */
    assert_int_equal(ppb_config_set(&cfg, "mc", "seed", "9007199254740993.0", &err), -1);
    assert_non_null(strstr(err.msg, "--set mc.seed: '9007199254740993.0' is above 2^53"));
    assert_int_equal(ppb_config_set(&cfg, "mc", "seed", "1e19", &err), -1);
    assert_int_equal(ppb_config_set(&cfg, "mc", "seed", "99999999999999999999", &err), -1);
    assert_non_null(strstr(err.msg, "99999999999999999999 is out of range"));
    assert_int_equal(ppb_config_set(&cfg, "mc", "photons", "1234.5", &err), -1);
    assert_non_null(strstr(err.msg, "is not an integer"));
    /* A swept integer goes through the grid's doubles: below 2^53 only. */
    expect_grid_error("bigsweep", "[mc]\nseed = 1, 9007199254740993\n",
                      ":2: [mc] seed: a swept integer must be below 2^53");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_first_error_names_its_key),
        cmocka_unit_test(test_not_a_regular_file),
        cmocka_unit_test(test_long_lines),
        cmocka_unit_test(test_binary_input),
        cmocka_unit_test(test_memory_exhaustion),
        cmocka_unit_test(test_grid_point_limit),
        cmocka_unit_test(test_ranges),
        cmocka_unit_test(test_set_overrides),
        cmocka_unit_test(test_integer_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
