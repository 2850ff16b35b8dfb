/* main.c: the command line. Parses options, dispatches to the experiment runner, the sweep
 * driver, the device list and the benchmarks, and maps failures to the documented exit
 * codes. Everything else lives in its module. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/progress.h"
#include "drivers/experiment.h"
#include "drivers/mc_shard.h"
#include "drivers/perf.h"
#include "drivers/report.h"
#include "drivers/sweep.h"
#include "methods/registry.h"
#include "model/config.h"
#include "model/grid.h"
#include "runtime/ocl.h"

enum { EXIT_OK = 0, EXIT_RUN = 1, EXIT_USAGE = 2, EXIT_INTERRUPTED = 130 };

static void usage(FILE *out)
{
    fprintf(out,
            "usage: ppbench COMMAND [options]\n"
            "\n"
            "commands:\n"
            "  run CONFIG...       run every method of each experiment config and write\n"
            "                      SPEC.md section 8's outputs under [output] dir\n"
            "  sweep CONFIG        run a grid sweep (keys holding lists) into <dir>/sweep.csv\n"
            "  merge DIR...        merge sweep shards (--out DIR) into one sweep.csv\n"
            "  mc-shard CONFIG     trace part --shard I/N of the config's photons into\n"
            "                      <--out>/mc_tallies.bin\n"
            "  mc-merge CONFIG DIR...  add the shards' tallies and write mc, mc1 outputs to\n"
            "                      --out, byte-identical to one run of the whole budget\n"
            "  devices             list OpenCL devices (index: platform / device)\n"
            "  keys                print every config key with its default and range\n"
            "  perf                benchmarks: solver, ray marcher, Monte Carlo\n"
            "  report DIR CASE...  table2.csv/.md and README.md of a study from its cases\n"
            "\n"
            "options:\n"
            "  --device SEL        OpenCL device: index or name substring\n"
            "                      (default: $PPBENCH_DEVICE, else device 0)\n"
            "  --out DIR           output directory (overrides [output] dir)\n"
            "  --set SEC.KEY=VAL   override a config key (may repeat)\n"
            "  --shard I/N         sweep: run only the I-th of N parts (1-based)\n"
            "  --jobs J            sweep: J processes on this machine (default 1)\n"
            "  --yes               sweep: allow a grid larger than the safety limit\n"
            "  --quiet             no progress lines on stderr\n"
            "  -h, --help          this text\n"
            "\n"
            "methods:\n");
    for (int i = 0; i < ppb_method_count(); i++)
        fprintf(out, "  %-8s %s\n", ppb_method_at(i)->id, ppb_method_at(i)->summary);
    fprintf(out,
            "\n"
            "examples:\n"
            "  ppbench run configs/uniform_g0_normal.ini\n"
            "  ppbench run --device 0 --set mc.photons=1e6 --out /tmp/x configs/density_step.ini\n"
            "  ppbench sweep --shard 2/3 configs/sweep_example.ini\n"
            "  PPBENCH_DEVICE=pthread ppbench devices\n"
            "\n"
            "exit codes: 0 success; 1 a run failed (OpenCL, I/O, numerics); 2 bad command\n"
            "line or config; 130 interrupted (what was done is written, marked partial).\n");
}

typedef struct cli {
    const char *device, *out;
    const char *sets[64];
    int nsets;
    int quiet, yes;
    int shard_i, shard_n;
    int jobs;
    const char *args[256];
    int nargs;
} cli;

static int parse_shard(const char *s, cli *c)
{
    return sscanf(s, "%d/%d", &c->shard_i, &c->shard_n) == 2 && c->shard_n >= 1 &&
           c->shard_i >= 1 && c->shard_i <= c->shard_n;
}

/* Returns 0, or EXIT_USAGE having printed why. */
static int parse_cli(int argc, char **argv, cli *c)
{
    memset(c, 0, sizeof *c);
    c->shard_i = c->shard_n = 1;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        int has_next = i + 1 < argc;
        if (!strcmp(a, "--quiet")) {
            c->quiet = 1;
        } else if (!strcmp(a, "--yes")) {
            c->yes = 1;
        } else if (!strcmp(a, "--device") && has_next) {
            c->device = argv[++i];
        } else if (!strcmp(a, "--out") && has_next) {
            c->out = argv[++i];
        } else if (!strcmp(a, "--set") && has_next && c->nsets < 64) {
            c->sets[c->nsets++] = argv[++i];
        } else if (!strcmp(a, "--jobs") && has_next) {
            c->jobs = atoi(argv[++i]);
            if (c->jobs < 1 || c->jobs > 64) {
                fprintf(stderr, "ppbench: --jobs %s: expected 1 to 64\n", argv[i]);
                return EXIT_USAGE;
            }
        } else if (!strcmp(a, "--shard") && has_next) {
            if (!parse_shard(argv[++i], c)) {
                fprintf(stderr, "ppbench: --shard %s: expected I/N with 1 <= I <= N\n", argv[i]);
                return EXIT_USAGE;
            }
        } else if (a[0] == '-') {
            fprintf(stderr, "ppbench: %s: unknown option or missing value (see --help)\n", a);
            return EXIT_USAGE;
        } else if (c->nargs < 256) {
            c->args[c->nargs++] = a;
        }
    }
    return 0;
}

/* Loads a config with its grid (the keys holding lists) and applies --set and --out. The
 * method ids are checked against the registry after the file and after each --set, where the
 * config checks its own keys. */
static int load_config(const cli *c, const char *path, ppb_config *cfg, ppb_grid *grid,
                       ppb_err *err)
{
    if (ppb_config_load_grid(cfg, grid, path, err) || ppb_methods_check(cfg, err))
        return -1;
    for (int i = 0; i < c->nsets; i++) {
        char sec[64], key[64];
        const char *eq = strchr(c->sets[i], '=');
        const char *dot = strchr(c->sets[i], '.');
        if (!eq || !dot || dot > eq || sscanf(c->sets[i], "%63[^.].%63[^=]", sec, key) != 2)
            return ppb_fail(err, "--set %s: expected SECTION.KEY=VALUE", c->sets[i]);
        if (ppb_config_set_grid(cfg, grid, sec, key, eq + 1, err) || ppb_methods_check(cfg, err))
            return -1;
    }
    if (c->out)
        snprintf(cfg->out_dir, sizeof cfg->out_dir, "%s", c->out);
    return 0;
}

/* A config or option the user must fix: printed once, exit code 2. */
static int usage_error(const ppb_err *err)
{
    fprintf(stderr, "ppbench: %s\n", err->msg);
    return EXIT_USAGE;
}

static int cmd_run(const cli *c)
{
    if (c->nargs == 0) {
        fprintf(stderr, "ppbench run: no config given (see --help)\n");
        return EXIT_USAGE;
    }
    ppb_grid *grid = ppb_grid_new();
    if (!grid) {
        fprintf(stderr, "ppbench: out of memory\n");
        return EXIT_RUN;
    }
    ppb_err err = {{0}};
    int code = EXIT_OK;
    for (int i = 0; i < c->nargs && code == EXIT_OK; i++) {
        ppb_config cfg;
        if (load_config(c, c->args[i], &cfg, grid, &err)) {
            code = usage_error(&err);
            break;
        }
        if (grid->naxes > 0) {
            fprintf(stderr, "ppbench: %s: keys hold lists (a sweep): use `ppbench sweep`\n",
                    cfg.path);
            code = EXIT_USAGE;
            break;
        }
        ppb_experiment ex = {0};
        ppb_run_ctx ctx = {.device_selector = c->device, .quiet = c->quiet};
        int rc = ppb_experiment_compute(&ex, &cfg, &ctx, &err);
        if (rc == 0)
            rc = ppb_experiment_write(&ex, &err);
        int partial = ex.partial;
        ppb_experiment_free(&ex);
        ppb_ctx_close(&ctx);
        if (rc) {
            fprintf(stderr, "ppbench: %s: %s\n", cfg.path, err.msg);
            code = EXIT_RUN;
        } else {
            if (!c->quiet)
                fprintf(stderr, "%s: wrote %s%s\n", cfg.name, cfg.out_dir,
                        partial ? " (partial: interrupted)" : "");
            if (partial)
                code = EXIT_INTERRUPTED;
        }
    }
    ppb_grid_free(grid);
    return code;
}

static int cmd_devices(void)
{
    ppb_err err = {{0}};
    if (ppb_ocl_list(stdout, &err) < 0) {
        fprintf(stderr, "ppbench: %s\n", err.msg);
        return EXIT_RUN;
    }
    return EXIT_OK;
}

static int cmd_perf(const cli *c)
{
    ppb_err err = {{0}};
    ppb_run_ctx ctx = {.device_selector = c->device, .quiet = 1};
    int rc = ppb_perf_all(&ctx, stdout, &err);
    ppb_ctx_close(&ctx);
    if (rc) {
        fprintf(stderr, "ppbench perf: %s\n", err.msg);
        return EXIT_RUN;
    }
    return EXIT_OK;
}

static int cmd_sweep(const cli *c)
{
    if (c->nargs != 1) {
        fprintf(stderr, "ppbench sweep: give exactly one config (see --help)\n");
        return EXIT_USAGE;
    }
    ppb_grid *grid = ppb_grid_new();
    if (!grid) {
        fprintf(stderr, "ppbench: out of memory\n");
        return EXIT_RUN;
    }
    ppb_config cfg;
    ppb_err err = {{0}};
    if (load_config(c, c->args[0], &cfg, grid, &err)) {
        ppb_grid_free(grid);
        return usage_error(&err);
    }
    ppb_sweep_opts o = {.device = c->device,
                        .quiet = c->quiet,
                        .yes = c->yes,
                        .shard_i = c->shard_i,
                        .shard_n = c->shard_n,
                        .jobs = c->jobs};
    int rc = ppb_sweep_run(&cfg, grid, &o, &err);
    ppb_grid_free(grid);
    if (rc == PPB_SWEEP_BAD_CONFIG) {
        fprintf(stderr, "ppbench: %s\n", err.msg);
        return EXIT_USAGE;
    }
    if (rc) {
        fprintf(stderr, "ppbench sweep: %s\n", err.msg);
        return EXIT_RUN;
    }
    return ppb_interrupted() ? EXIT_INTERRUPTED : EXIT_OK;
}

static int cmd_merge(const cli *c)
{
    if (c->nargs < 1 || !c->out) {
        fprintf(stderr, "ppbench merge: usage: ppbench merge --out DIR SHARD_DIR...\n");
        return EXIT_USAGE;
    }
    ppb_err err = {{0}};
    if (ppb_sweep_merge(c->args, c->nargs, c->out, &err)) {
        fprintf(stderr, "ppbench merge: %s\n", err.msg);
        return EXIT_RUN;
    }
    return EXIT_OK;
}

static int cmd_mc_shard(const cli *c, int merge)
{
    if (c->nargs < (merge ? 2 : 1) || (!merge && c->nargs != 1) || !c->out) {
        fprintf(stderr, "ppbench: usage: ppbench mc-shard --shard I/N --out DIR CONFIG | "
                        "ppbench mc-merge --out DIR CONFIG SHARD_DIR...\n");
        return EXIT_USAGE;
    }
    /* One Monte Carlo run split by photons: a config holding lists is refused as by `run`. */
    ppb_config cfg;
    ppb_err err = {{0}};
    if (load_config(c, c->args[0], &cfg, NULL, &err))
        return usage_error(&err);
    int rc = merge ? ppb_mc_shard_merge(&cfg, c->args + 1, c->nargs - 1, &err)
                   : ppb_mc_shard_run(&cfg, c->device, c->quiet, c->shard_i, c->shard_n, &err);
    if (rc) {
        fprintf(stderr, "ppbench: %s: %s\n", cfg.path, err.msg);
        return EXIT_RUN;
    }
    return EXIT_OK;
}

static int cmd_report(const cli *c)
{
    if (c->nargs < 2) {
        fprintf(stderr, "ppbench report: usage: ppbench report STUDY_DIR CASE...\n");
        return EXIT_USAGE;
    }
    ppb_err err = {{0}};
    if (ppb_report_write(c->args[0], c->args + 1, c->nargs - 1, &err)) {
        fprintf(stderr, "ppbench report: %s\n", err.msg);
        return EXIT_RUN;
    }
    return EXIT_OK;
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") ||
        !strcmp(argv[1], "help")) {
        usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? EXIT_USAGE : EXIT_OK;
    }
    cli c;
    int rc = parse_cli(argc, argv, &c);
    if (rc)
        return rc;
    ppb_progress_install_signals();
    const char *cmd = argv[1];
    if (!strcmp(cmd, "run"))
        return cmd_run(&c);
    if (!strcmp(cmd, "devices"))
        return cmd_devices();
    if (!strcmp(cmd, "keys")) {
        ppb_config_write_keys(stdout);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "perf"))
        return cmd_perf(&c);
    if (!strcmp(cmd, "sweep"))
        return cmd_sweep(&c);
    if (!strcmp(cmd, "merge"))
        return cmd_merge(&c);
    if (!strcmp(cmd, "mc-shard") || !strcmp(cmd, "mc-merge"))
        return cmd_mc_shard(&c, !strcmp(cmd, "mc-merge"));
    if (!strcmp(cmd, "report"))
        return cmd_report(&c);
    fprintf(stderr, "ppbench: %s: unknown command (see --help)\n", cmd);
    return EXIT_USAGE;
}
