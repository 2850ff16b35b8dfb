/* test_slurm.c: `ppbench slurm` without a cluster (tests/cluster.sh runs it on a real
 * one). Every expected text is the one drivers/slurm.h specifies, written out by hand here:
 * - the array and merge scripts for given options: #SBATCH lines, the task's command (sweep or
 *   mc-shard), the done marker, the merge's check of every marker and its command;
 * - the scripts run by bash with a stand-in ppbench: a task that exits 0 leaves a marker holding
 *   the stamp, one that fails leaves none; the merge refuses a missing marker and a marker of
 *   another stamp, and runs the merge command once all are there;
 * - the config copy loads back to the same settings and the same grid, axes in the file's order
 *   (not the key table's), compared with the original config loaded independently;
 * - array specs, squeue parsing, option checks, shell quoting;
 * - --account, --qos, --gres and free --sbatch lines in the scripts, and their refusals;
 *   check.sh, run on this machine, says ok, and names an unreadable kernels directory;
 * - the command with stand-in sbatch, squeue and scancel on PATH: the first submission, the
 *   re-run after a failed task (only the missing shard, the old merge cancelled, the new merge
 *   after the new array and the task still running), nothing submitted when all is done, and a
 *   directory of another seed or a foreign directory refused with exit 2. */
#include "cliutil.h"

#include <sys/stat.h>

#include "drivers/slurm.h"

static void assert_has(const char *text, const char *needle)
{
    if (!text || !strstr(text, needle))
        fail_msg("text lacks '%s':\n%s", needle, text ? text : "(null)");
}

static void assert_lacks(const char *text, const char *needle)
{
    if (strstr(text, needle))
        fail_msg("text holds '%s':\n%s", needle, text);
}

static void write_text(const char *path, const char *text, int exec)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    if (exec)
        chmod(path, 0755);
}

static ppb_slurm_job sweep_job(const char *dir)
{
    ppb_slurm_job job = {.kind = PPB_SLURM_SWEEP, .shards = 4, .units = 12};
    snprintf(job.dir, sizeof job.dir, "%s", dir);
    snprintf(job.name, sizeof job.name, "ppb-sw-0badcafe");
    snprintf(job.stamp, sizeof job.stamp, "sweep shards=4 config=1 build=2");
    return job;
}

static void test_array_script_text(void **state)
{
    (void)state;
    ppb_slurm_job job = sweep_job("/scratch/j");
    ppb_slurm_opts o = {
        .shards = 4, .partition = "short", .time = "1-02:00:00", .mem = "4G", .cpus = 2};
    char *s = ppb_slurm_array_script(&job, &o);
    assert_has(s, "#!/bin/bash\n");
    assert_has(s, "#SBATCH --job-name=ppb-sw-0badcafe\n");
    assert_has(s, "#SBATCH --array=1-4\n");
    assert_has(s, "#SBATCH --output=/scratch/j/logs/task_%a_job_%A.out\n");
    assert_has(s, "#SBATCH --partition=short\n#SBATCH --time=1-02:00:00\n#SBATCH --mem=4G\n"
                  "#SBATCH --cpus-per-task=2\n");
    assert_has(s, "dir='/scratch/j'\nstamp='sweep shards=4 config=1 build=2'\n");
    assert_has(s, "\"$dir/ppbench\" sweep --quiet --shard \"$i/4\" --out \"$dir/shards/$i\" "
                  "\"$dir/config.ini\"\n");
    assert_has(s, "printf '%s\\n' \"$stamp\" > \"$dir/done/$i.tmp.$$\"\n"
                  "mv -f \"$dir/done/$i.tmp.$$\" \"$dir/done/$i\"\n");
    free(s);

    /* The Monte Carlo's task, a device with a quote, no optional #SBATCH line. */
    job.kind = PPB_SLURM_MC;
    ppb_slurm_opts m = {.shards = 4, .device = "it's"};
    s = ppb_slurm_array_script(&job, &m);
    assert_has(s, "\"$dir/ppbench\" mc-shard --quiet --device 'it'\\''s' --shard \"$i/4\"");
    assert_lacks(s, "--partition");
    assert_lacks(s, "--time");
    assert_lacks(s, "--mem");
    assert_lacks(s, "--cpus-per-task");
    free(s);
}

static void test_merge_script_text(void **state)
{
    (void)state;
    ppb_slurm_job job = sweep_job("/scratch/j");
    ppb_slurm_opts o = {.shards = 4, .time = "30", .cpus = 8};
    char *s = ppb_slurm_merge_script(&job, &o);
    assert_has(s, "#SBATCH --job-name=ppb-sw-0badcafe-merge\n");
    assert_has(s, "#SBATCH --output=/scratch/j/logs/merge_job_%j.out\n");
    assert_has(s, "#SBATCH --time=30\n");
    assert_lacks(s, "--cpus-per-task"); /* the merge is one process */
    assert_lacks(s, "--array");
    assert_has(s, "for i in $(seq 1 4); do\n");
    assert_has(s, "\"$dir/ppbench\" merge --out \"$dir/result\" \"${shards[@]}\"\n");
    free(s);
    job.kind = PPB_SLURM_MC;
    s = ppb_slurm_merge_script(&job, &o);
    assert_has(s, "\"$dir/ppbench\" mc-merge --out \"$dir/result\" \"$dir/config.ini\" "
                  "\"${shards[@]}\"\n");
    free(s);
}

/* The scripts as bash runs them, with a stand-in ppbench that logs its arguments and exits
 * with $FAKE_RC. */
static void test_scripts_run(void **state)
{
    (void)state;
    const char *d = tu_scratch("slurm-scripts");
    char path[1300], log[1300];
    ppb_slurm_job job = sweep_job(d);
    job.shards = 2;
    snprintf(job.stamp, sizeof job.stamp, "sweep shards=2 config=1 build=2");
    ppb_slurm_opts o = {.shards = 2};
    assert_int_equal(tu_sh("mkdir -p '%s/done' '%s/shards' '%s/logs'", d, d, d), 0);
    snprintf(log, sizeof log, "%s/calls.log", d);
    char fake[2000];
    snprintf(fake, sizeof fake, "#!/bin/sh\necho \"$*\" >> '%s'\nexit ${FAKE_RC:-0}\n", log);
    snprintf(path, sizeof path, "%s/ppbench", d);
    write_text(path, fake, 1);
    char *a = ppb_slurm_array_script(&job, &o), *m = ppb_slurm_merge_script(&job, &o);
    snprintf(path, sizeof path, "%s/job.sh", d);
    write_text(path, a, 1);
    snprintf(path, sizeof path, "%s/merge.sh", d);
    write_text(path, m, 1);
    free(a);
    free(m);

    /* A failing task: no marker. */
    assert_int_not_equal(tu_sh("FAKE_RC=1 SLURM_ARRAY_TASK_ID=2 bash '%s/job.sh' 2>/dev/null", d),
                         0);
    snprintf(path, sizeof path, "%s/done/2", d);
    assert_int_not_equal(access(path, F_OK), 0);
    /* The merge refuses while shard 1 and 2 have no marker, and calls no ppbench merge. */
    assert_int_not_equal(tu_sh("bash '%s/merge.sh' 2>'%s/merge.err'", d, d), 0);
    snprintf(path, sizeof path, "%s/merge.err", d);
    assert_has(tu_read_text(path), "shard 1 of 2 is not done by this job (done/1: none)");
    /* Both tasks succeed: markers holding the stamp. */
    assert_int_equal(tu_sh("SLURM_ARRAY_TASK_ID=1 bash '%s/job.sh'", d), 0);
    assert_int_equal(tu_sh("SLURM_ARRAY_TASK_ID=2 bash '%s/job.sh'", d), 0);
    snprintf(path, sizeof path, "%s/done/2", d);
    assert_string_equal(tu_read_text(path), "sweep shards=2 config=1 build=2\n");
    /* A marker of another job (another build) is refused. */
    snprintf(path, sizeof path, "%s/done/1", d);
    write_text(path, "sweep shards=2 config=1 build=3\n", 0);
    assert_int_not_equal(tu_sh("bash '%s/merge.sh' 2>'%s/merge.err'", d, d), 0);
    snprintf(path, sizeof path, "%s/merge.err", d);
    assert_has(tu_read_text(path), "shard 1 of 2 is not done by this job (done/1: sweep shards=2 "
                                   "config=1 build=3)");
    snprintf(path, sizeof path, "%s/done/1", d);
    write_text(path, "sweep shards=2 config=1 build=2\n", 0);
    assert_int_equal(tu_sh("bash '%s/merge.sh'", d), 0);
    snprintf(path, sizeof path, "%s/done/merge", d);
    assert_string_equal(tu_read_text(path), "sweep shards=2 config=1 build=2\n");
    char want[16000];
    snprintf(want, sizeof want,
             "sweep --quiet --shard 2/2 --out %s/shards/2 %s/config.ini\n"
             "sweep --quiet --shard 1/2 --out %s/shards/1 %s/config.ini\n"
             "sweep --quiet --shard 2/2 --out %s/shards/2 %s/config.ini\n"
             "merge --out %s/result %s/shards/1 %s/shards/2\n",
             d, d, d, d, d, d, d, d, d);
    assert_string_equal(tu_read_text(log), want);
}

static void test_config_copy(void **state)
{
    (void)state;
    /* Axes in the file's order, light before medium, which is not the key table's; an external
     * method's section, [method.m2], comes back as itself (it was written as [method] with a key
     * m2.command, which does not load: "unknown section"). */
    const char *cfg_path = cli_config("slurm-copy", "[experiment]\nname = copy\n"
                                                    "methods = mc, mp, m2\n"
                                                    "[light]\ntheta_deg = 45, 0, 30\n"
                                                    "[medium]\ng = 0.1:0.3:0.1\nalbedo = 0.7\n"
                                                    "[mc]\nphotons = 123456789\nseed = 42\n"
                                                    "[method.m2]\ncommand = m2 {scene} {out}\n");
    ppb_config cfg, back;
    ppb_grid *grid = ppb_grid_new(), *gback = ppb_grid_new();
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load_grid(&cfg, grid, cfg_path, &err), 0);
    char *text = ppb_slurm_config_text(&cfg, grid, "/scratch/j/result");
    assert_non_null(text);
    char copy[1300];
    snprintf(copy, sizeof copy, "%s.copy.ini", cfg_path);
    write_text(copy, text, 0);
    free(text);
    if (ppb_config_load_grid(&back, gback, copy, &err))
        fail_msg("the copy does not load: %s", err.msg);
    assert_string_equal(back.out_dir, "/scratch/j/result");
    assert_int_equal(back.mc.photons, 123456789);
    assert_int_equal(back.mc.seed, 42);
    assert_int_equal(gback->naxes, 2);
    for (int a = 0; a < 2; a++) {
        assert_int_equal(gback->axes[a].key, grid->axes[a].key);
        assert_int_equal(gback->axes[a].n, grid->axes[a].n);
        for (int v = 0; v < grid->axes[a].n; v++)
            assert_memory_equal(&gback->axes[a].values[v], &grid->axes[a].values[v],
                                sizeof(double)); /* bit for bit: %.17g round-trips */
    }
    /* Every resolved key the same, but the output directory. */
    snprintf(cfg.out_dir, sizeof cfg.out_dir, "/scratch/j/result");
    char *ta = NULL, *tb = NULL;
    size_t na = 0, nb = 0;
    FILE *fa = open_memstream(&ta, &na), *fb = open_memstream(&tb, &nb);
    ppb_config_write_resolved(&cfg, fa);
    ppb_config_write_resolved(&back, fb);
    fclose(fa);
    fclose(fb);
    assert_string_equal(ta, tb);
    free(ta);
    free(tb);
    ppb_grid_free(grid);
    ppb_grid_free(gback);
}

static void test_array_spec(void **state)
{
    (void)state;
    unsigned char pick[9] = {0, 1, 1, 1, 0, 1, 0, 1, 1};
    char buf[64];
    assert_int_equal(ppb_slurm_array_spec(pick, 8, buf, sizeof buf), 6);
    assert_string_equal(buf, "1-3,5,7-8");
    unsigned char none[4] = {0};
    assert_int_equal(ppb_slurm_array_spec(none, 3, buf, sizeof buf), 0);
    assert_string_equal(buf, "");
    unsigned char one[4] = {0, 0, 0, 1};
    assert_int_equal(ppb_slurm_array_spec(one, 3, buf, sizeof buf), 1);
    assert_string_equal(buf, "3");
}

static void test_parse_squeue(void **state)
{
    (void)state;
    const char *q = "17_2|ppb-a-1|RUNNING\n"
                    "17_4|ppb-a-1|PENDING\n"
                    "18|ppb-a-1-merge|PENDING\n"
                    "19_3|ppb-other-2|RUNNING\n" /* another job directory's */
                    "17_9|ppb-a-1|PENDING\n";    /* beyond the shards: not ours */
    unsigned char active[5] = {0};
    char ids[5][32] = {{0}}, merge[32];
    assert_int_equal(ppb_slurm_parse_squeue(q, "ppb-a-1", 4, active, ids, merge, sizeof merge), 2);
    assert_int_equal(active[1] + active[3], 0);
    assert_int_equal(active[2] + active[4], 2);
    assert_string_equal(ids[2], "17_2");
    assert_string_equal(ids[4], "17_4");
    assert_string_equal(merge, "18");
    memset(active, 0, sizeof active);
    assert_int_equal(ppb_slurm_parse_squeue("", "ppb-a-1", 4, active, NULL, merge, sizeof merge),
                     0);
    assert_string_equal(merge, "");
}

static void test_check_opts(void **state)
{
    (void)state;
    ppb_err err;
    const char *good_times[] = {"30",      "30:00",      "01:30:00", "2-0",
                                "2-12:00", "2-12:00:00", "UNLIMITED"};
    const char *bad_times[] = {"", "1h", "1:2:3:4", "-5", "1-", "1:", "x-1", "1;rm"};
    for (size_t k = 0; k < sizeof good_times / sizeof *good_times; k++) {
        ppb_slurm_opts o = {.shards = 1, .time = good_times[k]};
        if (ppb_slurm_check_opts(&o, &err))
            fail_msg("--time %s refused: %s", good_times[k], err.msg);
    }
    for (size_t k = 0; k < sizeof bad_times / sizeof *bad_times; k++) {
        ppb_slurm_opts o = {.shards = 1, .time = bad_times[k]};
        if (!ppb_slurm_check_opts(&o, &err))
            fail_msg("--time '%s' accepted", bad_times[k]);
        assert_has(err.msg, "--time");
    }
    const char *good_mem[] = {"4000", "4G", "512M"}, *bad_mem[] = {"", "4GB", "G", "-1", "4 G"};
    for (size_t k = 0; k < 3; k++) {
        ppb_slurm_opts o = {.shards = 1, .mem = good_mem[k]};
        assert_int_equal(ppb_slurm_check_opts(&o, &err), 0);
    }
    for (size_t k = 0; k < 5; k++) {
        ppb_slurm_opts o = {.shards = 1, .mem = bad_mem[k]};
        assert_int_equal(ppb_slurm_check_opts(&o, &err), -1);
    }
    ppb_slurm_opts p = {.shards = 1, .partition = "gpu,short"};
    assert_int_equal(ppb_slurm_check_opts(&p, &err), 0);
    p.partition = "a b";
    assert_int_equal(ppb_slurm_check_opts(&p, &err), -1);
    ppb_slurm_opts n = {.shards = PPB_SLURM_MAX_SHARDS + 1};
    assert_int_equal(ppb_slurm_check_opts(&n, &err), -1);
}

/* --account, --qos, --gres and --sbatch lines (drivers/slurm.h): account, qos and the free
 * lines on every job, gres on the tasks (and check.sh) only, each line as given; refused,
 * naming the option, where a value would not stay one #SBATCH line or is not an sbatch option
 * (a newline followed by a command, a tab, a ';', no leading "--", an option the scripts set
 * themselves). Expected text: sbatch(1)'s option names, as the scripts write them. */
static void test_account_qos_gres_sbatch(void **state)
{
    (void)state;
    ppb_slurm_job job = sweep_job("/scratch/j");
    const char *lines[] = {"--constraint=a100", "--reservation=r1"};
    ppb_slurm_opts o = {.shards = 4,
                        .account = "proj-42",
                        .qos = "normal",
                        .gres = "gpu:a100:1",
                        .sbatch = lines,
                        .nsbatch = 2};
    ppb_err err;
    assert_int_equal(ppb_slurm_check_opts(&o, &err), 0);
    char *a = ppb_slurm_array_script(&job, &o), *m = ppb_slurm_merge_script(&job, &o);
    char *c = ppb_slurm_check_script(&job, &o, "/src");
    const char *every = "#SBATCH --account=proj-42\n#SBATCH --qos=normal\n";
    const char *extra = "#SBATCH --constraint=a100\n#SBATCH --reservation=r1\n";
    for (int k = 0; k < 3; k++) {
        char *t = k == 0 ? a : k == 1 ? m : c;
        assert_has(t, every);
        assert_has(t, extra);
        if (k == 1)
            assert_lacks(t, "--gres"); /* the merge needs no device */
        else
            assert_has(t, "#SBATCH --gres=gpu:a100:1\n");
    }
    assert_has(c, "#SBATCH --job-name=ppb-sw-0badcafe-check\n");
    assert_has(c, "source=${PPBENCH_SOURCE:-'/src'}\n");
    free(a);
    free(m);
    free(c);
    const struct {
        const char *opt, *account, *qos, *gres, *line;
    } bad[] = {
        {"--account", "a b", NULL, NULL, NULL},
        {"--account", "a\nb", NULL, NULL, NULL},
        {"--qos", NULL, "q;rm", NULL, NULL},
        {"--gres", NULL, NULL, "gpu:1\n", NULL},
        {"--sbatch", NULL, NULL, NULL, "--constraint=x\ntouch /tmp/owned"},
        {"--sbatch", NULL, NULL, NULL, "--constraint=x\ttab"},
        {"--sbatch", NULL, NULL, NULL, ""},
        {"--sbatch", NULL, NULL, NULL, "constraint=x"},
        {"--sbatch", NULL, NULL, NULL, "--array=1-9"},
        {"--sbatch", NULL, NULL, NULL, "--output=/tmp/x"},
        {"--sbatch", NULL, NULL, NULL, "--dependency=afterok:1"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        ppb_slurm_opts b = {.shards = 1,
                            .account = bad[k].account,
                            .qos = bad[k].qos,
                            .gres = bad[k].gres,
                            .sbatch = &bad[k].line,
                            .nsbatch = bad[k].line ? 1 : 0};
        if (ppb_slurm_check_opts(&b, &err) != -1)
            fail_msg("case %zu (%s) accepted", k, bad[k].opt);
        assert_has(err.msg, bad[k].opt);
    }
}

/* check.sh run by bash on this machine (which has what a node needs: the built binary's
 * libraries, the kernel sources, PoCL): "ok on <host>", exit 0, the device list printed; with
 * the kernel sources unreadable ($PPBENCH_SOURCE, as ppbench reads it) it names them and exits
 * 1. */
static void test_check_script_runs(void **state)
{
    (void)state;
    const char *d = tu_scratch("slurm-check");
    char path[1300];
    ppb_slurm_job job = sweep_job(d);
    ppb_slurm_opts o = {.shards = 4};
    assert_int_equal(tu_sh("cp '%s' '%s/ppbench'", tu_bin(), d), 0);
    char *c = ppb_slurm_check_script(&job, &o, PPB_SOURCE_DIR);
    snprintf(path, sizeof path, "%s/check.sh", d);
    write_text(path, c, 1);
    free(c);
    assert_int_equal(tu_sh("bash '%s/check.sh' > '%s/out' 2>&1", d, d), 0);
    snprintf(path, sizeof path, "%s/out", d);
    const char *out = tu_read_text(path);
    assert_has(out, "ppbench slurm check: ok on ");
    assert_has(out, "0: ");
    assert_int_equal(
        tu_sh("PPBENCH_SOURCE=/nonexistent-source bash '%s/check.sh' > '%s/out' 2>&1", d, d), 1);
    out = tu_read_text(path);
    assert_has(out, "cannot read the kernel sources in /nonexistent-source");
    assert_lacks(out, "ok on");
}

static void test_shell_quote(void **state)
{
    (void)state;
    char buf[64];
    assert_int_equal(ppb_slurm_shell_quote("a'b c", buf, sizeof buf), 10);
    assert_string_equal(buf, "'a'\\''b c'");
    /* Too small: cut, but the length needed is still returned. */
    assert_int_equal(ppb_slurm_shell_quote("abcdef", buf, 4), 8);
    assert_string_equal(buf, "'ab");
}

/* The stamp line of a job directory's job.txt. */
static const char *stamp_of(const char *dir)
{
    char path[1300];
    static char stamp[256];
    snprintf(path, sizeof path, "%s/job.txt", dir);
    const char *t = tu_read_text(path);
    const char *p = strstr(t, "ppbench slurm job: ");
    assert_non_null(p);
    snprintf(stamp, sizeof stamp, "%.*s", (int)strcspn(p + 19, "\n"), p + 19);
    return stamp;
}

static void test_submit_with_stand_ins(void **state)
{
    (void)state;
    char cfg[1200]; /* cli_config's buffer is reused by the next call */
    snprintf(cfg, sizeof cfg, "%s",
             cli_config("slurm-cli", "[experiment]\nname = cli\nmethods = mc\n"
                                     "[mc]\nphotons = 3000\n"));
    char d[1100], env[2600], args[4000], path[1300];
    snprintf(d, sizeof d, "%s", tu_scratch("slurm-submit"));
    /* sbatch logs its arguments and prints the next id from 101; squeue prints queue.txt. */
    assert_int_equal(
        tu_sh("mkdir -p '%s/bin' && echo 100 > '%s/next' && : > '%s/queue.txt'", d, d, d), 0);
    char text[8000];
    snprintf(text, sizeof text,
             "#!/bin/sh\necho \"sbatch $*\" >> '%s/calls.log'\nn=$(($(cat '%s/next') + 1))\n"
             "echo $n > '%s/next'\necho $n\n",
             d, d, d);
    snprintf(path, sizeof path, "%s/bin/sbatch", d);
    write_text(path, text, 1);
    snprintf(text, sizeof text,
             "#!/bin/sh\necho \"squeue $*\" >> '%s/calls.log'\ncat '%s/queue.txt'\n", d, d);
    snprintf(path, sizeof path, "%s/bin/squeue", d);
    write_text(path, text, 1);
    snprintf(text, sizeof text, "#!/bin/sh\necho \"scancel $*\" >> '%s/calls.log'\n", d);
    snprintf(path, sizeof path, "%s/bin/scancel", d);
    write_text(path, text, 1);
    snprintf(env, sizeof env, "PATH='%s/bin':\"$PATH\"", d);

    /* Without --submit: the commands, nothing called. */
    snprintf(args, sizeof args, "slurm --shards 3 --out %s/job %s", d, cfg);
    cli_expect_env(env, args, 0, "jid=$(sbatch --parsable --array=1-3 ");
    snprintf(path, sizeof path, "%s/calls.log", d);
    assert_int_not_equal(access(path, F_OK), 0);
    /* The first submission: the whole array, the merge after it. */
    snprintf(args, sizeof args, "slurm --shards 3 --out %s/job --submit %s", d, cfg);
    cli_expect_env(env, args, 0, "submitted: merge job 102, after afterok:101");
    char want[16000];
    snprintf(want, sizeof want,
             "squeue -h -r --name=%s,%s-merge -o %%i|%%j|%%T\n"
             "sbatch --parsable --array=1-3 %s/job/job.sh\n"
             "sbatch --parsable --dependency=afterok:101 %s/job/merge.sh\n",
             "NAME", "NAME", d, d);
    /* The job name is the module's (ppb-cli-<hash of the directory>): read it from job.txt. */
    char jobtxt[1300];
    snprintf(jobtxt, sizeof jobtxt, "%s/job/job.txt", d);
    const char *jt = tu_read_text(jobtxt);
    const char *nm = strstr(jt, "Slurm job name ");
    assert_non_null(nm);
    char name[160];
    snprintf(name, sizeof name, "%.*s", (int)strcspn(nm + 15, "\n"), nm + 15);
    assert_has(name, "ppb-cli-");
    snprintf(want, sizeof want,
             "squeue -h -r --name=%s,%s-merge -o %%i|%%j|%%T\n"
             "sbatch --parsable --array=1-3 %s/job/job.sh\n"
             "sbatch --parsable --dependency=afterok:101 %s/job/merge.sh\n",
             name, name, d, d);
    assert_string_equal(tu_read_text(path), want);

    /* Shard 1 done, shard 2 still running, shard 3 failed (neither done nor queued); the merge
     * waits on the array for ever: re-run submits shard 3 alone, cancels the merge, and the new
     * merge waits on the new array and on task 101_2. */
    char job_dir[1200], mark[1300];
    snprintf(job_dir, sizeof job_dir, "%s/job", d);
    snprintf(mark, sizeof mark, "%s/job/done/1", d);
    char line[300];
    snprintf(line, sizeof line, "%s\n", stamp_of(job_dir));
    write_text(mark, line, 0);
    snprintf(text, sizeof text, "101_2|%s|RUNNING\n102|%s-merge|PENDING\n", name, name);
    snprintf(mark, sizeof mark, "%s/queue.txt", d);
    write_text(mark, text, 0);
    assert_int_equal(tu_sh(": > '%s'", path), 0);
    cli_expect_env(env, args, 0, "submitted: merge job 104, after afterok:103:101_2");
    assert_has(cli_out, "shards done: 1 of 3");
    assert_has(cli_out, "cancelled: merge job 102");
    assert_has(cli_out, "submitted: array job 103, task 3\n");
    snprintf(want, sizeof want,
             "scancel 102\n"
             "sbatch --parsable --array=3 %s/job/job.sh\n"
             "sbatch --parsable --dependency=afterok:103:101_2 %s/job/merge.sh\n",
             d, d);
    const char *calls = tu_read_text(path);
    assert_non_null(strstr(calls, want));

    /* All done and merged, nothing queued: nothing submitted. */
    for (int i = 1; i <= 3; i++) {
        snprintf(mark, sizeof mark, "%s/job/done/%d", d, i);
        write_text(mark, line, 0);
    }
    snprintf(mark, sizeof mark, "%s/job/done/merge", d);
    write_text(mark, line, 0);
    snprintf(mark, sizeof mark, "%s/queue.txt", d);
    write_text(mark, "", 0);
    assert_int_equal(tu_sh(": > '%s'", path), 0);
    cli_expect_env(env, args, 0, "nothing to submit: every shard is done and merged");
    assert_lacks(tu_read_text(path), "sbatch");

    /* Another seed into the same directory: refused, exit 2, nothing written or submitted. */
    snprintf(args, sizeof args, "slurm --shards 3 --set mc.seed=7 --out %s/job --submit %s", d,
             cfg);
    cli_expect_env(env, args, 2, "holds the job of another config");
    snprintf(args, sizeof args, "slurm --shards 2 --out %s/job %s", d, cfg);
    cli_expect_env(env, args, 2, "holds the job of another --shards");
    /* A directory that is not a job directory. */
    snprintf(mark, sizeof mark, "%s/foreign/x", d);
    assert_int_equal(tu_sh("mkdir -p '%s/foreign' && : > '%s'", d, mark), 0);
    snprintf(args, sizeof args, "slurm --shards 2 --out %s/foreign %s", d, cfg);
    cli_expect_env(env, args, 2, "not empty and not a ppbench slurm job directory");
    /* A config with neither a list nor mc. */
    const char *det = cli_config("slurm-det", "[experiment]\nname = det\nmethods = mp\n");
    snprintf(args, sizeof args, "slurm --shards 2 --out %s/det %s", d, det);
    cli_expect_env(env, args, 2, "nothing to shard");
    /* More shards than photons. */
    snprintf(args, sizeof args, "slurm --shards 4 --set mc.photons=3 --out %s/few %s", d, cfg);
    cli_expect_env(env, args, 2, "--shards 4: more shards than photons (3)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_array_script_text),
        cmocka_unit_test(test_merge_script_text),
        cmocka_unit_test(test_scripts_run),
        cmocka_unit_test(test_config_copy),
        cmocka_unit_test(test_array_spec),
        cmocka_unit_test(test_parse_squeue),
        cmocka_unit_test(test_check_opts),
        cmocka_unit_test(test_account_qos_gres_sbatch),
        cmocka_unit_test(test_check_script_runs),
        cmocka_unit_test(test_shell_quote),
        cmocka_unit_test(test_submit_with_stand_ins),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
