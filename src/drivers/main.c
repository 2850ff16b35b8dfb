/* main.c: the command line. Parses options, checks everything that can be checked before any
 * work (options, the device, every config, the output directories), dispatches to the
 * experiment runner, the sweep driver, the device list and the benchmarks, and maps failures to
 * the documented exit codes. Everything else lives in its module. */
#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/child.h"
#include "base/memory.h"
#include "base/progress.h"
#include "drivers/experiment.h"
#include "drivers/mc_shard.h"
#include "drivers/object.h"
#include "drivers/perf.h"
#include "drivers/report.h"
#include "drivers/score.h"
#include "drivers/study_guard.h"
#include "drivers/study_score.h"
#include "drivers/slurm.h"
#include "drivers/sweep.h"
#include "io/scene_json.h"
#include "methods/object_registry.h"
#include "methods/registry.h"
#include "physics/ppsolver.h"
#include "model/config.h"
#include "model/grid.h"
#include "model/materials.h"
#include "runtime/ocl.h"

#ifndef PPB_VERSION
#define PPB_VERSION "unknown"
#endif

enum { EXIT_OK = 0, EXIT_RUN = 1, EXIT_USAGE = 2, EXIT_INTERRUPTED = 130 };

/* The options; each command lists those that apply to it, and any other is refused (an option
 * a command silently ignored looked as if it had been used). */
enum {
    OPT_DEVICE = 1 << 0,
    OPT_OUT = 1 << 1,
    OPT_SET = 1 << 2,
    OPT_SHARD = 1 << 3,
    OPT_JOBS = 1 << 4,
    OPT_YES = 1 << 5,
    OPT_QUIET = 1 << 6,
    OPT_REF = 1 << 20,
    OPT_REF_CACHE = 1 << 21,
    OPT_NO_REF_CACHE = 1 << 22,
    OPT_SHARDS = 1 << 7, /* slurm's: its job array and scripts (drivers/slurm.h) */
    OPT_PARTITION = 1 << 8,
    OPT_TIME = 1 << 9,
    OPT_MEM = 1 << 10,
    OPT_CPUS = 1 << 11,
    OPT_SUBMIT = 1 << 12,
    OPT_ACCOUNT = 1 << 13,
    OPT_QOS = 1 << 14,
    OPT_GRES = 1 << 15,
    OPT_SBATCH = 1 << 16,
    OPT_METHODS = 1 << 17, /* study-score's */
    OPT_RADIANCE_DIR = 1 << 18,
};

static const struct option_doc {
    unsigned bit;
    const char *name, *arg, *help; /* help: lines after the first are indented under it */
} option_docs[] = {
    {OPT_DEVICE, "--device", "SEL",
     "OpenCL device: index or name substring\n(default: $PPBENCH_DEVICE, else device 0)"},
    {OPT_OUT, "--out", "DIR", "output directory (overrides [output] dir)"},
    {OPT_SET, "--set", "SEC.KEY=VAL", "override a config key (may repeat)"},
    {OPT_SHARD, "--shard", "I/N",
     "run only the I-th of N parts (1-based): sweep points,\nmc-shard photons"},
    {OPT_JOBS, "--jobs", "J", "sweep: J processes on this machine (1 to 64, default 1)"},
    {OPT_YES, "--yes", NULL, "sweep: allow a grid larger than the safety limit"},
    {OPT_QUIET, "--quiet", NULL, "no progress lines on stderr"},
    {OPT_REF, "--ref", "DIR", "score: the finished experiment to score against"},
    {OPT_REF_CACHE, "--ref-cache", "DIR",
     "run, sweep: reuse the Monte Carlo reference stored under\nDIR by its fingerprint (and "
     "store it there); default:\n$PPBENCH_CACHE, else $XDG_CACHE_HOME/ppbench/ref, else\n"
     "~/.cache/ppbench/ref ($PPBENCH_CACHE set empty: none)"},
    {OPT_NO_REF_CACHE, "--no-ref-cache", NULL,
     "run, sweep: no reference cache: trace the Monte Carlo"},
    {OPT_METHODS, "--methods", "A,B",
     "study-score: the methods to score (built-in ids, or\nexternal ones defined by CONFIG or "
     "--set method.NAME...)"},
    {OPT_RADIANCE_DIR, "--radiance-dir", "DIR",
     "study-score: score the files DIR/<case>.csv (or\nDIR/<case>/radiance.csv), one per case"},
    {OPT_SHARDS, "--shards", "N",
     "slurm: N array tasks, each one shard (1 to 1000; at most\nthe grid points or photons)"},
    {OPT_PARTITION, "--partition", "P", "slurm: #SBATCH --partition (default: the cluster's)"},
    {OPT_TIME, "--time", "T",
     "slurm: #SBATCH --time per task and for the merge\n(minutes, "
     "HH:MM:SS, D-HH:MM, ...; default: the partition's)"},
    {OPT_MEM, "--mem", "M", "slurm: #SBATCH --mem per task (MB, or with K/M/G/T)"},
    {OPT_CPUS, "--cpus", "C", "slurm: #SBATCH --cpus-per-task (1 to 4096)"},
    {OPT_ACCOUNT, "--account", "A", "slurm: #SBATCH --account, every job"},
    {OPT_QOS, "--qos", "Q", "slurm: #SBATCH --qos, every job"},
    {OPT_GRES, "--gres", "G", "slurm: #SBATCH --gres per task (e.g. gpu:1)"},
    {OPT_SBATCH, "--sbatch", "LINE",
     "slurm: one more #SBATCH line, every job (may repeat;\ne.g. --sbatch --constraint=a100)"},
    {OPT_SUBMIT, "--submit", NULL,
     "slurm: submit the shards neither done nor queued, and a\nmerge job after them (sbatch "
     "--dependency=afterok)"},
};
enum { NOPTIONS = sizeof option_docs / sizeof option_docs[0] };

/* The parsed command line. sets and args point into argv (no fixed limit on either). */
typedef struct cli {
    const char *device, *out;
    const char **sets;
    int nsets;
    int quiet, yes;
    int shard_i, shard_n;
    int jobs;
    const char *ref;
    const char *methods, *radiance_dir; /* study-score's */
    const char *ref_cache;
    int no_ref_cache;
    int shards, cpus, submit; /* slurm's */
    const char *partition, *time, *mem;
    const char *account, *qos, *gres;
    const char **sbatch; /* --sbatch lines, nsbatch of them */
    int nsbatch;
    const char **args;
    int nargs;
} cli;

typedef struct command {
    const char *name;
    const char *operands; /* after the options, e.g. "CONFIG..."; NULL: none */
    unsigned required;    /* OPT_* bits it cannot do without (shown in the synopsis) */
    const char *summary;  /* what it does; '\n' breaks the line in the overview */
    const char *example;
    unsigned opts;  /* OPT_* bits that apply */
    int takes_args; /* 0: any operand is refused */
    int (*run)(const cli *c);
} command;

/* A whole decimal number in [lo, hi]: digits only, no sign, fraction, exponent or trailing text
 * (atoi took "2x" and "2.9" as 2), and no overflow; stop is the character that must follow
 * it ('\0': the end of the string). */
static int parse_int(const char *s, long lo, long hi, int *v, char stop)
{
    if (*s < '0' || *s > '9')
        return 0;
    errno = 0;
    char *end;
    long x = strtol(s, &end, 10);
    if (errno || *end != stop || x < lo || x > hi)
        return 0;
    *v = (int)x;
    return 1;
}

static int parse_shard(const char *s, cli *c)
{
    const char *slash = strchr(s, '/');
    return slash && parse_int(s, 1, INT_MAX, &c->shard_i, '/') &&
           parse_int(slash + 1, 1, INT_MAX, &c->shard_n, '\0') && c->shard_i <= c->shard_n;
}

enum { PARSE_HELP = -1 };

/* The longest directory --out may name: what ppb_config holds (it was cut silently, and the
 * results landed in the shorter path). */
enum { OUT_MAX = sizeof(((ppb_config *)0)->out_dir) - 1 };

/* Parses argv[2..] for cmd. Returns 0, PARSE_HELP for -h/--help, or EXIT_USAGE having printed
 * why: an unknown option, a missing or malformed value, or an option that does not apply to
 * cmd. */
static int parse_cli(int argc, char **argv, const command *cmd, cli *c)
{
    memset(c, 0, sizeof *c);
    c->shard_i = c->shard_n = 1;
    c->sets = calloc((size_t)argc, sizeof *c->sets);
    c->args = calloc((size_t)argc, sizeof *c->args);
    c->sbatch = calloc((size_t)argc, sizeof *c->sbatch);
    if (!c->sets || !c->args || !c->sbatch) {
        fprintf(stderr, "ppbench: out of memory\n");
        return EXIT_RUN;
    }
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (a[0] != '-' || !a[1]) {
            c->args[c->nargs++] = a;
            continue;
        }
        if (!strcmp(a, "-h") || !strcmp(a, "--help"))
            return PARSE_HELP;
        const struct option_doc *o = NULL;
        for (int k = 0; k < NOPTIONS; k++)
            if (!strcmp(a, option_docs[k].name))
                o = &option_docs[k];
        if (!o) {
            fprintf(stderr, "ppbench: %s: unknown option (see ppbench %s --help)\n", a, cmd->name);
            return EXIT_USAGE;
        }
        if (!(cmd->opts & o->bit)) {
            fprintf(stderr,
                    "ppbench %s: %s does not apply to this command (see ppbench %s --help)\n",
                    cmd->name, a, cmd->name);
            return EXIT_USAGE;
        }
        const char *v = NULL;
        if (o->arg) {
            if (i + 1 >= argc) {
                fprintf(stderr, "ppbench: %s: missing value %s (see ppbench %s --help)\n", a,
                        o->arg, cmd->name);
                return EXIT_USAGE;
            }
            v = argv[++i];
        }
        switch (o->bit) {
        case OPT_QUIET:
            c->quiet = 1;
            break;
        case OPT_YES:
            c->yes = 1;
            break;
        case OPT_REF:
            c->ref = v;
            break;
        case OPT_METHODS:
            c->methods = v;
            break;
        case OPT_RADIANCE_DIR:
            c->radiance_dir = v;
            break;
        case OPT_REF_CACHE:
            c->ref_cache = v;
            break;
        case OPT_NO_REF_CACHE:
            c->no_ref_cache = 1;
            break;
        case OPT_SUBMIT:
            c->submit = 1;
            break;
        case OPT_PARTITION:
            c->partition = v;
            break;
        case OPT_TIME:
            c->time = v;
            break;
        case OPT_MEM:
            c->mem = v;
            break;
        case OPT_ACCOUNT:
            c->account = v;
            break;
        case OPT_QOS:
            c->qos = v;
            break;
        case OPT_GRES:
            c->gres = v;
            break;
        case OPT_SBATCH:
            c->sbatch[c->nsbatch++] = v;
            break;
        case OPT_SHARDS:
        case OPT_CPUS:
            if (!parse_int(v, 1, o->bit == OPT_SHARDS ? PPB_SLURM_MAX_SHARDS : 4096,
                           o->bit == OPT_SHARDS ? &c->shards : &c->cpus, '\0')) {
                fprintf(stderr, "ppbench: %s %s: expected a whole number from 1 to %d\n", a, v,
                        o->bit == OPT_SHARDS ? PPB_SLURM_MAX_SHARDS : 4096);
                return EXIT_USAGE;
            }
            break;
        case OPT_DEVICE:
            c->device = v;
            break;
        case OPT_OUT:
            if (!*v || strlen(v) > OUT_MAX) {
                fprintf(stderr, "ppbench: --out: %s (%zu characters; 1 to %d)\n",
                        *v ? "too long" : "empty", strlen(v), (int)OUT_MAX);
                return EXIT_USAGE;
            }
            c->out = v;
            break;
        case OPT_SET:
            c->sets[c->nsets++] = v;
            break;
        case OPT_JOBS:
            if (!parse_int(v, 1, 64, &c->jobs, '\0')) {
                fprintf(stderr, "ppbench: --jobs %s: expected a whole number from 1 to 64\n", v);
                return EXIT_USAGE;
            }
            break;
        case OPT_SHARD:
            if (!parse_shard(v, c)) {
                fprintf(stderr,
                        "ppbench: --shard %s: expected I/N, whole numbers with 1 <= I <= N <= %d\n",
                        v, INT_MAX);
                return EXIT_USAGE;
            }
            break;
        }
    }
    if (c->ref_cache && c->no_ref_cache) {
        fprintf(stderr, "ppbench %s: --ref-cache and --no-ref-cache: give one of them\n",
                cmd->name);
        return EXIT_USAGE;
    }
    if (c->ref_cache && !*c->ref_cache) {
        fprintf(stderr, "ppbench %s: --ref-cache: empty (use --no-ref-cache for none)\n",
                cmd->name);
        return EXIT_USAGE;
    }
    if (!cmd->takes_args && c->nargs > 0) {
        fprintf(stderr, "ppbench %s: unexpected argument '%s' (see ppbench %s --help)\n", cmd->name,
                c->args[0], cmd->name);
        return EXIT_USAGE;
    }
    return 0;
}

static void free_cli(cli *c)
{
    free(c->sets);
    free(c->args);
    free(c->sbatch);
}

/* The Monte Carlo reference cache of run and sweep (methods/mc_cache.h): --ref-cache DIR,
 * none with --no-ref-cache, else $PPBENCH_CACHE (set empty: none), else the user's cache
 * directory by the XDG base directory rule ($XDG_CACHE_HOME, else ~/.cache) under
 * ppbench/ref: per user and outside any checkout, so every run of every checkout shares the
 * references already traced, and a cleaner of caches may delete it (it is only ever a miss).
 * NULL: no cache (also when no home is known). buf holds a composed path. */
static const char *ref_cache_dir(const cli *c, char *buf, size_t cap)
{
    if (c->no_ref_cache)
        return NULL;
    if (c->ref_cache)
        return c->ref_cache;
    const char *env = getenv("PPBENCH_CACHE");
    if (env)
        return *env ? env : NULL;
    const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    int n;
    if (xdg && xdg[0] == '/') /* the XDG rule: a relative value is ignored */
        n = snprintf(buf, cap, "%s/ppbench/ref", xdg);
    else if (home && *home)
        n = snprintf(buf, cap, "%s/.cache/ppbench/ref", home);
    else
        return NULL;
    return n > 0 && (size_t)n < cap ? buf : NULL;
}

/* Loads a config with its grid (the keys holding lists), applies every --set and then --out.
 * The keys are checked against each other, and the method ids against the registry, once all
 * --set are applied: their order does not matter (model/config.h). */
static int load_config(const cli *c, const char *path, ppb_config *cfg, ppb_grid *grid,
                       ppb_err *err)
{
    if (ppb_config_load_sets(cfg, grid, path, c->sets, c->nsets, err) ||
        ppb_methods_check(cfg, err))
        return -1;
    /* A colour run's methods are checked against every channel's medium (mp refuses albedo 1
     * in any of them), before any work. */
    for (int ch = 0; cfg->channel == PPB_CHANNEL_RGB && ch < 3; ch++) {
        static ppb_config one; /* large: not on the stack */
        if (ppb_config_channel(cfg, ch, &one, err) || ppb_methods_check(&one, err))
            return -1;
    }
    if (c->out)
        snprintf(cfg->out_dir, sizeof cfg->out_dir, "%s", c->out);
    return 0;
}

/* A colour config (channel = rgb) where only `ppbench run` takes one (sweep, slurm,
 * mc-shard, mc-merge: one channel's experiment each). */
static int refuse_colour(const ppb_config *cfg, ppb_err *err)
{
    if (cfg->channel != PPB_CHANNEL_RGB)
        return 0;
    return ppb_config_key_fail(cfg, "medium", "channel", err,
                               "rgb (a colour run, docs/reference.md: Colour) is `ppbench run`'s "
                               "alone: give one channel here, r, g or b");
}

/* Commands whose methods call OpenBLAS (the slab solver, the march tables, rte2d). */
static int needs_blas(const command *cmd)
{
    return !strcmp(cmd->name, "run") || !strcmp(cmd->name, "sweep") || !strcmp(cmd->name, "perf") ||
           !strcmp(cmd->name, "mc-shard") || !strcmp(cmd->name, "object");
}

/* A config or option the user must fix: printed once, exit code 2. */
static int usage_error(const ppb_err *err)
{
    fprintf(stderr, "ppbench: %s\n", err->msg);
    return EXIT_USAGE;
}

/* Resolves --device (or $PPBENCH_DEVICE) before any work, so a bad one is a usage error even
 * when no method of the run needs OpenCL. The enumeration runs in a child process: this one
 * stays untouched by the OpenCL runtime until it opens the device itself, as before (a sweep
 * forks its --jobs workers, and a runtime initialised before fork() is unusable in them). */
static int check_device(const cli *c)
{
    const char *env = getenv("PPBENCH_DEVICE");
    if (!(c->device && *c->device) && !(env && *env))
        return 0; /* device 0, opened at first use; a CPU-only run needs none */
    int fd[2];
    ppb_err err = {{0}};
    fflush(NULL);
    pid_t pid = pipe(fd) < 0 ? -1 : fork();
    if (pid < 0) {
        fprintf(stderr, "ppbench: --device: cannot start the device check: %s\n", strerror(errno));
        return EXIT_RUN;
    }
    if (pid == 0) {
        close(fd[0]);
        int rc = ppb_ocl_select(c->device, &err) < 0;
        if (rc && write(fd[1], err.msg, strlen(err.msg)) < 0)
            rc = 1;
        _exit(rc);
    }
    close(fd[1]);
    size_t n = 0;
    ssize_t r;
    while (n < sizeof err.msg - 1 && (r = read(fd[0], err.msg + n, sizeof err.msg - 1 - n)) != 0)
        if (r > 0)
            n += (size_t)r;
        else if (errno != EINTR)
            break;
    err.msg[n] = '\0';
    close(fd[0]);
    int st;
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR)
        ;
    if (WIFEXITED(st) && WEXITSTATUS(st) == 0)
        return 0;
    if (!n)
        ppb_fail(&err, "--device %s: the device check failed", c->device ? c->device : env);
    return usage_error(&err);
}

/* Whether dir can be an output directory: it is one, or every prefix of it that exists is one
 * (mkdir -p makes the rest). Checked before any work: an --out naming a file used to fail only
 * after the computing. what names the setting ("--out", "file: [output] dir"). */
static int check_out_dir(const char *dir, const char *what, ppb_err *err)
{
    char buf[PPB_PATH_MAX];
    if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf)
        return ppb_fail(err, "%s: too long", what);
    for (size_t i = 1, len = strlen(buf); i <= len; i++) {
        if (buf[i] != '/' && buf[i] != '\0')
            continue;
        char keep = buf[i];
        buf[i] = '\0';
        struct stat st;
        int rc = stat(buf, &st);
        if (rc < 0 && errno == ENOENT)
            return 0;
        if (rc < 0)
            return ppb_fail(err, "%s %s: %s: %s", what, dir, buf, strerror(errno));
        if (!S_ISDIR(st.st_mode))
            return ppb_fail(err, "%s %s: %s is not a directory", what, dir, buf);
        buf[i] = keep;
    }
    if (access(dir, W_OK | X_OK) < 0)
        return ppb_fail(err, "%s %s: not writable: %s", what, dir, strerror(errno));
    return 0;
}

/* The output directory of a loaded config, checked; exit code 2 when it cannot be one. */
static int check_config_out(const cli *c, const ppb_config *cfg)
{
    char what[1100];
    snprintf(what, sizeof what, "%s%s", c->out ? "--out" : cfg->path,
             c->out ? "" : ": [output] dir");
    ppb_err err = {{0}};
    return check_out_dir(cfg->out_dir, what, &err) ? usage_error(&err) : 0;
}

/* The same directory spelled alike but for trailing slashes. */
static int same_dir(const char *a, const char *b)
{
    size_t na = strlen(a), nb = strlen(b);
    while (na > 1 && a[na - 1] == '/')
        na--;
    while (nb > 1 && b[nb - 1] == '/')
        nb--;
    return na == nb && !memcmp(a, b, na);
}

/* Every config of `run`, loaded and checked before the first one runs (the second config's
 * error used to appear only after the first had run): each a single experiment, with an
 * output directory that can be one and is its own (two configs never share one; with --out
 * they would). */
static int cmd_run(const cli *c)
{
    if (c->nargs == 0) {
        fprintf(stderr, "ppbench run: no config given (see ppbench run --help)\n");
        return EXIT_USAGE;
    }
    if (c->out && c->nargs > 1) {
        fprintf(stderr,
                "ppbench: --out %s: %d configs would share it; give one config per --out\n"
                "(or no --out: each config writes its own [output] dir)\n",
                c->out, c->nargs);
        return EXIT_USAGE;
    }
    ppb_grid *grid = ppb_grid_new();
    ppb_config *cfgs = calloc((size_t)c->nargs, sizeof *cfgs);
    if (!grid || !cfgs) {
        ppb_grid_free(grid);
        free(cfgs);
        fprintf(stderr, "ppbench: out of memory\n");
        return EXIT_RUN;
    }
    ppb_err err = {{0}};
    int code = EXIT_OK;
    for (int i = 0; i < c->nargs && code == EXIT_OK; i++) {
        if (load_config(c, c->args[i], &cfgs[i], grid, &err)) {
            code = usage_error(&err);
        } else if (grid->naxes > 0) {
            /* Named where the list was given: the file's line or the --set option. */
            ppb_config_axis_fail(&cfgs[i], grid, 0, &err,
                                 "holds a list (a sweep): use `ppbench sweep`");
            code = usage_error(&err);
        } else {
            code = check_config_out(c, &cfgs[i]);
            /* The committed study is make bench's (docs/reference.md: Outputs). */
            if (code == EXIT_OK && ppb_study_guard(cfgs[i].out_dir, &err))
                code = usage_error(&err);
            /* The directory is the run's own: refused, untouched, if ppbench did not write it. */
            if (code == EXIT_OK && ppb_experiment_claim_out(cfgs[i].out_dir, &err))
                code = usage_error(&err);
            for (int j = 0; j < i && code == EXIT_OK; j++)
                if (same_dir(cfgs[j].out_dir, cfgs[i].out_dir)) {
                    fprintf(stderr,
                            "ppbench: %s and %s both write [output] dir %s: two configs never "
                            "share one output directory\n",
                            cfgs[j].path, cfgs[i].path, cfgs[i].out_dir);
                    code = EXIT_USAGE;
                }
        }
    }
    ppb_grid_free(grid);
    char cache_buf[PPB_PATH_MAX];
    const char *cache = ref_cache_dir(c, cache_buf, sizeof cache_buf);
    for (int i = 0; i < c->nargs && code == EXIT_OK; i++) {
        const ppb_config *cfg = &cfgs[i];
        ppb_experiment ex = {0};
        ppb_run_ctx ctx = {.device_selector = c->device,
                           .quiet = c->quiet ? 2 : 0, /* 2: silent (method.h) */
                           .ref_cache = cache,
                           .extras = 1};
        int rc = ppb_experiment_compute(&ex, cfg, &ctx, &err);
        if (rc == 0)
            rc = ppb_experiment_write(&ex, &err);
        /* The summary table on stdout (reference: Outputs), before the line saying where the
         * set went, also when a method failed and the others were written. */
        if (!c->quiet && (rc == 0 || ex.nfailed > 0))
            ppb_experiment_print_summary(&ex, stdout);
        int partial = ex.partial;
        ppb_experiment_free(&ex);
        ppb_ctx_close(&ctx);
        if (rc) {
            fprintf(stderr, "ppbench: %s: %s\n", cfg->path, err.msg);
            code = ppb_interrupted() ? EXIT_INTERRUPTED : EXIT_RUN;
        } else {
            /* A signal while writing (after the last check) exits 130 as one earlier does,
             * though the set is whole (docs/reference.md: Exit codes). */
            int late = !partial && ppb_interrupted();
            if (!c->quiet)
                fprintf(stderr, "%s: wrote %s%s\n", cfg->name, cfg->out_dir,
                        partial ? " (partial: interrupted)"
                        : late  ? " (interrupted after every method finished: complete)"
                                : "");
            if (partial || late)
                code = EXIT_INTERRUPTED;
        }
    }
    free(cfgs);
    return code;
}

static int cmd_devices(const cli *c)
{
    (void)c;
    ppb_err err = {{0}};
    if (ppb_ocl_list(stdout, &err) < 0) {
        fprintf(stderr, "ppbench: %s\n", err.msg);
        return EXIT_RUN;
    }
    return EXIT_OK;
}

static int cmd_keys(const cli *c)
{
    (void)c;
    ppb_config_write_keys(stdout);
    return EXIT_OK;
}

static int cmd_materials(const cli *c)
{
    (void)c;
    ppb_materials_write(stdout);
    return EXIT_OK;
}

static int cmd_version(const cli *c)
{
    (void)c;
    printf("ppbench %s\n", PPB_VERSION);
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

/* The one config of sweep and slurm, with its grid, loaded and checked (load_config) and its
 * output directory checked: EXIT_OK with *grid to free, else the exit code (message printed,
 * nothing to free). */
static int load_grid_config(const cli *c, ppb_config *cfg, ppb_grid **grid)
{
    *grid = ppb_grid_new();
    if (!*grid) {
        fprintf(stderr, "ppbench: out of memory\n");
        return EXIT_RUN;
    }
    ppb_err err = {{0}};
    int code =
        load_config(c, c->args[0], cfg, *grid, &err) ? usage_error(&err) : check_config_out(c, cfg);
    if (code == EXIT_OK && refuse_colour(cfg, &err))
        code = usage_error(&err);
    if (code) {
        ppb_grid_free(*grid);
        *grid = NULL;
    }
    return code;
}

static int cmd_sweep(const cli *c)
{
    if (c->nargs != 1) {
        fprintf(stderr, "ppbench sweep: give exactly one config (see ppbench sweep --help)\n");
        return EXIT_USAGE;
    }
    ppb_grid *grid;
    ppb_config cfg;
    int code = load_grid_config(c, &cfg, &grid);
    if (code)
        return code;
    char cache_buf[PPB_PATH_MAX];
    ppb_sweep_opts o = {.device = c->device,
                        .quiet = c->quiet,
                        .yes = c->yes,
                        .shard_i = c->shard_i,
                        .shard_n = c->shard_n,
                        .jobs = c->jobs,
                        .ref_cache = ref_cache_dir(c, cache_buf, sizeof cache_buf)};
    ppb_err err = {{0}};
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
        fprintf(stderr, "ppbench merge: usage: ppbench merge --out DIR SHARD_DIR... (see "
                        "ppbench merge --help)\n");
        return EXIT_USAGE;
    }
    ppb_err err = {{0}};
    if (check_out_dir(c->out, "--out", &err))
        return usage_error(&err);
    int rc = ppb_sweep_merge(c->args, c->nargs, c->out, &err);
    if (rc) {
        fprintf(stderr, "ppbench merge: %s\n", err.msg);
        return rc == PPB_SWEEP_BAD_CONFIG ? EXIT_USAGE : EXIT_RUN; /* shards of another grid */
    }
    return EXIT_OK;
}

static int mc_shard_or_merge(const cli *c, int merge)
{
    if (c->nargs < (merge ? 2 : 1) || (!merge && c->nargs != 1) || !c->out) {
        fprintf(stderr, "ppbench: usage: ppbench mc-shard --shard I/N --out DIR CONFIG | "
                        "ppbench mc-merge --out DIR CONFIG SHARD_DIR...\n");
        return EXIT_USAGE;
    }
    /* One Monte Carlo run split by photons: a config holding lists is refused as by `run`. */
    ppb_config cfg;
    ppb_err err = {{0}};
    if (load_config(c, c->args[0], &cfg, NULL, &err) || refuse_colour(&cfg, &err))
        return usage_error(&err);
    int code = check_config_out(c, &cfg);
    if (code)
        return code;
    if (merge && ppb_experiment_claim_out(cfg.out_dir, &err))
        return usage_error(&err);
    int rc = merge ? ppb_mc_shard_merge(&cfg, c->args + 1, c->nargs - 1, &err)
                   : ppb_mc_shard_run(&cfg, c->device, c->quiet, c->shard_i, c->shard_n, &err);
    if (rc) {
        fprintf(stderr, "ppbench: %s: %s\n", cfg.path, err.msg);
        return ppb_interrupted()               ? EXIT_INTERRUPTED
               : rc == PPB_MC_MERGE_BAD_SHARDS ? EXIT_USAGE
                                               : EXIT_RUN;
    }
    /* A signal after the last check (while writing): the outputs are whole, but the command
     * was stopped, as an interrupt earlier says (docs/reference.md: Exit codes). */
    return ppb_interrupted() ? EXIT_INTERRUPTED : EXIT_OK;
}

static int cmd_mc_shard(const cli *c)
{
    return mc_shard_or_merge(c, 0);
}

static int cmd_mc_merge(const cli *c)
{
    return mc_shard_or_merge(c, 1);
}

/* `ppbench slurm`: the job array of a sweep or of one experiment's Monte Carlo
 * (drivers/slurm.h); the config is loaded and checked here as by sweep and mc-shard. */
static int cmd_slurm(const cli *c)
{
    if (c->nargs != 1 || !c->out || !c->shards) {
        fprintf(stderr, "ppbench slurm: usage: ppbench slurm --shards N --out DIR [options] CONFIG "
                        "(see ppbench slurm --help)\n");
        return EXIT_USAGE;
    }
    ppb_grid *grid;
    ppb_config cfg;
    int code = load_grid_config(c, &cfg, &grid);
    if (code)
        return code;
    ppb_slurm_opts o = {.shards = c->shards,
                        .partition = c->partition,
                        .time = c->time,
                        .mem = c->mem,
                        .cpus = c->cpus,
                        .account = c->account,
                        .qos = c->qos,
                        .gres = c->gres,
                        .sbatch = c->sbatch,
                        .nsbatch = c->nsbatch,
                        .device = c->device,
                        .out = c->out,
                        .submit = c->submit};
    ppb_err err = {{0}};
    int rc = ppb_slurm_run(&cfg, grid, &o, &err);
    ppb_grid_free(grid);
    if (rc) {
        fprintf(stderr, "ppbench slurm: %s\n", err.msg);
        return rc == PPB_SLURM_BAD_CONFIG ? EXIT_USAGE : EXIT_RUN;
    }
    return EXIT_OK;
}

/* Whether scene may write DIR/scene.json: DIR is new, or holds nothing but scene.json (and
 * temporaries). Without --out DIR is the config's [output] dir, where `run` puts its output
 * set: a file added there would sit in a set it does not belong to, and go with the next run. */
static int check_scene_dir(const char *dir, ppb_err *err)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0; /* new (mkdir -p makes it); another failure shows when it is written */
    char other[256] = "";
    struct dirent *de;
    while (!other[0] && (de = readdir(d)))
        if (strcmp(de->d_name, ".") && strcmp(de->d_name, "..") &&
            strcmp(de->d_name, "scene.json") && !ppb_temp_pid(de->d_name, 0))
            snprintf(other, sizeof other, "%s", de->d_name);
    closedir(d);
    if (!other[0])
        return 0;
    return ppb_fail(err,
                    "%s: holds other files (%s; a run's output set?): scene writes scene.json "
                    "only into a new directory or one holding nothing else; give --out DIR",
                    dir, other);
}

/* `ppbench scene CONFIG --out DIR`: DIR/scene.json, what an external method reads
 * (io/scene_json.h; docs/external.md). */
static int cmd_scene(const cli *c)
{
    if (c->nargs != 1) {
        fprintf(stderr, "ppbench scene: usage: ppbench scene --out DIR CONFIG\n");
        return EXIT_USAGE;
    }
    ppb_config cfg;
    ppb_err err = {{0}};
    if (load_config(c, c->args[0], &cfg, NULL, &err))
        return usage_error(&err);
    int code = check_config_out(c, &cfg);
    if (code)
        return code;
    if (check_scene_dir(cfg.out_dir, &err))
        return usage_error(&err);
    char path[PPB_PATH_MAX + 16];
    snprintf(path, sizeof path, "%s/scene.json", cfg.out_dir);
    if (ppb_mkdirs(cfg.out_dir, &err) || ppb_scene_json_write(&cfg, path, &err)) {
        fprintf(stderr, "ppbench scene: %s\n", err.msg);
        return EXIT_RUN;
    }
    return EXIT_OK;
}

/* `ppbench object CONFIG --out DIR` (drivers/object.h; docs/reference.md, Objects). The
 * config's methods are object methods (methods/object_registry.h), checked there. */
static int cmd_object(const cli *c)
{
    if (c->nargs != 1) {
        fprintf(stderr, "ppbench object: usage: ppbench object --out DIR CONFIG\n");
        return EXIT_USAGE;
    }
    ppb_config cfg;
    ppb_err err = {{0}};
    if (ppb_config_load_sets(&cfg, NULL, c->args[0], c->sets, c->nsets, &err))
        return usage_error(&err);
    if (c->out)
        snprintf(cfg.out_dir, sizeof cfg.out_dir, "%s", c->out);
    int code = check_config_out(c, &cfg);
    if (code)
        return code;
    if (ppb_study_guard(cfg.out_dir, &err))
        return usage_error(&err);
    code = check_device(c);
    if (code)
        return code;
    code = ppb_object_command(&cfg, c->device, c->quiet ? 2 : 0, PPB_VERSION, &err);
    if (code)
        fprintf(stderr, "ppbench object: %s\n", err.msg);
    return code == 2 ? EXIT_USAGE : code ? EXIT_RUN : EXIT_OK;
}

/* `ppbench score RADIANCE.csv --ref DIR [--out DIR2]` (drivers/score.h). */
static int cmd_score(const cli *c)
{
    return ppb_score_main(c->nargs ? c->args[0] : NULL, c->nargs, c->ref, c->out, c->quiet);
}

static int cmd_study_score(const cli *c)
{
    if (c->nargs > 1) {
        fprintf(stderr,
                "ppbench study-score: at most one CONFIG (see ppbench study-score --help)\n");
        return EXIT_USAGE;
    }
    ppb_study_score_opts o = {.methods = c->methods,
                              .radiance_dir = c->radiance_dir,
                              .out = c->out,
                              .config = c->nargs ? c->args[0] : NULL,
                              .sets = c->sets,
                              .nsets = c->nsets,
                              .ref_cache = c->ref_cache,
                              .no_ref_cache = c->no_ref_cache,
                              .quiet = c->quiet,
                              .device = c->device};
    return ppb_study_score_main(&o);
}

static int cmd_report(const cli *c)
{
    if (c->nargs < 2) {
        fprintf(stderr, "ppbench report: usage: ppbench report STUDY_DIR CASE... (see ppbench "
                        "report --help)\n");
        return EXIT_USAGE;
    }
    ppb_err err = {{0}};
    int rc = ppb_report_write(c->args[0], c->args + 1, c->nargs - 1, &err);
    if (rc) {
        fprintf(stderr, "ppbench report: %s\n", err.msg);
        return rc == PPB_REPORT_REFUSED || rc == PPB_REPORT_BAD_INPUT ? EXIT_USAGE : EXIT_RUN;
    }
    return EXIT_OK;
}

static const command commands[] = {
    {"run", "CONFIG...", 0,
     "run every method of each experiment config and write\nthe outputs of docs/reference.md under "
     "[output] dir",
     "ppbench run --device 0 --set mc.photons=1e6 --out /tmp/x configs/density_step.ini",
     OPT_DEVICE | OPT_OUT | OPT_SET | OPT_QUIET | OPT_REF_CACHE | OPT_NO_REF_CACHE, 1, cmd_run},
    {"sweep", "CONFIG", 0, "run a grid sweep (keys holding lists) into <dir>/sweep.csv",
     "ppbench sweep --shard 2/3 --jobs 2 configs/sweep_example.ini",
     OPT_DEVICE | OPT_OUT | OPT_SET | OPT_SHARD | OPT_JOBS | OPT_YES | OPT_QUIET | OPT_REF_CACHE |
         OPT_NO_REF_CACHE,
     1, cmd_sweep},
    {"merge", "SHARD_DIR...", OPT_OUT, "merge sweep shards (--out DIR) into one sweep.csv",
     "ppbench merge --out /tmp/sweep /tmp/part1 /tmp/part2 /tmp/part3", OPT_OUT, 1, cmd_merge},
    {"mc-shard", "CONFIG", OPT_OUT,
     "trace part --shard I/N of the config's photons into\n<--out>/mc_tallies.bin",
     "ppbench mc-shard --shard 1/2 --out /tmp/p1 configs/uniform_g0_normal.ini",
     OPT_DEVICE | OPT_OUT | OPT_SET | OPT_SHARD | OPT_QUIET, 1, cmd_mc_shard},
    {"mc-merge", "CONFIG SHARD_DIR...", OPT_OUT,
     "add the shards' tallies and write mc, mc1 outputs to\n--out, byte-identical to one run of "
     "the whole budget",
     "ppbench mc-merge --out /tmp/mc configs/uniform_g0_normal.ini /tmp/p1 /tmp/p2",
     OPT_OUT | OPT_SET, 1, cmd_mc_merge},
    {"scene", "CONFIG", OPT_OUT,
     "write --out DIR/scene.json: what an external method\nreads (docs/external.md)",
     "ppbench scene --out /tmp/scene configs/uniform_g0_normal.ini", OPT_OUT | OPT_SET, 1,
     cmd_scene},
    {"object", "CONFIG", 0,
     "render a three-dimensional object ([object]) with the\nobject methods, scored against the "
     "Monte Carlo "
     "per patch and pixel\n(docs/reference.md, Objects)",
     "ppbench object --out /tmp/sphere configs/objects/sphere.ini",
     OPT_DEVICE | OPT_OUT | OPT_SET | OPT_QUIET, 1, cmd_object},
    {"score", "RADIANCE.csv", OPT_REF,
     "score a radiance.csv against the finished experiment\n--ref DIR: its summary, rms and "
     "totals rows into --out\n(default DIR-score, -score-2, ...; DIR is never written)",
     "ppbench score --ref results/uniform_g0_normal mine/radiance.csv",
     OPT_REF | OPT_OUT | OPT_QUIET, 1, cmd_score},
    {"slurm", "CONFIG", OPT_SHARDS | OPT_OUT,
     "write a Slurm job array into --out DIR (job.sh: shard I\nof a sweep, or of one config's "
     "Monte Carlo; merge.sh:\nits merge into DIR/result) and print the sbatch lines;\n--submit "
     "submits the shards neither done nor queued",
     "ppbench slurm --shards 4 --time 30 --out /scratch/sw --submit configs/sweep_example.ini",
     OPT_DEVICE | OPT_OUT | OPT_SET | OPT_SHARDS | OPT_PARTITION | OPT_TIME | OPT_MEM | OPT_CPUS |
         OPT_ACCOUNT | OPT_QOS | OPT_GRES | OPT_SBATCH | OPT_SUBMIT,
     1, cmd_slurm},
    {"devices", NULL, 0, "list OpenCL devices (index: platform / device)",
     "PPBENCH_DEVICE=pthread ppbench devices", 0, 0, cmd_devices},
    {"keys", NULL, 0, "print every config key with its default and range", "ppbench keys", 0, 0,
     cmd_keys},
    {"materials", NULL, 0,
     "print the measured media `[medium] material` takes, with\ntheir sources (per mm)",
     "ppbench materials", 0, 0, cmd_materials},
    {"perf", NULL, 0, "benchmarks: solver, ray marcher, Monte Carlo", "ppbench perf --device 0",
     OPT_DEVICE, 0, cmd_perf},
    {"study-score", "[CONFIG]", 0,
     "score methods on every case of configs/study.list\nagainst the shipped or cached reference "
     "(no photon\ntraced) into --out DIR/<case>, and the study's report",
     "ppbench study-score --out /tmp/mine configs/mine.ini",
     OPT_DEVICE | OPT_OUT | OPT_SET | OPT_QUIET | OPT_REF_CACHE | OPT_NO_REF_CACHE | OPT_METHODS |
         OPT_RADIANCE_DIR,
     1, cmd_study_score},
    {"report", "STUDY_DIR CASE...", 0, "table2.csv/.md and README.md of a study from its cases",
     "ppbench report results uniform_g0_normal density_step", 0, 1, cmd_report},
    {"version", NULL, 0, "print the version (as --version)", "ppbench version", 0, 0, cmd_version},
};
enum { NCOMMANDS = sizeof commands / sizeof commands[0] };

/* Text with '\n' continuation lines indented to the help column. */
static void print_indented(FILE *out, const char *head, const char *text)
{
    fprintf(out, strlen(head) < 19 ? "  %-19s " : "  %s  ", head);
    for (const char *s = text; *s; s++) {
        fputc(*s, out);
        if (*s == '\n')
            fprintf(out, "%22s", "");
    }
    fputc('\n', out);
}

static void print_option(FILE *out, const struct option_doc *o)
{
    char head[64];
    snprintf(head, sizeof head, "%s%s%s", o->name, o->arg ? " " : "", o->arg ? o->arg : "");
    print_indented(out, head, o->help);
}

static void usage(FILE *out)
{
    fprintf(out, "usage: ppbench COMMAND [options]\n"
                 "       ppbench COMMAND --help   (that command's options and an example)\n"
                 "\n"
                 "commands:\n");
    for (int i = 0; i < NCOMMANDS; i++) {
        char head[64];
        snprintf(head, sizeof head, "%s%s%s", commands[i].name, commands[i].operands ? " " : "",
                 commands[i].operands ? commands[i].operands : "");
        print_indented(out, head, commands[i].summary);
    }
    fprintf(out, "\noptions (each applies to the commands its help names):\n");
    for (int i = 0; i < NOPTIONS; i++)
        print_option(out, &option_docs[i]);
    fprintf(out, "  -h, --help          this text; `ppbench COMMAND --help`: that command's\n"
                 "                      options and an example\n"
                 "  --version           the version (as `ppbench version`)\n"
                 "\n"
                 "methods:\n");
    for (int i = 0; i < ppb_method_count(); i++)
        fprintf(out, "  %-8s %s\n", ppb_method_at(i)->id, ppb_method_at(i)->summary);
    fprintf(out, "\nobject methods (`ppbench object`):\n");
    for (int i = 0; i < ppb_object_method_count(); i++)
        fprintf(out, "  %-8s %s\n", ppb_object_method_at(i)->id, ppb_object_method_at(i)->summary);
    fprintf(out,
            "\n"
            "examples:\n"
            "  ppbench run --out /tmp/g0 configs/uniform_g0_normal.ini\n"
            "  ppbench run --device 0 --set mc.photons=1e6 --out /tmp/x configs/density_step.ini\n"
            "  ppbench sweep --shard 2/3 configs/sweep_example.ini\n"
            "  PPBENCH_DEVICE=pthread ppbench devices\n"
            "\n"
            "exit codes: 0 success; 1 a run failed (OpenCL, I/O, numerics); 2 bad command\n"
            "line or config (found before any work starts); 130 interrupted (what was done\n"
            "is written, marked partial).\n"
            "\n"
            "reference: docs/reference.md (every output file and column, config key and\n"
            "convention).\n");
}

/* `ppbench CMD --help`: the command's synopsis, what it does, its options, one example. */
static void command_usage(FILE *out, const command *cmd)
{
    fprintf(out, "usage: ppbench %s", cmd->name);
    for (int i = 0; i < NOPTIONS; i++)
        if (cmd->required & option_docs[i].bit)
            fprintf(out, " %s %s", option_docs[i].name, option_docs[i].arg);
    fprintf(out, "%s%s%s\n\n%s.\n", cmd->opts & ~cmd->required ? " [options]" : "",
            cmd->operands ? " " : "", cmd->operands ? cmd->operands : "", cmd->summary);
    if (cmd->opts) {
        fprintf(out, "\noptions:\n");
        for (int i = 0; i < NOPTIONS; i++)
            if (cmd->opts & option_docs[i].bit)
                print_option(out, &option_docs[i]);
    }
    fprintf(out, "\nexample:\n  %s\n", cmd->example);
}

static const command *find_command(const char *name)
{
    for (int i = 0; i < NCOMMANDS; i++)
        if (!strcmp(commands[i].name, name))
            return &commands[i];
    return NULL;
}

int main(int argc, char **argv)
{
    pp_blas_threads(argv); /* may execute ppbench again: first (base/memory.h) */
    if (argc < 2 || !strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") ||
        !strcmp(argv[1], "help")) {
        /* `ppbench help CMD` is `ppbench CMD --help`. */
        const command *cmd = argc > 2 ? find_command(argv[2]) : NULL;
        if (argc > 2 && !cmd) {
            fprintf(stderr, "ppbench: %s: unknown command (see ppbench --help)\n", argv[2]);
            return EXIT_USAGE;
        }
        if (argc > 3) {
            fprintf(stderr, "ppbench %s: unexpected argument '%s'\n", argv[1], argv[3]);
            return EXIT_USAGE;
        }
        if (cmd)
            command_usage(stdout, cmd);
        else
            usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? EXIT_USAGE : EXIT_OK;
    }
    const command *cmd = find_command(strcmp(argv[1], "--version") ? argv[1] : "version");
    if (!cmd) {
        fprintf(stderr, "ppbench: %s: unknown command (see --help)\n", argv[1]);
        return EXIT_USAGE;
    }
    /* What a ppbench killed with SIGKILL left running (its commands' descendants) goes first
     * (base/child.h). */
    ppb_child_clean_dead();
    cli c;
    int rc = parse_cli(argc, argv, cmd, &c);
    if (rc == PARSE_HELP) {
        command_usage(stdout, cmd);
        free_cli(&c);
        return EXIT_OK;
    }
    if (rc == 0 && (cmd->opts & OPT_DEVICE))
        rc = check_device(&c);
    if (rc == 0 && needs_blas(cmd)) {
        /* OpenBLAS retries its buffer's allocation for ever: it is had here, before any work,
         * or its lack is an error (base/memory.h). */
        ppb_err err = {{0}};
        if (pp_blas_reserve(&err)) {
            fprintf(stderr, "ppbench: %s\n", err.msg);
            rc = EXIT_RUN;
        }
    }
    if (rc == 0) {
        ppb_progress_install_signals();
        rc = cmd->run(&c);
    }
    free_cli(&c);
    return rc;
}
