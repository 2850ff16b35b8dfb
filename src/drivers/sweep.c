#include "drivers/sweep.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/csv_read.h"
#include "base/hash.h"
#include "drivers/experiment.h"
#include "physics/march_tables.h"
#include "model/metrics.h"
#include "base/progress.h"
#include "drivers/sweep_plot.h"

/* A hash (base/hash.h) of the resolved settings that shape results (output.dir and the name
 * excluded), so a renamed or moved sweep still finds its finished points. */
static uint64_t point_hash(const ppb_config *pt)
{
    ppb_config c = *pt;
    c.out_dir[0] = '\0';
    c.name[0] = '\0';
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    ppb_config_write_resolved(&c, f);
    fclose(f);
    uint64_t h = ppb_hash64(text, len);
    free(text);
    return h;
}

static void point_file(const char *dir, uint64_t h, const char *ext, char *buf, size_t n)
{
    snprintf(buf, n, "%s/points/%016llx.%s", dir, (unsigned long long)h, ext);
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static void write_header(const ppb_grid *grid, FILE *f)
{
    fprintf(f, "point");
    for (int a = 0; a < grid->naxes; a++) {
        char name[64];
        ppb_config_key_name(grid->axes[a].key, name, sizeof name);
        fprintf(f, ",%s", name);
    }
    fprintf(f, ",method");
    for (int c = 0; c < PPB_NCELLS; c++)
        fprintf(f, ",rms_%s", ppb_cell_name(c));
    fprintf(f, ",noise_R_x0,noise_T_x0,R,T,sides,absorbed,ballistic\n");
}

/* One row per method of a point: its parameters, the RMS per summary cell against the Monte
 * Carlo (empty without one), the noise floor at x = 0 and the totals. */
static void write_rows(const ppb_grid *grid, const ppb_config *pt, long long i,
                       const ppb_experiment *ex, FILE *f)
{
    const ppb_result *ref = ppb_experiment_reference(ex);
    const ppb_layout *lo = &ex->res[0].layout;
    int cap = lo->nseg[PPB_S1] > lo->nseg[PPB_S3] ? lo->nseg[PPB_S1] : lo->nseg[PPB_S3];
    ppb_point *pts = malloc(sizeof *pts * (size_t)(cap > 2 ? cap : 2));
    for (int m = 0; m < ex->n; m++) {
        fprintf(f, "%lld", i);
        for (int a = 0; a < grid->naxes; a++)
            fprintf(f, ",%.10g", ppb_config_key_value(pt, grid->axes[a].key));
        fprintf(f, ",%s", ex->res[m].method);
        ppb_rms x0[2] = {{NAN, NAN, NAN}, {NAN, NAN, NAN}};
        for (int c = 0; c < PPB_NCELLS; c++) {
            int np = ref ? ppb_cell_points(lo, c, pts, cap > 2 ? cap : 2) : 0;
            ppb_rms e = {NAN, NAN, NAN};
            if (np > 0 && &ex->res[m] != ref)
                e = ppb_rms_points(&ex->res[m], ref, pts, np);
            if (c < 2)
                x0[c] = e;
            fprintf(f, ",%.6g", e.rms_rel);
        }
        ppb_totals t = ex->res[m].totals;
        ppb_totals_complete(&t);
        fprintf(f, ",%.6g,%.6g,%.10g,%.10g,%.10g,%.10g,%.10g\n", x0[0].noise_rel, x0[1].noise_rel,
                t.R, t.T, t.sides, t.absorbed, t.ballistic);
    }
    free(pts);
}

static int run_point(const ppb_config *cfg, const ppb_grid *grid, const ppb_config *pt, long long i,
                     ppb_run_ctx *ctx, ppb_err *err)
{
    ppb_experiment ex = {0};
    double t0 = ppb_now();
    int rc = ppb_experiment_compute(&ex, pt, ctx, err);
    if (rc == 0 && !ex.partial) {
        char path[1300];
        uint64_t h = point_hash(pt);
        ppb_afile af;
        point_file(cfg->out_dir, h, "time", path, sizeof path);
        if ((rc = ppb_afile_open(&af, path, err)) == 0) {
            fprintf(af.f, "%lld,%.4f\n", i, ppb_now() - t0);
            rc = ppb_afile_commit(&af, err);
        }
        point_file(cfg->out_dir, h, "csv", path, sizeof path);
        if (rc == 0 && (rc = ppb_afile_open(&af, path, err)) == 0) {
            write_rows(grid, pt, i, &ex, af.f);
            rc = ppb_afile_commit(&af, err);
        }
    }
    ppb_experiment_free(&ex);
    return rc;
}

/* Every point is resolved and checked before any work starts. */
static int check_grid(const ppb_config *cfg, const ppb_grid *grid, const ppb_sweep_opts *o,
                      ppb_err *err)
{
    long long n = ppb_grid_npoints(grid);
    if (grid->naxes == 0)
        return ppb_fail(err, "%s: no key holds a list: nothing to sweep (use ppbench run)",
                        cfg->path);
    if (n > PPB_SWEEP_MAX_POINTS && !o->yes)
        return ppb_fail(err, "%s: the grid has %lld points, over the limit of %d: add --yes",
                        cfg->path, n, PPB_SWEEP_MAX_POINTS);
    ppb_config pt;
    for (long long i = 0; i < n; i++)
        if (ppb_config_point(cfg, grid, i, &pt, err))
            return -1;
    return 0;
}

/* grid.txt: the header of sweep.csv, then each point's hash in grid order; merge reads it. */
static int write_grid(const ppb_config *cfg, const ppb_grid *grid, ppb_err *err)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/grid.txt", cfg->out_dir);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    write_header(grid, af.f);
    ppb_config pt;
    for (long long i = 0; i < ppb_grid_npoints(grid); i++) {
        ppb_config_point(cfg, grid, i, &pt, NULL);
        fprintf(af.f, "%016llx\n", (unsigned long long)point_hash(&pt));
    }
    return ppb_afile_commit(&af, err);
}

static int copy_into(FILE *dst, const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    char buf[8192];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        fwrite(buf, 1, n, dst);
    fclose(f);
    return 0;
}

/* Finds a point's file of type ext in any of dirs. */
static int find_point(const char *const *dirs, int ndirs, const char *hash, const char *ext,
                      char *path, size_t n)
{
    for (int d = 0; d < ndirs; d++) {
        snprintf(path, n, "%s/points/%.16s.%s", dirs[d], hash, ext);
        if (exists(path))
            return 0;
    }
    return -1;
}

/* Writes out/sweep.csv and out/timings.csv from the points found in dirs, in grid order.
 * grid.txt is read as CSV (base/csv_read.h): its header is sweep.csv's (names never need
 * quotes: write_header), its records one field each, a point's hash.
 * Returns the number of points still missing (then nothing is written), or -1. */
static long long assemble(const char *const *dirs, int ndirs, const char *out, ppb_err *err)
{
    char gpath[1200], path[1300];
    snprintf(gpath, sizeof gpath, "%s/grid.txt", dirs[0]);
    ppb_csv g;
    ppb_err gerr;
    if (ppb_csv_open(&g, gpath, &gerr))
        return ppb_fail(err, "%s (not a sweep directory?)", gerr.msg);
    ppb_afile csv, tim;
    snprintf(path, sizeof path, "%s/sweep.csv", out);
    if (ppb_afile_open(&csv, path, err)) {
        ppb_csv_close(&g);
        return -1;
    }
    snprintf(path, sizeof path, "%s/timings.csv", out);
    if (ppb_afile_open(&tim, path, err)) {
        ppb_afile_abort(&csv);
        ppb_csv_close(&g);
        return -1;
    }
    for (int c = 0; c < g.ncol; c++)
        fprintf(csv.f, "%s%s", c ? "," : "", g.col[c]);
    fputc('\n', csv.f);
    fprintf(tim.f, "point,seconds\n");
    long long missing = 0;
    int rc;
    while ((rc = ppb_csv_next(&g, err)) == 1) {
        const char *hash = ppb_csv_get(&g, 0);
        if (find_point(dirs, ndirs, hash, "csv", path, sizeof path) == 0)
            copy_into(csv.f, path);
        else
            missing++;
        if (find_point(dirs, ndirs, hash, "time", path, sizeof path) == 0)
            copy_into(tim.f, path);
    }
    ppb_csv_close(&g);
    if (missing || rc < 0) {
        ppb_afile_abort(&csv);
        ppb_afile_abort(&tim);
        return rc < 0 ? -1 : missing;
    }
    if (ppb_afile_commit(&csv, err) || ppb_afile_commit(&tim, err))
        return -1;
    return 0;
}

/* The points with index % parts == part, one device context for all of them. */
static int run_shard(const ppb_config *cfg, const ppb_grid *grid, const ppb_sweep_opts *o, int part,
                     int parts, int quiet, ppb_err *err)
{
    long long n = ppb_grid_npoints(grid);
    ppb_config pt;
    ppb_progress pr;
    ppb_progress_begin(&pr, cfg->name, "points", (double)n, quiet);
    /* Points that share a medium share the marcher's tables: built once per process. */
    ppb_run_ctx ctx = {
        .device_selector = o->device, .quiet = 1, .march_cache = ppb_march_cache_new()};
    long long done = 0;
    int rc = 0;
    for (long long i = part; i < n && rc == 0 && !ppb_interrupted(); i += parts) {
        char path[1300];
        if ((rc = ppb_config_point(cfg, grid, i, &pt, err)) != 0)
            break;
        point_file(cfg->out_dir, point_hash(&pt), "csv", path, sizeof path);
        if (!exists(path))
            rc = run_point(cfg, grid, &pt, i, &ctx, err);
        ppb_progress_update(&pr, (double)++done * parts);
    }
    ppb_ctx_close(&ctx);
    ppb_march_cache_free(ctx.march_cache);
    ppb_progress_end(&pr, (double)done);
    return rc;
}

/* --jobs J: J processes, each its own device context, taking every J-th point of this shard;
 * the first one shows progress. A failing child's message is on its stderr. */
static int run_jobs(const ppb_config *cfg, const ppb_grid *grid, const ppb_sweep_opts *o,
                    ppb_err *err)
{
    int jobs = o->jobs > 1 ? o->jobs : 1, parts = o->shard_n * jobs;
    if (jobs == 1)
        return run_shard(cfg, grid, o, o->shard_i - 1, o->shard_n, o->quiet, err);
    fflush(NULL);
    pid_t pids[64];
    for (int j = 0; j < jobs; j++) {
        pids[j] = fork();
        if (pids[j] < 0)
            return ppb_fail(err, "--jobs: fork failed");
        if (pids[j] == 0) {
            ppb_err e = {{0}};
            int rc =
                run_shard(cfg, grid, o, o->shard_i - 1 + o->shard_n * j, parts, o->quiet || j, &e);
            if (rc)
                fprintf(stderr, "ppbench sweep (job %d): %s\n", j + 1, e.msg);
            _exit(rc ? 1 : 0);
        }
    }
    int failed = 0;
    for (int j = 0; j < jobs; j++) {
        int st;
        if (waitpid(pids[j], &st, 0) < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0)
            failed++;
    }
    return failed ? ppb_fail(err, "%d of %d jobs failed", failed, jobs) : 0;
}

int ppb_sweep_run(const ppb_config *cfg, const ppb_grid *grid, const ppb_sweep_opts *o,
                  ppb_err *err)
{
    if (check_grid(cfg, grid, o, err))
        return PPB_SWEEP_BAD_CONFIG;
    char dir[1200];
    snprintf(dir, sizeof dir, "%s/points", cfg->out_dir);
    if (ppb_mkdirs(dir, err) || write_grid(cfg, grid, err))
        return -1;
    if (run_jobs(cfg, grid, o, err))
        return -1;
    if (ppb_interrupted())
        return 0;
    const char *dirs[1] = {cfg->out_dir};
    long long missing = assemble(dirs, 1, cfg->out_dir, err);
    if (missing < 0)
        return -1;
    if (missing == 0 && ppb_sweep_heatmaps(cfg, grid, cfg->out_dir, err))
        return -1;
    if (!o->quiet && missing)
        fprintf(stderr, "%s: %lld points left to other shards; merge when done\n", cfg->name,
                missing);
    else if (!o->quiet)
        fprintf(stderr, "%s: wrote %s/sweep.csv\n", cfg->name, cfg->out_dir);
    return 0;
}

int ppb_sweep_merge(const char *const *dirs, int n, const char *out_dir, ppb_err *err)
{
    if (ppb_mkdirs(out_dir, err))
        return -1;
    long long missing = assemble(dirs, n, out_dir, err);
    if (missing < 0)
        return -1;
    if (missing > 0)
        return ppb_fail(err, "%lld grid points are in none of the shard directories", missing);
    return 0;
}
