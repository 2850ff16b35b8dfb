#include "drivers/sweep.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "base/file_read.h"
#include "base/atomic_file.h"
#include "base/csv_read.h"
#include "base/hash.h"
#include "drivers/experiment.h"
#include "model/metrics.h"
#include "base/progress.h"
#include "drivers/sweep_failures.h"
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

/* A point's files hold only what the point's settings determine: points/<hash>.rows2.csv its
 * rows from the method on (method, RMS, noise, totals), points/<hash>.seconds its wall time.
 * The point index and the swept values are the grid's, not the point's: they are prefixed when
 * sweep.csv is assembled, from the grid of that run (grid.txt), so a grid grown by a value or an
 * axis reuses its finished points under their new index and columns. (Files of the earlier
 * forms are not read: points/<hash>.csv carried both; points/<hash>.rows.csv lacked the noise
 * and excess of every cell. Such points are computed again.) */
#define ROWS_EXT    "rows2.csv"
#define SECONDS_EXT "seconds"

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
    /* rms_rel, noise_rel and rms_excess of every summary cell (model/metrics.h), each kind
     * in the cells' order; the noise of R_x0 and T_x0 first, where it always was */
    static const char *const kinds[3] = {"rms", "noise", "excess"};
    for (int k = 0; k < 3; k++)
        for (int c = 0; c < PPB_NCELLS; c++)
            fprintf(f, ",%s_%s", kinds[k], ppb_cell_name(c));
    fprintf(f, ",R,T,sides,absorbed,ballistic,specular\n");
}

/* One row per method of a point, from the method on: the RMS per summary cell against the
 * Monte Carlo (empty without one), the noise floor at x = 0 and the totals. */
static int write_rows(const ppb_experiment *ex, FILE *f, ppb_err *err)
{
    const ppb_result *ref = ppb_experiment_reference(ex);
    const ppb_layout *lo = &ex->res[0].layout;
    int cap = lo->nseg[PPB_S1] > lo->nseg[PPB_S3] ? lo->nseg[PPB_S1] : lo->nseg[PPB_S3];
    if (cap < 2)
        cap = 2;
    ppb_point *pts = malloc(sizeof *pts * (size_t)cap);
    if (!pts)
        return ppb_fail(err, "sweep: out of memory for %d cell points", cap);
    for (int m = 0; m < ex->n; m++) {
        fprintf(f, "%s", ex->res[m].method);
        ppb_rms e[PPB_NCELLS];
        for (int c = 0; c < PPB_NCELLS; c++) {
            int np = ref ? ppb_cell_points(lo, c, pts, cap) : 0;
            e[c] = (ppb_rms){NAN, NAN, NAN};
            if (np > 0 && &ex->res[m] != ref)
                e[c] = ppb_rms_points(&ex->res[m], ref, pts, np);
        }
        for (int c = 0; c < PPB_NCELLS; c++)
            fprintf(f, ",%.6g", e[c].rms_rel);
        for (int c = 0; c < PPB_NCELLS; c++)
            fprintf(f, ",%.6g", e[c].noise_rel);
        for (int c = 0; c < PPB_NCELLS; c++)
            fprintf(f, ",%.6g", e[c].rms_excess);
        ppb_totals t = ex->res[m].totals;
        ppb_totals_complete(&t);
        fprintf(f, ",%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", t.R, t.T, t.sides, t.absorbed,
                t.ballistic, t.specular);
    }
    free(pts);
    return 0;
}

/* Computes one point and writes its files. An interrupted point writes nothing and is no
 * failure: the sweep stops and a re-run computes it. */
static int run_point(const ppb_config *cfg, const ppb_config *pt, uint64_t h, ppb_run_ctx *ctx,
                     ppb_err *err)
{
    ppb_experiment ex = {0};
    double t0 = ppb_now();
    int rc = ppb_experiment_compute(&ex, pt, ctx, err);
    if (ppb_interrupted() || ex.partial) {
        ppb_experiment_free(&ex);
        return 0;
    }
    rc = ppb_sweep_failures_point(cfg->out_dir, h, &ex, rc, err); /* recorded */
    if (rc == 0) {
        char path[1300];
        ppb_afile af;
        point_file(cfg->out_dir, h, SECONDS_EXT, path, sizeof path);
        if ((rc = ppb_afile_open(&af, path, err)) == 0) {
            fprintf(af.f, "%.4f\n", ppb_now() - t0);
            rc = ppb_afile_commit(&af, err);
        }
        point_file(cfg->out_dir, h, ROWS_EXT, path, sizeof path);
        if (rc == 0 && (rc = ppb_afile_open(&af, path, err)) == 0) {
            if ((rc = write_rows(&ex, af.f, err)) != 0)
                ppb_afile_abort(&af);
            else
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

/* grid.txt: the header of sweep.csv, then one record per point in grid order: its hash and
 * its swept values as sweep.csv prints them. merge reads it, and refuses shards whose grid.txt
 * differ (another grid, another order, other settings). hashes[n] receives the hashes. */
static int write_grid(const ppb_config *cfg, const ppb_grid *grid, uint64_t *hashes, ppb_err *err)
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
        hashes[i] = point_hash(&pt);
        fprintf(af.f, "%016llx", (unsigned long long)hashes[i]);
        for (int a = 0; a < grid->naxes; a++)
            fprintf(af.f, ",%.10g", ppb_config_key_value(&pt, grid->axes[a].key));
        fputc('\n', af.f);
    }
    return ppb_afile_commit(&af, err);
}

/* Copies each line of path to dst behind prefix. */
static int copy_lines(FILE *dst, const char *prefix, const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    char *line = NULL;
    size_t cap = 0;
    while (getline(&line, &cap, f) > 0)
        fprintf(dst, "%s,%s", prefix, line);
    free(line);
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

/* Shards of one sweep have the same grid.txt: the same swept keys in the same order (its
 * header), the same values in the same order, the same settings at every point (the hashes).
 * Refuses any other, saying which part differs. */
static int same_grids(const char *const *dirs, int ndirs, ppb_err *err)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/grid.txt", dirs[0]);
    size_t n0 = 0;
    char *g0 = ppb_read_file(path, &n0);
    if (!g0)
        return ppb_fail(err, "%s: cannot read: %s (not a sweep directory?)", path, strerror(errno));
    int rc = 0;
    for (int d = 1; d < ndirs && rc == 0; d++) {
        size_t n = 0;
        snprintf(path, sizeof path, "%s/grid.txt", dirs[d]);
        char *g = ppb_read_file(path, &n);
        if (!g) {
            rc = ppb_fail(err, "%s: cannot read: %s (not a sweep directory?)", path,
                          strerror(errno));
            break;
        }
        if (n != n0 || memcmp(g, g0, n) != 0) {
            const char *e0 = memchr(g0, '\n', n0), *e = memchr(g, '\n', n);
            size_t h0 = e0 ? (size_t)(e0 - g0) : n0, h = e ? (size_t)(e - g) : n;
            const char *what = "the same points hold other settings (another config)";
            if (h != h0 || memcmp(g, g0, h) != 0)
                what = "other swept keys or another key order";
            else {
                /* Compare the records without their hashes: values and their order. */
                const char *p = g0 + h0, *q = g + h;
                const char *p1 = g0 + n0, *q1 = g + n;
                while (p < p1 && q < q1) {
                    const char *pe = memchr(p + 1, '\n', (size_t)(p1 - p - 1));
                    const char *qe = memchr(q + 1, '\n', (size_t)(q1 - q - 1));
                    pe = pe ? pe : p1, qe = qe ? qe : q1;
                    const char *pv = memchr(p, ',', (size_t)(pe - p)),
                               *qv = memchr(q, ',', (size_t)(qe - q));
                    pv = pv ? pv : pe, qv = qv ? qv : qe;
                    if (pe - pv != qe - qv || memcmp(pv, qv, (size_t)(pe - pv)) != 0) {
                        what = "other values or another value order";
                        break;
                    }
                    p = pe, q = qe;
                }
                if ((p < p1) != (q < q1))
                    what = "another number of points";
            }
            rc =
                ppb_fail(err, "%s: its grid differs from %s's (%s): only shards of one sweep merge",
                         dirs[d], dirs[0], what);
        }
        free(g);
    }
    free(g0);
    return rc;
}

/* Writes out/sweep.csv and out/timings.csv from the points found in dirs, in grid order.
 * grid.txt is read as CSV (base/csv_read.h): its header is sweep.csv's (names never need
 * quotes: write_header), its records a point's hash and swept values; each row of sweep.csv is
 * the point's index, those values, and a row of its rows file.
 * Returns the number of points still missing (then nothing is written), or -1. */
static long long assemble(const char *const *dirs, int ndirs, const char *out, ppb_err *err)
{
    char gpath[1200], path[1300];
    snprintf(gpath, sizeof gpath, "%s/grid.txt", dirs[0]);
    ppb_csv g;
    ppb_err gerr;
    if (ppb_csv_open(&g, gpath, &gerr))
        return ppb_fail(err, "%s (not a sweep directory?)", gerr.msg);
    int nvalues = ppb_csv_col(&g, "method") - 1;
    if (nvalues < 1) {
        ppb_csv_close(&g);
        return ppb_fail(err, "%s: not a grid file (no method column)", gpath);
    }
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
    long long missing = 0, i = 0;
    int rc;
    char *prefix = NULL;
    size_t prefix_cap = 0;
    while ((rc = ppb_csv_next(&g, err)) == 1) {
        if (g.nfield != nvalues + 1) {
            rc = ppb_fail(err,
                          "%s:%ld: %d fields, the grid has %d swept keys (a grid.txt of an "
                          "earlier ppbench: run the sweep again)",
                          gpath, g.line, g.nfield, nvalues);
            break;
        }
        const char *hash = ppb_csv_get(&g, 0);
        size_t need = 32;
        for (int a = 1; a <= nvalues; a++)
            need += strlen(ppb_csv_get(&g, a)) + 1;
        if (need > prefix_cap) {
            char *p = realloc(prefix, need);
            if (!p) {
                rc = ppb_fail(err, "sweep: out of memory assembling %s", out);
                break;
            }
            prefix = p, prefix_cap = need;
        }
        size_t len = (size_t)snprintf(prefix, prefix_cap, "%lld", i);
        for (int a = 1; a <= nvalues; a++)
            len += (size_t)snprintf(prefix + len, prefix_cap - len, ",%s", ppb_csv_get(&g, a));
        if (find_point(dirs, ndirs, hash, ROWS_EXT, path, sizeof path) == 0)
            copy_lines(csv.f, prefix, path);
        else
            missing++;
        snprintf(prefix, prefix_cap, "%lld", i);
        if (find_point(dirs, ndirs, hash, SECONDS_EXT, path, sizeof path) == 0)
            copy_lines(tim.f, prefix, path);
        i++;
    }
    free(prefix);
    ppb_csv_close(&g);
    if (missing || rc < 0) {
        ppb_afile_abort(&csv);
        ppb_afile_abort(&tim);
        return rc < 0 ? -1 : missing;
    }
    if (ppb_afile_commit(&csv, err) || ppb_afile_commit(&tim, err))
        return -1;
    return ppb_sweep_failures_assemble(dirs, ndirs, out, err) ? -1 : 0;
}

/* The points of this shard whose rows are written (computed now or before). */
static long long shard_done(const ppb_config *cfg, const ppb_grid *grid, const uint64_t *hashes,
                            const ppb_sweep_opts *o, long long *mine)
{
    long long done = 0, n = ppb_grid_npoints(grid);
    *mine = 0;
    for (long long i = o->shard_i - 1; i < n; i += o->shard_n) {
        char path[1300];
        point_file(cfg->out_dir, hashes[i], ROWS_EXT, path, sizeof path);
        ++*mine;
        done += exists(path);
    }
    return done;
}

/* The points with index % parts == part, one device context for all of them. A point counts as
 * done once its rows are written: an interrupted or failed one is not (the point in
 * progress at a Ctrl-C was counted). The completion line is printed when end_line is set (the
 * serial sweep; with --jobs the parent prints it for all workers). */
static int run_shard(const ppb_config *cfg, const ppb_grid *grid, const uint64_t *hashes,
                     const ppb_sweep_opts *o, int part, int parts, int quiet, int end_line,
                     ppb_err *err)
{
    long long n = ppb_grid_npoints(grid);
    ppb_config pt;
    ppb_progress pr;
    ppb_progress_begin(&pr, cfg->name, "points", (double)n, quiet);
    /* One context for every point: what methods keep in it (the marcher's tables, shared by
     * the points of one medium) is built once per process. */
    ppb_run_ctx ctx = {.device_selector = o->device,
                       .quiet = o->quiet ? 2 : 1, /* a point's progress: never */
                       .ref_cache = o->ref_cache};
    long long done = 0;
    int rc = 0;
    for (long long i = part; i < n && rc == 0 && !ppb_interrupted(); i += parts) {
        char path[1300];
        if ((rc = ppb_config_point(cfg, grid, i, &pt, err)) != 0)
            break;
        point_file(cfg->out_dir, hashes[i], ROWS_EXT, path, sizeof path);
        if (!exists(path))
            rc = run_point(cfg, &pt, hashes[i], &ctx, err);
        if (exists(path))
            ppb_progress_update(&pr, (double)++done * parts);
    }
    ppb_ctx_close(&ctx);
    if (end_line)
        ppb_progress_end(&pr, (double)done);
    return rc;
}

static void sleep_ms(long ms)
{
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* --jobs J: J processes, each its own device context, taking every J-th point of this shard;
 * the first one shows progress, and this process, once all have ended, the completion line
 * with the points of the whole shard done (it was the first worker's own count,
 * "1 points" of a 2-point sweep under --jobs 2). A failing child's message is on its stderr.
 *
 * The workers die with the sweep: each asks the kernel for SIGTERM when its parent dies
 * (PR_SET_PDEATHSIG; the getppid() check covers a parent gone before the request), so a
 * kill -9 of the sweep leaves no orphan computing on. Each worker has its own process group,
 * so a Ctrl-C reaches the parent alone, which passes one SIGINT to every worker: each stops
 * at its next check as a serial sweep does (a second Ctrl-C ends the parent at once, and the
 * workers with it). An interrupted worker exits 130, which is no failure. */
static int run_jobs(const ppb_config *cfg, const ppb_grid *grid, const uint64_t *hashes,
                    const ppb_sweep_opts *o, ppb_err *err)
{
    enum { MAX_JOBS = 64 };
    int jobs = o->jobs > 1 ? o->jobs : 1, parts = o->shard_n * jobs;
    if (jobs == 1)
        return run_shard(cfg, grid, hashes, o, o->shard_i - 1, o->shard_n, o->quiet, 1, err);
    if (jobs > MAX_JOBS)
        return ppb_fail(err, "--jobs %d: at most %d", jobs, MAX_JOBS);
    ppb_progress pr;
    ppb_progress_begin(&pr, cfg->name, "points", (double)ppb_grid_npoints(grid), o->quiet);
    fflush(NULL);
    pid_t pids[MAX_JOBS], parent = getpid();
    int started = 0;
    for (; started < jobs; started++) {
        pid_t p = fork();
        if (p < 0)
            break;
        if (p == 0) {
            setpgid(0, 0);
            if (prctl(PR_SET_PDEATHSIG, SIGTERM) != 0 || getppid() != parent)
                _exit(1);
            ppb_err e = {{0}};
            int rc = run_shard(cfg, grid, hashes, o, o->shard_i - 1 + o->shard_n * started, parts,
                               o->quiet || started, 0, &e);
            if (rc)
                fprintf(stderr, "ppbench sweep (job %d): %s\n", started + 1, e.msg);
            fflush(NULL);
            _exit(rc ? 1 : ppb_interrupted() ? 130 : 0);
        }
        pids[started] = p;
    }
    int fork_failed = started < jobs, fork_errno = errno;
    /* Polled, not a blocking waitpid: an interrupt is seen and passed on at once, whenever it
     * comes. */
    int live = started, failed = 0, forwarded = 0;
    if (fork_failed) {
        for (int j = 0; j < started; j++)
            kill(pids[j], SIGINT);
        forwarded = 1;
    }
    while (live > 0) {
        if (ppb_interrupted() && !forwarded) {
            for (int j = 0; j < started; j++)
                if (pids[j] > 0)
                    kill(pids[j], SIGINT);
            forwarded = 1;
        }
        int st;
        pid_t p = waitpid(-1, &st, WNOHANG);
        if (p == 0) {
            sleep_ms(20);
            continue;
        }
        if (p < 0) {
            if (errno == EINTR)
                continue;
            break; /* ECHILD: none left */
        }
        for (int j = 0; j < started; j++)
            if (pids[j] == p) {
                pids[j] = 0;
                live--;
                int ok = WIFEXITED(st) && WEXITSTATUS(st) == 0;
                int stopped =
                    ppb_interrupted() &&
                    ((WIFEXITED(st) && WEXITSTATUS(st) == 130) ||
                     (WIFSIGNALED(st) && (WTERMSIG(st) == SIGINT || WTERMSIG(st) == SIGTERM)));
                failed += !ok && !stopped;
            }
    }
    long long mine;
    ppb_progress_end(&pr, (double)shard_done(cfg, grid, hashes, o, &mine));
    if (fork_failed)
        return ppb_fail(err, "--jobs %d: fork failed after %d: %s", jobs, started,
                        strerror(fork_errno));
    return failed ? ppb_fail(err, "%d of %d jobs failed", failed, jobs) : 0;
}

int ppb_sweep_run(const ppb_config *cfg, const ppb_grid *grid, const ppb_sweep_opts *o,
                  ppb_err *err)
{
    if (check_grid(cfg, grid, o, err))
        return PPB_SWEEP_BAD_CONFIG;
    long long n = ppb_grid_npoints(grid);
    uint64_t *hashes = malloc(sizeof *hashes * (size_t)n);
    if (!hashes)
        return ppb_fail(err, "sweep: out of memory for the hashes of %lld points", n);
    char dir[1200];
    snprintf(dir, sizeof dir, "%s/points", cfg->out_dir);
    int rc = ppb_mkdirs(dir, err) || write_grid(cfg, grid, hashes, err) ? -1 : 0;
    int hashed = rc == 0; /* hashes[] is filled */
    if (rc == 0)
        rc = run_jobs(cfg, grid, hashes, o, err);
    if (ppb_interrupted() && hashed) {
        /* Interrupted: no failure (the caller exits 130), the finished points are kept. */
        long long mine, done = shard_done(cfg, grid, hashes, o, &mine);
        fprintf(stderr,
                "%s: interrupted: %lld of %lld points done, no sweep.csv written (run the same "
                "command again to compute the other %lld)\n",
                cfg->name, done, mine, mine - done);
        free(hashes);
        return 0;
    }
    free(hashes);
    if (rc)
        return -1;
    const char *dirs[1] = {cfg->out_dir};
    long long missing = assemble(dirs, 1, cfg->out_dir, err);
    if (missing < 0)
        return -1;
    ppb_figures fig = {.who = cfg->name};
    if (missing == 0)
        ppb_sweep_heatmaps(cfg, grid, cfg->out_dir, &fig); /* a figure left out is said there */
    if (!o->quiet && missing)
        fprintf(stderr, "%s: %lld points left to other shards; merge when done\n", cfg->name,
                missing);
    else if (!o->quiet)
        fprintf(stderr, "%s: wrote %s/sweep.csv\n", cfg->name, cfg->out_dir);
    return 0;
}

int ppb_sweep_merge(const char *const *dirs, int n, const char *out_dir, ppb_err *err)
{
    if (same_grids(dirs, n, err))
        return PPB_SWEEP_BAD_CONFIG;
    if (ppb_mkdirs(out_dir, err))
        return -1;
    long long missing = assemble(dirs, n, out_dir, err);
    if (missing < 0)
        return -1;
    if (missing > 0)
        return ppb_fail(err, "%lld grid points are in none of the shard directories", missing);
    return 0;
}
