/* Methods from outside (docs/external.md), through the built binary ($PPBENCH):
 * - `ppbench scene` writes scene.json whose sample points and bins are the conventions' own:
 *   checked against kernels/ppb_conventions.h (the point count of the layout, the bin index of
 *   every averaging direction as the Monte Carlo tallies bin it, w_k summing to pi -- reference:
 * Bins: the bins cover the projected solid angle of the hemisphere, pi);
 * - an external method end to end: its command copies the rows of a built-in method (mp) from
 *   an earlier run under its own name, so every output of it (summary, rms, totals, images) must
 *   equal mp's -- mp's own rows are the expected values; without a totals.csv its R, T and sides
 *   are the radiance integrated (the cell measure, reference: Bins), which must give the Monte
 * Carlo's own R, T, sides when it copies the mc rows (energy per cell is what the tallies count);
 * - each bad output (missing row, duplicate, NaN, negative, wrong columns, non-zero exit,
 *   timeout) is refused with file:line or the reason, and none of its rows or images is written;
 *   on timeout the command's process group is gone.
 * Expected values come from the conventions' functions (an independent path: the tallies'
 * binning of a direction, not the writer's loop), from the bins' sum (reference: Bins), from a
 * built-in method's own outputs and from exit codes of README.md. Tiny grids: bookkeeping, not
 * physics. */
#include "cliutil.h"

#include <jansson.h>
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <time.h>

static json_t *load_json(const char *path)
{
    json_error_t je;
    json_t *doc = json_load_file(path, 0, &je);
    if (!doc)
        fail_msg("%s:%d: %s", path, je.line, je.text);
    return doc;
}

static double num(const json_t *obj, const char *key)
{
    json_t *v = json_object_get(obj, key);
    if (!json_is_number(v))
        fail_msg("no number '%s'", key);
    return json_number_value(v);
}

static void test_scene_json(void **state)
{
    (void)state;
    const char *dir = tu_scratch("scene");
    char args[2400], path[1200];
    snprintf(args, sizeof args,
             "scene --out %s/out --set bins.theta=3 --set bins.phi=5 --set bins.samples_dir=2 "
             "--set tube.segments_top=7 --set tube.segments_side=3 configs/uniform_g0_normal.ini",
             dir);
    cli_expect(args, 0, "");
    snprintf(path, sizeof path, "%s/out/scene.json", dir);
    json_t *doc = load_json(path);
    json_t *pts = json_object_get(doc, "sample_points");
    json_t *bins = json_object_get(doc, "bins");
    assert_int_equal(json_array_size(pts), 2 * 7 + 2 * 3);
    assert_int_equal(json_array_size(bins), 3 * 5);
    double wsum = 0.0;
    for (size_t i = 0; i < json_array_size(bins); i++) {
        json_t *b = json_array_get(bins, i);
        int index = (int)num(b, "index");
        assert_int_equal(index, (int)i); /* the order of radiance.csv's rows */
        wsum += num(b, "w_k");
        json_t *dirs = json_object_get(b, "directions");
        assert_int_equal(json_array_size(dirs), 2 * 2);
        /* One weight per direction; a bin's weights sum to n^2, its projected solid angle in
         * units of one midpoint sample's (reference: Bins). */
        json_t *wts = json_object_get(b, "weights");
        assert_int_equal(json_array_size(wts), 2 * 2);
        double ws = 0.0;
        for (size_t k = 0; k < json_array_size(wts); k++)
            ws += json_number_value(json_array_get(wts, k));
        assert_close(ws, 2.0 * 2.0, 1e-12);
        for (size_t k = 0; k < json_array_size(dirs); k++) {
            json_t *w = json_array_get(dirs, k);
            double n = json_number_value(json_array_get(w, 0));
            double t = json_number_value(json_array_get(w, 1));
            double z = json_number_value(json_array_get(w, 2));
            assert_close(n * n + t * t + z * z, 1.0, 1e-12);
            /* On S4 (n = +x, t = -y): the direction in world coordinates, binned as mc does. */
            assert_int_equal(ppb_dir_bin(PPB_S4, n, -t, z, 3, 5), index);
        }
    }
    assert_close(wsum, PPB_PI, 1e-12);
    /* Every point's frame: t = n x b with b = +z, i.e. t = (n_y, -n_x). */
    for (size_t i = 0; i < json_array_size(pts); i++) {
        json_t *p = json_array_get(pts, i);
        json_t *n = json_object_get(p, "normal"), *t = json_object_get(p, "tangent");
        assert_close(json_number_value(json_array_get(t, 0)),
                     json_number_value(json_array_get(n, 1)), 0);
        assert_close(json_number_value(json_array_get(t, 1)),
                     -json_number_value(json_array_get(n, 0)), 0);
    }
    json_t *first = json_array_get(pts, 0);
    assert_string_equal(json_string_value(json_object_get(first, "surface")), "S1");
    assert_close(num(first, "s"), -5.0 + 0.5 * 10.0 / 7,
                 1e-12); /* reference: Geometry, from x = -W/2 */
    json_decref(doc);
    /* The medium as the config sets it (the value given is the expected one). */
    snprintf(args, sizeof args,
             "scene --out %s/n --set experiment.methods=mc --set medium.n=1.4 --set medium.g=0.5 "
             "configs/uniform_g0_normal.ini",
             dir);
    cli_expect(args, 0, "");
    snprintf(path, sizeof path, "%s/n/scene.json", dir);
    doc = load_json(path);
    assert_close(num(json_object_get(doc, "medium"), "n"), 1.4, 0);
    assert_close(num(json_object_get(doc, "medium"), "g"), 0.5, 0);
    json_decref(doc);
    /* A bad config is refused before anything is written (exit 2, README). */
    snprintf(args, sizeof args,
             "scene --out %s/bad --set medium.albedo=2 "
             "configs/uniform_g0_normal.ini",
             dir);
    cli_expect(args, 2, "albedo");
    struct stat st;
    snprintf(path, sizeof path, "%s/bad", dir);
    assert_int_equal(stat(path, &st), -1);
}

/* The tiny experiment every test below builds on (seconds on a CPU). */
static const char tiny[] = "[tube]\nsegments_top = 8\nsegments_side = 3\n"
                           "[bins]\ntheta = 2\nphi = 2\n[mc]\nphotons = 20000\n";

static char ref_dir[1200]; /* a finished run of mc and mp, made once */

static int make_ref(void **state)
{
    (void)state;
    char text[2600], args[2600];
    snprintf(ref_dir, sizeof ref_dir, "%s/ref", tu_scratch("extref"));
    snprintf(text, sizeof text, "[experiment]\nmethods = mc, mp\n%s[output]\ndir = %s\n", tiny,
             ref_dir);
    snprintf(args, sizeof args, "run --quiet %s", cli_config("extref", text));
    return cli_run_env("", args, cli_out, sizeof cli_out) != 0;
}

/* Lines of dir/file whose first field is method, with that field dropped, joined. */
static char *rows_of(const char *dir, const char *file, const char *method)
{
    char path[1400];
    snprintf(path, sizeof path, "%s/%s", dir, file);
    FILE *f = fopen(path, "r");
    if (!f)
        fail_msg("cannot open %s", path);
    size_t cap = 1 << 20, n = 0, len = strlen(method);
    char *out = calloc(cap, 1), line[4096];
    assert_non_null(out);
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, method, len) && line[len] == ',' && n + strlen(line) < cap)
            n += (size_t)sprintf(out + n, "%s", line + len + 1);
    fclose(f);
    return out;
}

static void assert_same_rows(const char *dir, const char *file, const char *a, const char *b)
{
    char *ra = rows_of(dir, file, a), *rb = rows_of(dir, file, b);
    if (!*ra || strcmp(ra, rb) != 0)
        fail_msg("%s/%s: rows of %s differ from those of %s:\n%s\n---\n%s", dir, file, a, b, ra,
                 rb);
    free(ra);
    free(rb);
}

static int file_exists(const char *dir, const char *file)
{
    char path[8400];
    snprintf(path, sizeof path, "%s/%s", dir, file);
    struct stat st;
    return stat(path, &st) == 0;
}

static int file_has(const char *dir, const char *file, const char *needle)
{
    char path[1400], buf[1 << 16];
    snprintf(path, sizeof path, "%s/%s", dir, file);
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return strstr(buf, needle) != NULL;
}

/* A script (its path into buf) that copies method `from`'s rows of `file` in the reference run
 * under the name `to` into $1/file, through the shell text `filter` ("" for none; it reads the
 * rows on stdin), then runs `after` ("" for nothing). */
static void copy_script(char *buf, size_t cap, const char *name, const char *file, const char *from,
                        const char *to, const char *filter, const char *after)
{
    char dir[64];
    snprintf(dir, sizeof dir, "%s_sh", name);
    snprintf(buf, cap, "%s/copy.sh", tu_scratch(dir));
    FILE *f = fopen(buf, "w");
    assert_non_null(f);
    fprintf(f,
            "awk -F, -v OFS=, 'NR == 1 || $1 == \"%s\" { if (NR > 1) $1 = \"%s\"; print }' "
            "%s/%s | %s > \"$1/%s\"\n%s\n",
            from, to, ref_dir, file, *filter ? filter : "cat", file, after);
    fclose(f);
}

static void test_external_end_to_end(void **state)
{
    (void)state;
    char text[8192], rad[2400], tot[2400], args[2600], out[1200];
    copy_script(rad, sizeof rad, "ext_e2e_r", "radiance.csv", "mp", "mine", "", "");
    copy_script(tot, sizeof tot, "ext_e2e_t", "totals.csv", "mp", "mine", "", "");
    snprintf(out, sizeof out, "%s/out", tu_scratch("ext_e2e"));
    /* {scene} must be there and be this experiment's; the indented line continues the
     * command. */
    snprintf(text, sizeof text,
             "[experiment]\nmethods = mc, mp, mine\n%s[output]\ndir = %s\n[method.mine]\n"
             "command = grep -q '\"segments_top\": 8' {scene} &&\n"
             "  sh %s {out} && sh %s {out}\ntimeout = 60\n",
             tiny, out, rad, tot);
    snprintf(args, sizeof args, "run --quiet %s", cli_config("ext_e2e", text));
    cli_expect(args, 0, "");
    assert_same_rows(out, "radiance.csv", "mine", "mp");
    assert_same_rows(out, "summary.csv", "mine", "mp");
    assert_same_rows(out, "rms.csv", "mine", "mp");
    assert_same_rows(out, "totals.csv", "mine", "mp");
    assert_true(file_exists(out, "images/mine.png"));
    assert_true(file_exists(out, "images/mine.exr"));
    assert_true(file_exists(out, "images/error_mine.png"));
    /* The definition is part of the resolved config in provenance (what `score` reads). */
    assert_true(file_has(out, "provenance.txt", "method.mine.command = grep -q"));
    assert_true(file_has(out, "provenance.txt", "method.mine.timeout = 60\n"));
    /* config.ini holds the section too, cut into continuation lines, and runs again alike. */
    assert_true(file_has(out, "config.ini", "[method.mine]\ncommand = grep -q"));
    char out2[1300];
    snprintf(out2, sizeof out2, "%s2", out);
    snprintf(args, sizeof args, "run --quiet --out %s %s/config.ini", out2, out);
    cli_expect(args, 0, "");
    assert_same_rows(out2, "summary.csv", "mine", "mp");

    /* No totals.csv: R, T and sides integrated from the copied mc radiance are mc's own. */
    copy_script(rad, sizeof rad, "ext_tot_r", "radiance.csv", "mc", "mine", "", "");
    snprintf(out, sizeof out, "%s/out", tu_scratch("ext_tot"));
    snprintf(text, sizeof text,
             "[experiment]\nmethods = mp, mine\n%s[output]\ndir = %s\n[method.mine]\n"
             "command = sh %s {out}\n",
             tiny, out, rad);
    snprintf(args, sizeof args, "run --quiet %s", cli_config("ext_tot", text));
    cli_expect(args, 0, "");
    char *mine = rows_of(out, "totals.csv", "mine"), *mc = rows_of(ref_dir, "totals.csv", "mc");
    double a[5], b[5];
    assert_int_equal(sscanf(mine, "%lf,%lf,%lf,%lf,%lf", &a[0], &a[1], &a[2], &a[3], &a[4]), 5);
    assert_int_equal(sscanf(mc, "%lf,%lf,%lf,%lf,%lf", &b[0], &b[1], &b[2], &b[3], &b[4]), 5);
    for (int k = 0; k < 3; k++) /* radiance.csv holds 10 significant digits */
        assert_rel(a[k], b[k], 1e-8);
    assert_close(a[4], 0.0, 0); /* ballistic: not radiance, not reported */
    free(mine);
    free(mc);
}

/* A method whose command is body (with {out}) must fail with needle in the message, and
 * nothing of it may be written: no row in radiance.csv, no image. */
static void expect_refused(const char *name, const char *body, const char *extra,
                           const char *needle)
{
    char text[8192], args[2600], out[1200];
    snprintf(out, sizeof out, "%s/out", tu_scratch(name));
    snprintf(text, sizeof text,
             "[experiment]\nmethods = mp, bad\n%s[output]\ndir = %s\n[method.bad]\n"
             "command = %s\n%s",
             tiny, out, body, extra);
    snprintf(args, sizeof args, "run %s", cli_config(name, text));
    /* timeout: a run that blocks (on a FIFO left as an output) fails instead of hanging */
    int rc = cli_run_env("timeout 120", args, cli_out, sizeof cli_out);
    if (!strstr(cli_out, needle) || !strstr(cli_out, "bad failed"))
        fail_msg("%s: exit %d, output lacks '%s':\n%s", name, rc, needle, cli_out);
    char *rows = rows_of(out, "radiance.csv", "bad");
    if (*rows)
        fail_msg("%s: rows of the failed method written:\n%s", name, rows);
    free(rows);
    assert_false(file_exists(out, "images/bad.png"));
    assert_false(file_exists(out, "images/bad.exr"));
    assert_true(file_exists(out, "images/mp.png")); /* the others' outputs are written */
}

/* expect_refused for a copy of mp's rows through filter, then after. */
static void expect_bad_copy(const char *name, const char *filter, const char *after,
                            const char *needle)
{
    char script[1200], body[1400];
    copy_script(script, sizeof script, name, "radiance.csv", "mp", "bad", filter, after);
    snprintf(body, sizeof body, "sh %s {out}", script);
    expect_refused(name, body, "", needle);
}

static void test_external_refusals(void **state)
{
    (void)state;
    expect_bad_copy("ext_missing", "awk 'NR != 7'", "",
                    "missing row: S1 segment 1 theta_bin 0 phi_bin 1");
    expect_bad_copy("ext_dup", "awk '{ print } NR == 3'", "",
                    "radiance.csv:4: a second row for S1 segment 0 bin (0, 1) (the first: line 3)");
    expect_bad_copy("ext_nan", "awk -F, -v OFS=, 'NR == 5 { $7 = \"nan\" } { print }'", "",
                    "radiance.csv:5: radiance nan");
    expect_bad_copy("ext_neg", "awk -F, -v OFS=, 'NR == 6 { $7 = -$7 } { print }'", "",
                    "radiance.csv:6: radiance -");
    expect_bad_copy("ext_cols", "sed '1s/theta_bin/theta/'", "",
                    "radiance.csv:1: the columns must begin");
    expect_bad_copy("ext_exit", "", "exit 3", "its command exited with status 3");
    expect_refused("ext_none", "true {out}", "", "its command wrote no");
    /* Outputs that are not regular files (file_read.h): a FIFO would block open() after the
     * command exited, a link to /dev/zero never ends; each is refused naming the file. */
    expect_refused("ext_fifo", "mkfifo {out}/radiance.csv", "",
                   "radiance.csv: not a regular file (a FIFO)");
    expect_refused("ext_zero", "ln -s /dev/zero {out}/radiance.csv", "",
                   "radiance.csv: not a regular file (a character device)");
    expect_bad_copy("ext_fifo_tot", "", "mkfifo \"$1/totals.csv\"",
                    "totals.csv: not a regular file (a FIFO)");
    /* A negative fraction in totals.csv (R = -0.25 in mp's row, copied): refused at its line. */
    char after[2600];
    snprintf(after, sizeof after,
             "awk -F, -v OFS=, 'NR == 1 || $1 == \"mp\" { if (NR > 1) { $1 = \"bad\"; $2 = "
             "-0.25 } print }' %s/totals.csv > \"$1/totals.csv\"",
             ref_dir);
    expect_bad_copy("ext_negtot", "", after, "totals.csv:2: R = '-0.25': a fraction of the power");
    char body[2600];

    /* Timeout: the command and its children are killed (the whole process group). */
    char pidfile[1200];
    snprintf(pidfile, sizeof pidfile, "%s/sleep.pid", tu_scratch("ext_pid"));
    snprintf(body, sizeof body, "sleep 30 & echo $! > %s; wait; echo never > {out}/radiance.csv",
             pidfile);
    expect_refused("ext_timeout", body, "timeout = 1\n", "ran past its timeout of 1 s: killed");
    FILE *f = fopen(pidfile, "r");
    assert_non_null(f);
    int pid = 0;
    assert_int_equal(fscanf(f, "%d", &pid), 1);
    fclose(f);
    int alive = 1;
    for (int i = 0; i < 100 && alive; i++) { /* reaped by init within moments */
        alive = kill(pid, 0) == 0;
        if (alive)
            nanosleep(&(struct timespec){0, 20000000L}, NULL);
    }
    if (alive)
        fail_msg("the command's child %d still runs after the timeout", pid);

    /* Config errors, exit 2 before any work. */
    char text[512], args[1400];
    snprintf(text, sizeof text, "[experiment]\nmethods = mp, x\n[method.x]\ncommand = true\n");
    snprintf(args, sizeof args, "run %s", cli_config("ext_noout", text));
    cli_expect(args, 2, ":4: [method.x] command: holds no {out}");
    snprintf(text, sizeof text, "[experiment]\nmethods = mp, x\n[method.x]\ntimeout = 5\n");
    snprintf(args, sizeof args, "run %s", cli_config("ext_nocmd", text));
    cli_expect(args, 2, ":4: [method.x]: no command given");
    snprintf(text, sizeof text, "[experiment]\nmethods = mp\n[method.mp]\ncommand = x {out}\n");
    snprintf(args, sizeof args, "run %s", cli_config("ext_builtin", text));
    cli_expect(args, 2, "[method.mp]: 'mp' is a built-in method's id");
    snprintf(text, sizeof text, "[experiment]\nmethods = mp\n[method.y]\ncolor = 1\n");
    snprintf(args, sizeof args, "run %s", cli_config("ext_key", text));
    cli_expect(args, 2, ":4: [method.y] color: unknown key");
}

/* The pid written in path (0 when there is none yet). */
static int read_pid(const char *path)
{
    FILE *f = fopen(path, "r");
    int pid = 0;
    if (f) {
        if (fscanf(f, "%d", &pid) != 1)
            pid = 0;
        fclose(f);
    }
    return pid;
}

/* Waits up to `seconds` for process pid to be gone (a zombie counts as gone: it runs nothing);
 * on failure kills it, so that a failed check leaves nothing running. */
static void assert_gone(int pid, double seconds, const char *what)
{
    char path[64], st[512];
    snprintf(path, sizeof path, "/proc/%d/stat", pid);
    for (int i = 0; i < seconds * 50; i++) {
        FILE *f = fopen(path, "r");
        int gone = !f || !fgets(st, sizeof st, f) || strstr(st, ") Z ");
        if (f)
            fclose(f);
        if (gone)
            return;
        nanosleep(&(struct timespec){0, 20000000L}, NULL);
    }
    kill(pid, SIGKILL);
    fail_msg("%s (pid %d) still runs", what, pid);
}

/* Waits up to 120 s for path to hold a pid. */
static int wait_pid_file(const char *path)
{
    for (int i = 0; i < 6000; i++) {
        int pid = read_pid(path);
        if (pid > 0)
            return pid;
        nanosleep(&(struct timespec){0, 20000000L}, NULL);
    }
    fail_msg("no pid in %s after 120 s", path);
    return 0;
}

/* What an external command starts dies with it (base/child.h): a background job and one that
 * left the process group (setsid) are gone once ppbench has finished; with ppbench killed by
 * SIGKILL mid-command the command and its children die at once; with ppbench and the command's
 * guard both killed by SIGKILL, the next ppbench (any command) kills what they left. Before,
 * each of these processes ran on (sleep 300: five minutes). */
static void test_orphans(void **state)
{
    (void)state;
    char dir[1024], body[1400], p1[1100], p2[1100], script[1100];
    snprintf(dir, sizeof dir, "%s", tu_scratch("ext_orphans"));
    snprintf(p1, sizeof p1, "%s/bg.pid", dir);
    snprintf(p2, sizeof p2, "%s/setsid.pid", dir);
    /* The commands are scripts: a config line holds at most 198 characters. */
    snprintf(script, sizeof script, "%s/bg.sh", dir);
    FILE *f = fopen(script, "w");
    assert_non_null(f);
    fprintf(f,
            "sleep 300 > /dev/null 2>&1 & echo $! > %s\n"
            "setsid sleep 300 > /dev/null 2>&1 & echo $! > %s\nexit 3\n",
            p1, p2);
    fclose(f);
    snprintf(body, sizeof body, "sh %s {out}", script);
    expect_refused("ext_orphan_bg", body, "", "its command exited with status 3");
    assert_gone(read_pid(p1), 2, "the command's background job");
    assert_gone(read_pid(p2), 2, "the command's setsid job");
    /* The same past the timeout, where the process group is killed: setsid left it. */
    snprintf(script, sizeof script, "%s/to.sh", dir);
    f = fopen(script, "w");
    assert_non_null(f);
    fprintf(f, "setsid sleep 300 > /dev/null 2>&1 & echo $! > %s\nsleep 30\n", p2);
    fclose(f);
    snprintf(body, sizeof body, "sh %s {out}", script);
    expect_refused("ext_orphan_to", body, "timeout = 1\n", "ran past its timeout of 1 s");
    assert_gone(read_pid(p2), 2, "the timed-out command's setsid job");

    /* ppbench killed with SIGKILL while its command runs. */
    for (int both = 0; both < 2; both++) {
        char sh[1100], py[1100], ppb[1100], text[8192], cmd[12000];
        snprintf(sh, sizeof sh, "%s/sh%d.pid", dir, both);
        snprintf(py, sizeof py, "%s/py%d.pid", dir, both);
        snprintf(ppb, sizeof ppb, "%s/ppbench%d.pid", dir, both);
        snprintf(script, sizeof script, "%s/slow%d.sh", dir, both);
        f = fopen(script, "w");
        assert_non_null(f);
        fprintf(f, "python3 -c 'import time; time.sleep(300)' & echo $! > %s\necho $$ > %s\nwait\n",
                py, sh);
        fclose(f);
        snprintf(text, sizeof text,
                 "[experiment]\nmethods = slow\n%s[output]\ndir = %s/out%d\n[method.slow]\n"
                 "command = sh %s {out}\n",
                 tiny, dir, both, script);
        snprintf(cmd, sizeof cmd, "%s run --quiet %s > %s/log%d 2>&1 & echo $! > %s", tu_bin(),
                 cli_config("ext_orphan_kill", text), dir, both, ppb);
        assert_int_equal(system(cmd), 0);
        int pid_py = wait_pid_file(py), pid_sh = wait_pid_file(sh), pid_ppb = read_pid(ppb);
        if (both) { /* the guard first: nothing is left to kill the command's processes */
            char kids[128], line[256] = "";
            snprintf(kids, sizeof kids, "/proc/%d/task/%d/children", pid_ppb, pid_ppb);
            f = fopen(kids, "r");
            assert_non_null(f);
            assert_non_null(fgets(line, sizeof line, f));
            fclose(f);
            assert_int_equal(kill(atoi(line), SIGKILL), 0);
        }
        assert_int_equal(kill(pid_ppb, SIGKILL), 0);
        if (both) {
            nanosleep(&(struct timespec){0, 300000000L}, NULL);
            cli_expect("--version", 0, "");
        }
        assert_gone(pid_sh, 5, both ? "the command's shell (guard killed)" : "the command's shell");
        assert_gone(pid_py, 5,
                    both ? "the command's python3 (guard killed)" : "the command's python3");
    }
}

/* `score` on the run's own radiance.csv reproduces its summary, rms and regions byte for byte
 * (the run's own files are the expected values; the reference is read back from its
 * radiance.csv, 10 significant digits, and the metrics print 6), and its totals rows; the
 * experiment's directory is left as it was (diff -r against a copy). */
static void test_score(void **state)
{
    (void)state;
    char dir[1024], cmd[8192], args[8192], out[1200];
    snprintf(dir, sizeof dir, "%s", tu_scratch("ext_score"));
    snprintf(cmd, sizeof cmd, "cp -r %s %s/before", ref_dir, dir);
    assert_int_equal(system(cmd), 0);
    snprintf(out, sizeof out, "%s/scored", dir);
    snprintf(args, sizeof args, "score --ref %s --out %s %s/radiance.csv", ref_dir, out, ref_dir);
    cli_expect(args, 0, "score: wrote");
    static const char *const same[] = {"summary.csv", "rms.csv", "regions.csv"};
    for (int i = 0; i < 3; i++) {
        snprintf(cmd, sizeof cmd, "cmp %s/%s %s/%s", ref_dir, same[i], out, same[i]);
        if (system(cmd) != 0)
            fail_msg("%s differs from the run's own", same[i]);
    }
    char *a = rows_of(out, "totals.csv", "mp"), *b = rows_of(ref_dir, "totals.csv", "mp");
    assert_true(*a);
    assert_string_equal(a, b);
    free(a);
    free(b);
    char *mc = rows_of(out, "totals.csv", "mc");
    assert_string_equal(mc, ""); /* only the scored method's rows */
    free(mc);
    /* Without --out: a new directory beside, never the experiment's. */
    snprintf(args, sizeof args, "score --ref %s %s/radiance.csv", ref_dir, ref_dir);
    cli_expect(args, 0, "-score");
    snprintf(cmd, sizeof cmd, "%s-score", ref_dir);
    assert_true(file_exists(cmd, "summary.csv"));
    snprintf(args, sizeof args, "score --ref %s --out %s/ %s/radiance.csv", ref_dir, ref_dir,
             ref_dir);
    cli_expect(args, 2, "the experiment's own directory");
    snprintf(cmd, sizeof cmd, "diff -r %s/before %s", dir, ref_dir);
    if (system(cmd) != 0)
        fail_msg("score changed %s", ref_dir);
    /* A bad file is refused with file:line, as a method's output. */
    snprintf(cmd, sizeof cmd,
             "awk -F, -v OFS=, 'NR == 180 && $1 == \"mp\" { $7 = \"inf\" } { print }' "
             "%s/radiance.csv > %s/bad.csv",
             ref_dir, dir);
    assert_int_equal(system(cmd), 0);
    snprintf(args, sizeof args, "score --ref %s --out %s/bad %s/bad.csv", ref_dir, dir, dir);
    cli_expect(args, 2, "bad.csv:180: radiance inf"); /* bad input: docs/reference.md, Exit codes */
}

/* The Python path (python/ppbench): the example dipole through [method.dipole_py] against the C
 * mp at one pair (mp.pairs = 0: no pairs beyond the first) in slab mode -- both are the same
 * model, so they must agree within the example's stated quadrature error (1e-9) plus the
 * 10-digit print of radiance.csv and totals.csv: 1e-8 relative; and ppbench.metrics() on
 * load(dir) recomputes summary.csv (printed to 6 digits: 1e-5 relative). */
static void test_python(void **state)
{
    (void)state;
    if (system("python3 -c 'import sys; sys.exit(sys.version_info < (3, 8))'") != 0)
        fail_msg("python3 >= 3.8 is needed for the Python path");
    char root[PATH_MAX], text[8192], args[8192], out[1200];
    assert_non_null(realpath("python", root));
    snprintf(out, sizeof out, "%s/out", tu_scratch("ext_py"));
    snprintf(text, sizeof text,
             "[experiment]\ngeometry = slab\nmethods = mc, mp, dipole_py\n[tube]\nheight = 3\n"
             "[bins]\ntheta = 2\nphi = 2\n[mc]\nphotons = 20000\n[mp]\npairs = 0\n"
             "[output]\ndir = %s\n[method.dipole_py]\n"
             "command = PYTHONPATH=%s python3 -m ppbench.dipole {scene} {out}\n",
             out, root);
    snprintf(args, sizeof args, "run --quiet %s", cli_config("ext_py", text));
    cli_expect(args, 0, "");
    char *py = rows_of(out, "radiance.csv", "dipole_py"), *mp = rows_of(out, "radiance.csv", "mp");
    int n = 0;
    for (char *a = py, *b = mp; *a && *b; n++) {
        char sa[8], sb[8];
        int ga, gb, ta, tb, pa, pb, ka, kb;
        double xa, xb, La, Lb;
        assert_int_equal(sscanf(a, "%7[^,],%d,%lf,%d,%d,%lf%n", sa, &ga, &xa, &ta, &pa, &La, &ka),
                         6);
        assert_int_equal(sscanf(b, "%7[^,],%d,%lf,%d,%d,%lf%n", sb, &gb, &xb, &tb, &pb, &Lb, &kb),
                         6);
        assert_string_equal(sa, sb);
        assert_int_equal(ta * 2 + pa, tb * 2 + pb);
        assert_rel(La, Lb, 1e-8);
        a = strchr(a, '\n') + 1;
        b = strchr(b, '\n') + 1;
    }
    assert_int_equal(n, 2 * 4); /* S1 and S2, one point each, 4 bins */
    free(py);
    free(mp);
    char *tp = rows_of(out, "totals.csv", "dipole_py"), *tm = rows_of(out, "totals.csv", "mp");
    double a[5], b[5];
    assert_int_equal(sscanf(tp, "%lf,%lf,%lf,%lf,%lf", &a[0], &a[1], &a[2], &a[3], &a[4]), 5);
    assert_int_equal(sscanf(tm, "%lf,%lf,%lf,%lf,%lf", &b[0], &b[1], &b[2], &b[3], &b[4]), 5);
    assert_rel(a[0], b[0], 1e-8); /* R */
    assert_rel(a[1], b[1], 1e-8); /* T */
    assert_rel(a[4], b[4], 1e-8); /* ballistic, exp(-tau): both exact */
    free(tp);
    free(tm);
    /* metrics() from load(): every summary.csv row, recomputed. */
    snprintf(args, sizeof args,
             "PYTHONPATH=%s python3 -c '\n"
             "import ppbench, sys\n"
             "run = ppbench.load(\"%s\")\n"
             "rows = run[\"summary\"]\n"
             "rows = rows.to_dict(\"records\") if hasattr(rows, \"to_dict\") else rows\n"
             "bad = 0\n"
             "for r in rows:\n"
             "    m = ppbench.metrics(run[\"radiance\"], r[\"method\"], cell=r[\"cell\"])\n"
             "    for k in (\"rms_rel\", \"noise_rel\", \"rms_excess\"):\n"
             "        if abs(m[k] - r[k]) > 1e-5 * abs(r[k]) + 1e-12:\n"
             "            print(r, k, m[k]); bad = 1\n"
             "print(len(rows), \"rows\")\n"
             "sys.exit(bad or len(rows) < 6)'",
             root, out);
    int rc = system(args);
    assert_int_equal(rc, 0);
}

/* The reference cache: a second run with --ref-cache that needs the same Monte Carlo reference
 * (here: adding a method) traces no photon -- counted, not timed: provenance.txt records
 * mc.photons_traced for a traced reference and none for a cached one, and the run says "0
 * traced" -- and its mc rows are the first run's byte for byte; another seed is another
 * reference and is traced. */
static void test_ref_cache(void **state)
{
    (void)state;
    char dir[1024], text[4096], args[8192], cache[1100], a[1100], b[1100], c[1100], cmd[8192];
    snprintf(dir, sizeof dir, "%s", tu_scratch("ext_cache"));
    snprintf(cache, sizeof cache, "%s/cache", dir);
    snprintf(a, sizeof a, "%s/a", dir);
    snprintf(b, sizeof b, "%s/b", dir);
    snprintf(c, sizeof c, "%s/c", dir);
    snprintf(text, sizeof text, "[experiment]\nmethods = mc, mp\n%s", tiny);
    snprintf(args, sizeof args, "run --quiet --ref-cache %s --out %s %s", cache, a,
             cli_config("ext_cache1", text));
    cli_expect(args, 0, "");
    assert_true(file_has(a, "provenance.txt", "mc.photons_traced = 20000\n"));
    snprintf(text, sizeof text,
             "[experiment]\nmethods = mc, mp, mp2\n%s[method.mp2]\ncommand = sh %s/copy.sh {out}\n",
             tiny, dir);
    FILE *f = fopen(strcat(strcpy(cmd, dir), "/copy.sh"), "w");
    assert_non_null(f);
    fprintf(f,
            "awk -F, -v OFS=, 'NR == 1 || $1 == \"mp\" { if (NR > 1) $1 = \"mp2\"; print }' "
            "%s/radiance.csv > \"$1/radiance.csv\"\n",
            a);
    fclose(f);
    snprintf(args, sizeof args, "run --ref-cache %s --out %s %s", cache, b,
             cli_config("ext_cache2", text));
    cli_expect(args, 0, "mc: 20000 photons from the reference cache");
    assert_true(strstr(cli_out, "0 traced") != NULL);
    assert_false(file_has(b, "provenance.txt", "mc.photons_traced"));
    assert_same_rows(b, "summary.csv", "mp2", "mp");
    char *ra = rows_of(a, "radiance.csv", "mc"), *rb = rows_of(b, "radiance.csv", "mc");
    assert_true(*ra);
    assert_string_equal(ra, rb);
    free(ra);
    free(rb);
    /* Another seed: not the cached reference. */
    snprintf(args, sizeof args, "run --quiet --set mc.seed=2 --ref-cache %s --out %s %s", cache, c,
             cli_config("ext_cache1", "[experiment]\nmethods = mc\n[tube]\nsegments_top = 8\n"
                                      "segments_side = 3\n[bins]\ntheta = 2\nphi = 2\n[mc]\n"
                                      "photons = 20000\n"));
    cli_expect(args, 0, "");
    assert_true(file_has(c, "provenance.txt", "mc.photons_traced = 20000\n"));
    /* A FIFO in place of a cache entry is not read (open would block) and the reference is
     * traced again. */
    snprintf(cmd, sizeof cmd, "for f in %s/mc-*.bin; do rm \"$f\" && mkfifo \"$f\"; done", cache);
    assert_int_equal(system(cmd), 0);
    snprintf(args, sizeof args, "run --set mc.seed=2 --ref-cache %s --out %s/d %s", cache, dir,
             cli_config("ext_cache1", "[experiment]\nmethods = mc\n[tube]\nsegments_top = 8\n"
                                      "segments_side = 3\n[bins]\ntheta = 2\nphi = 2\n[mc]\n"
                                      "photons = 20000\n"));
    cli_expect_env("timeout 120", args, 0, ".bin: not a regular file (a FIFO)");
}

/* [method.NAME] keys through --set: a config without the section gets one (and the method
 * list names it), a file's command is overridden (the last wins, as for any key), and each
 * malformed --set is refused before any work with a message naming --set and the key. The
 * expected rows are mp's own, which the command copies under the new name. */
static void test_set_method(void **state)
{
    (void)state;
    char rad[2400], args[8192], out[1200], text[4096];
    copy_script(rad, sizeof rad, "ext_set_r", "radiance.csv", "mp", "mine", "", "");
    snprintf(out, sizeof out, "%s/out", tu_scratch("ext_set"));
    snprintf(text, sizeof text, "[experiment]\nmethods = mc, mp\n%s", tiny);
    const char *cfg = cli_config("ext_set", text);
    snprintf(args, sizeof args,
             "run --quiet --set 'method.mine.command=sh %s {out}' --set method.mine.timeout=60 "
             "--set experiment.methods=mc,mp,mine --out %s %s",
             rad, out, cfg);
    cli_expect(args, 0, "");
    assert_same_rows(out, "summary.csv", "mine", "mp");
    assert_true(file_has(out, "config.ini", "[method.mine]\ncommand = sh "));
    assert_true(file_has(out, "provenance.txt", "method.mine.timeout = 60\n"));
    /* Overriding the file's command: the file's would fail (exit 3). */
    snprintf(text, sizeof text,
             "[experiment]\nmethods = mp, mine\n%s[method.mine]\ncommand = exit 3 {out}\n", tiny);
    cfg = cli_config("ext_set2", text);
    snprintf(args, sizeof args, "run --quiet --set 'method.mine.command=sh %s {out}' --out %s2 %s",
             rad, out, cfg);
    cli_expect(args, 0, "");
    char out2[1300];
    snprintf(out2, sizeof out2, "%s2", out);
    assert_same_rows(out2, "radiance.csv", "mine", "mp"); /* no mc: no summary.csv */
    struct {
        const char *set, *needle;
    } bad[] = {
        {"method.mine=x", "--set method.mine=x: expected method.NAME.KEY=VALUE"},
        {"method.mine.cmd=x", "--set method.mine.cmd: unknown key"},
        {"'method.a b.command=x {out}'", "--set method.a b.command: a method name may hold"},
        {"method.mine.timeout=-1", "--set method.mine.timeout: seconds, a number in (0, 1e6]"},
        {"method.mine.command=true", "--set method.mine.command: holds no {out}"},
        {"method.mc.command={out}", "--set method.mc: 'mc' is a built-in method's id"},
        {"method.other.timeout=5", "--set method.other: no command given"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(args, sizeof args, "run --quiet --set %s --out %s3 %s", bad[i].set, out, cfg);
        cli_expect(args, 2, bad[i].needle);
        assert_int_equal(tu_sh("test ! -e %s3", out), 0);
    }
}

/* One run of tiny's mc (env: "" or "VAR=value ..."; opts: extra options) into out: 1 when it
 * traced its 20000 photons (provenance.txt's mc.photons_traced, written only for a traced
 * reference), 0 when it said it took them from a cache and traced none (under --quiet it says
 * nothing at all: docs/reference.md, Exit codes). Counted, not timed. */
static int traced(const char *env, const char *opts, const char *out)
{
    char args[4096];
    snprintf(args, sizeof args, "run %s --out %s %s", opts, out,
             cli_config("ext_cache_env", "[experiment]\nmethods = mc\n[tube]\nsegments_top = 8\n"
                                         "segments_side = 3\n[bins]\ntheta = 2\nphi = 2\n[mc]\n"
                                         "photons = 20000\n"));
    int rc = cli_run_env(env, args, cli_out, sizeof cli_out);
    if (rc != 0)
        fail_msg("%s ppbench %s: exit %d:\n%s", env, args, rc, cli_out);
    int from_cache = strstr(cli_out, "20000 photons from the reference cache") != NULL &&
                     strstr(cli_out, ", 0 traced") != NULL;
    int was_traced = file_has(out, "provenance.txt", "mc.photons_traced = 20000\n");
    if (strstr(opts, "--quiet")) {
        if (cli_out[0])
            fail_msg("%s ppbench %s printed under --quiet:\n%s", env, args, cli_out);
        from_cache = !was_traced;
    }
    if (from_cache == was_traced)
        fail_msg("%s ppbench %s: traced %d, from the cache %d:\n%s", env, args, was_traced,
                 from_cache, cli_out);
    return was_traced;
}

/* How many cache files dir holds (mc-<key>.bin). */
static int cache_files(const char *dir)
{
    char cmd[1400];
    snprintf(cmd, sizeof cmd, "ls %s/mc-*.bin 2>/dev/null | wc -l", dir);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    int n = -1;
    if (fscanf(p, "%d", &n) != 1)
        n = -1;
    pclose(p);
    return n;
}

/* The default cache of a plain run (no --ref-cache): $PPBENCH_CACHE, else
 * $XDG_CACHE_HOME/ppbench/ref, else ~/.cache/ppbench/ref; --no-ref-cache and an empty
 * $PPBENCH_CACHE trace and store nothing. PoCL keeps its own cache under the same variables:
 * POCL_CACHE_DIR pins it to a scratch directory, so only ppbench's cache moves. */
static void test_default_cache(void **state)
{
    (void)state;
    char dir[1024], env[4096], out[1100], pocl[1100];
    snprintf(dir, sizeof dir, "%s", tu_scratch("ext_defcache"));
    snprintf(pocl, sizeof pocl, "%s/pocl", dir);
    char c1[1100], c2[1100], c3[1100];
    snprintf(c1, sizeof c1, "%s/env", dir);
    snprintf(c2, sizeof c2, "%s/xdg/ppbench/ref", dir);
    snprintf(c3, sizeof c3, "%s/home/.cache/ppbench/ref", dir);
    /* $PPBENCH_CACHE: the first run traces and stores, the second reads it. */
    snprintf(env, sizeof env, "POCL_CACHE_DIR=%s PPBENCH_CACHE=%s", pocl, c1);
    snprintf(out, sizeof out, "%s/a", dir);
    assert_true(traced(env, "--quiet", out));
    assert_int_equal(cache_files(c1), 1);
    snprintf(out, sizeof out, "%s/b", dir);
    assert_false(traced(env, "", out));
    /* --no-ref-cache: traced, though the cache holds it. */
    snprintf(out, sizeof out, "%s/c", dir);
    assert_true(traced(env, "--quiet --no-ref-cache", out));
    /* No $PPBENCH_CACHE: $XDG_CACHE_HOME/ppbench/ref, then ~/.cache/ppbench/ref. */
    snprintf(env, sizeof env, "env -u PPBENCH_CACHE POCL_CACHE_DIR=%s XDG_CACHE_HOME=%s/xdg", pocl,
             dir);
    snprintf(out, sizeof out, "%s/d", dir);
    assert_true(traced(env, "--quiet", out));
    assert_int_equal(cache_files(c2), 1);
    snprintf(out, sizeof out, "%s/e", dir);
    assert_false(traced(env, "--quiet", out));
    snprintf(env, sizeof env,
             "env -u PPBENCH_CACHE -u XDG_CACHE_HOME POCL_CACHE_DIR=%s HOME=%s/home", pocl, dir);
    snprintf(out, sizeof out, "%s/f", dir);
    assert_true(traced(env, "--quiet", out));
    assert_int_equal(cache_files(c3), 1);
    /* $PPBENCH_CACHE set empty: no cache at all (what make test runs under). */
    snprintf(env, sizeof env, "POCL_CACHE_DIR=%s HOME=%s/home PPBENCH_CACHE=", pocl, dir);
    snprintf(out, sizeof out, "%s/g", dir);
    assert_true(traced(env, "--quiet", out));
    /* --ref-cache DIR wins over $PPBENCH_CACHE. */
    snprintf(env, sizeof env, "POCL_CACHE_DIR=%s PPBENCH_CACHE=%s/unused", pocl, dir);
    char opts[1200];
    snprintf(opts, sizeof opts, "--quiet --ref-cache %s", c1);
    snprintf(out, sizeof out, "%s/h", dir);
    assert_false(traced(env, opts, out));
    assert_int_equal(tu_sh("test ! -e %s/unused", dir), 0);
    cli_expect("run --ref-cache x --no-ref-cache configs/uniform_g0_normal.ini", 2,
               "--ref-cache and --no-ref-cache: give one of them");
}

/* A changed kernel is another reference: the key holds the hash of mc.cl's source text and of
 * every header it includes. A copy of the kernel sources in another tree (PPBENCH_SOURCE)
 * serves the cached tallies (the text is the same, its place does not count); a comment added
 * to mc.cl, or to a header it includes (ppb_sampling.h), makes the run trace again. */
static void test_cache_kernel_change(void **state)
{
    (void)state;
    char dir[1024], env[4096], out[1100], cache[1100];
    snprintf(dir, sizeof dir, "%s", tu_scratch("ext_kcache"));
    snprintf(cache, sizeof cache, "%s/cache", dir);
    assert_int_equal(tu_sh("rm -rf %s/k && mkdir -p %s/k && cd %s && cp --parents kernels/*.h "
                           "src/methods/*/*.cl src/methods/*/*.h %s/k",
                           dir, dir, PPB_SOURCE_DIR, dir),
                     0);
    snprintf(env, sizeof env, "PPBENCH_CACHE=%s", cache);
    snprintf(out, sizeof out, "%s/a", dir);
    assert_true(traced(env, "--quiet", out));
    snprintf(env, sizeof env, "PPBENCH_CACHE=%s PPBENCH_SOURCE=%s/k", cache, dir);
    snprintf(out, sizeof out, "%s/b", dir);
    assert_false(traced(env, "--quiet", out));
    const char *edits[] = {"src/methods/mc/mc.cl", "kernels/ppb_sampling.h"};
    for (int i = 0; i < 2; i++) {
        /* mc.cl restored from the tree each time: the second edit is the header's alone. */
        assert_int_equal(tu_sh("cp %s/%s %s/k/%s && printf '\\n/* changed */\\n' >> %s/k/%s",
                               PPB_SOURCE_DIR, edits[0], dir, edits[0], dir, edits[i]),
                         0);
        snprintf(out, sizeof out, "%s/c%d", dir, i);
        if (!traced(env, "--quiet", out))
            fail_msg("%s edited: the cached tallies were used", edits[i]);
    }
    /* The edit is a comment: the tallies traced again are the same (the key is the text, the
     * tallies a function of seed and index). */
    char *ra = rows_of(out, "radiance.csv", "mc");
    snprintf(out, sizeof out, "%s/a", dir);
    char *rb = rows_of(out, "radiance.csv", "mc");
    assert_true(*ra);
    assert_string_equal(ra, rb);
    free(ra);
    free(rb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scene_json),
        cmocka_unit_test(test_external_end_to_end),
        cmocka_unit_test(test_external_refusals),
        cmocka_unit_test(test_orphans),
        cmocka_unit_test(test_score),
        cmocka_unit_test(test_python),
        cmocka_unit_test(test_ref_cache),
        cmocka_unit_test(test_set_method),
        cmocka_unit_test(test_default_cache),
        cmocka_unit_test(test_cache_kernel_change),
    };
    if (getenv("PPB_TEST_FILTER")) /* one test by name, e.g. when checking a fix */
        cmocka_set_test_filter(getenv("PPB_TEST_FILTER"));
    return cmocka_run_group_tests(tests, make_ref, NULL);
}
