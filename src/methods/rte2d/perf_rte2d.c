/* perf_rte2d.c: the rte2d benchmark (perf_rte2d.h). */
#include "methods/rte2d/perf_rte2d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/clock.h"
#include "methods/rte2d/method_rte2d.h"

/* Photons of the reference's timed run per case: its noise there (8-14 % at the worst summary
 * cell) is far above any accuracy it is scaled to, so what is extrapolated is its 1/sqrt(photons)
 * law (independent batches: reference: Metrics); $PPBENCH_PERF_MC_PHOTONS overrides it. */
#define PERF_RTE_MC_PHOTONS 4000000LL

/* The tree configs/ is in: $PPBENCH_SOURCE, else the build's source directory. */
#ifndef PPB_SOURCE_DIR
#define PPB_SOURCE_DIR "."
#endif
static const char *source_root(void)
{
    const char *d = getenv("PPBENCH_SOURCE");
    return (d && *d) ? d : PPB_SOURCE_DIR;
}

/* rte2d on cfg, converged, without the refinement study (a reference's cost is the solve and
 * its exit march); seconds and the solve's stats through the pointers. */
static int rte_run(ppb_run_ctx *ctx, const ppb_config *cfg, ppb_result *r, double *seconds,
                   ppb_rte2d_stats *st, ppb_err *err)
{
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    if (ppb_result_init(r, "rte2d", &lo, err))
        return -1;
    const ppb_config *given = ctx->cfg;
    int quiet = ctx->quiet, extras = ctx->extras;
    ctx->cfg = cfg;
    ctx->quiet = 1;
    ctx->extras = 0;
    double t0 = ppb_now();
    int rc = ppb_rte2d_run(ctx, r, st, err);
    *seconds = ppb_now() - t0;
    ctx->cfg = given;
    ctx->quiet = quiet;
    ctx->extras = extras;
    if (rc)
        ppb_result_free(r);
    return rc;
}

/* The largest rms_rel over the summary cells of a against b. */
static double worst_cell(const ppb_result *a, const ppb_result *b)
{
    const ppb_layout *lo = &a->layout;
    int cap = lo->nseg[PPB_S1] > lo->nseg[PPB_S3] ? lo->nseg[PPB_S1] : lo->nseg[PPB_S3];
    ppb_point *pts = malloc(sizeof *pts * (size_t)(cap > 2 ? cap : 2));
    double worst = pts ? 0.0 : NAN;
    for (int cell = 0; pts && cell < PPB_NCELLS; cell++) {
        int np = ppb_cell_points(lo, cell, pts, cap > 2 ? cap : 2);
        double e = np ? ppb_rms_points(a, b, pts, np).rms_rel : 0.0;
        if (!(e <= worst))
            worst = e;
    }
    free(pts);
    return worst;
}

/* The largest noise_rel over the summary cells of the reference's result r. */
static double worst_noise(const ppb_result *r)
{
    const ppb_layout *lo = &r->layout;
    int cap = lo->nseg[PPB_S1] > lo->nseg[PPB_S3] ? lo->nseg[PPB_S1] : lo->nseg[PPB_S3];
    ppb_point *pts = malloc(sizeof *pts * (size_t)(cap > 2 ? cap : 2));
    double worst = pts ? 0.0 : NAN;
    for (int cell = 0; pts && cell < PPB_NCELLS; cell++) {
        int np = ppb_cell_points(lo, cell, pts, cap > 2 ? cap : 2);
        double e = np ? ppb_noise_points(r, pts, np) : 0.0;
        if (!(e <= worst))
            worst = e;
    }
    free(pts);
    return worst;
}

/* The reference on cfg's scene with photons traced (no cache: ctx->ref_cache off for the run), wall
 * seconds and the worst summary cell's noise_rel through the pointers. */
static int mc_trace(ppb_run_ctx *ctx, const ppb_method *m, const ppb_config *base,
                    long long photons, double *seconds, double *noise, ppb_err *err)
{
    ppb_config *cfg = malloc(sizeof *cfg);
    if (!cfg)
        return ppb_fail(err, "perf: out of memory");
    *cfg = *base;
    cfg->mc.photons = photons;
    cfg->mc.first = 0;
    cfg->mc.target_noise = 0;
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    ppb_result out[2];
    int n = 0, rc = 0;
    if (ppb_result_init(&out[n], m->id, &lo, err))
        rc = -1;
    else
        n++;
    if (!rc && m->also) {
        if (ppb_result_init(&out[n], m->also, &lo, err))
            rc = -1;
        else
            n++;
    }
    if (!rc) {
        ppb_run_ctx saved = *ctx; /* the fields set here, restored after */
        ctx->cfg = cfg;
        ctx->quiet = 2;
        ctx->extras = 0;
        ctx->ref_cache = NULL;
        ctx->prior = NULL, ctx->nprior = 0;
        ctx->self = m;
        double t0 = ppb_now();
        rc = m->run(ctx, out, err);
        *seconds = ppb_now() - t0;
        ctx->cfg = saved.cfg, ctx->quiet = saved.quiet, ctx->extras = saved.extras;
        ctx->ref_cache = saved.ref_cache, ctx->self = saved.self;
        ctx->prior = saved.prior, ctx->nprior = saved.nprior;
        if (!rc)
            *noise = worst_noise(&out[0]);
    }
    for (int i = 0; i < n; i++)
        ppb_result_free(&out[i]);
    free(cfg);
    return rc;
}

/* Richardson's estimate of a run's distance to its limit from the change d to one refined by 2
 * in a parameter the error goes with as h^p: e = d 2^p / (2^p - 1); p = 1, the flat source's
 * order in the grid and the least the cells have shown (docs/methods.md), so e = 2 d bounds
 * the higher orders' too. */
#define PERF_RTE_RICHARDSON 2.0

/* One case: rte2d at its settings, with the grid and track spacing halved, with the direction
 * cells doubled; the reference's rate on the same scene. */
static int perf_case(ppb_run_ctx *ctx, const ppb_method *mc, const char *name, long long photons,
                     FILE *out, ppb_err *err)
{
    char path[4200];
    snprintf(path, sizeof path, "%.4000s/configs/%.150s.ini", source_root(), name);
    ppb_config *cfg = malloc(3 * sizeof *cfg);
    if (!cfg)
        return ppb_fail(err, "perf: out of memory");
    ppb_config *fine_x = cfg + 1, *fine_w = cfg + 2;
    int rc = ppb_config_load(cfg, path, err);
    if (!rc) {
        *fine_x = *cfg;
        fine_x->rte2d.spacing *= 0.5;
        fine_x->rte2d.step *= 0.5;
        *fine_w = *cfg;
        fine_w->rte2d.directions *= 2;
    }
    ppb_result r0, rx, rw;
    ppb_rte2d_stats st, sx, sw;
    double t0 = 0, tx = 0, tw = 0, tmc = 0, noise = NAN;
    int ok0 = 0, okx = 0, okw = 0;
    if (!rc && !(rc = rte_run(ctx, cfg, &r0, &t0, &st, err)))
        ok0 = 1;
    if (!rc && !(rc = rte_run(ctx, fine_x, &rx, &tx, &sx, err)))
        okx = 1;
    if (!rc && !(rc = rte_run(ctx, fine_w, &rw, &tw, &sw, err)))
        okw = 1;
    /* The reference's warm-up (its kernel build), then the timed run. */
    if (!rc && mc)
        rc = mc_trace(ctx, mc, cfg, 20000, &tmc, &noise, err);
    if (!rc && mc)
        rc = mc_trace(ctx, mc, cfg, photons, &tmc, &noise, err);
    if (!rc) {
        double ex = PERF_RTE_RICHARDSON * worst_cell(&r0, &rx);
        double ew = PERF_RTE_RICHARDSON * worst_cell(&r0, &rw);
        double e = ex + ew; /* both limits at once: the triangle inequality's bound */
        /* The reference's noise falls as 1/sqrt(photons): to e in tmc (noise / e)^2. */
        double tmc_e = mc ? tmc * (noise / e) * (noise / e) : NAN;
        fprintf(out,
                "%-31s %5d x %3d %6.2f %3d %5.2f %5.2f %7.3f%% %7.3f%% %7.3f%%  %6.1f %6.1f  "
                "%8.3g %6.2f%% %10.4g %8.3g\n",
                name, st.nodes, st.cells, t0, st.sweeps, st.t_sweeps, st.t_exit, 100 * e, 100 * ex,
                100 * ew, tx, tw, mc ? (double)photons / tmc : NAN, 100 * noise, tmc_e, tmc_e / t0);
    }
    if (ok0)
        ppb_result_free(&r0);
    if (okx)
        ppb_result_free(&rx);
    if (okw)
        ppb_result_free(&rw);
    free(cfg);
    return rc;
}

/* The cases: $PPBENCH_PERF_RTE2D_CASES (comma-separated), else configs/study.list. Calls
 * fn on each; stops at the first failure. */
static int each_case(ppb_run_ctx *ctx, const ppb_method *mc, long long photons, FILE *out,
                     ppb_err *err)
{
    const char *env = getenv("PPBENCH_PERF_RTE2D_CASES");
    char line[256];
    if (env && *env) {
        char *list = strdup(env);
        if (!list)
            return ppb_fail(err, "perf: out of memory");
        int rc = 0;
        for (char *save = NULL, *c = strtok_r(list, ",", &save); !rc && c;
             c = strtok_r(NULL, ",", &save))
            rc = perf_case(ctx, mc, c, photons, out, err);
        free(list);
        return rc;
    }
    char path[4200];
    snprintf(path, sizeof path, "%.4000s/configs/study.list", source_root());
    FILE *f = fopen(path, "r");
    if (!f)
        return ppb_fail(err, "%s: cannot open (the study's cases)", path);
    int rc = 0, n = 0;
    while (!rc && fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        if (!line[0] || line[0] == '#')
            continue;
        n++;
        rc = perf_case(ctx, mc, line, photons, out, err);
    }
    fclose(f);
    return rc || n ? rc : ppb_fail(err, "%s: no case", path);
}

int ppb_perf_rte2d(ppb_run_ctx *ctx, FILE *out, ppb_err *err)
{
    long long photons = PERF_RTE_MC_PHOTONS;
    const char *env = getenv("PPBENCH_PERF_MC_PHOTONS");
    if (env && atoll(env) > 0)
        photons = atoll(env);
    const ppb_method *mc = ctx->reference; /* set by `ppbench perf` */
    fprintf(out,
            "Per study case: rte2d converged at the case's settings (nodes x cells, seconds, its "
            "sweeps and\ntheir seconds, the exit march's seconds); its estimated distance to "
            "its own limit e (the\nworst summary cell's rms_rel) = e_grid + e_dir, each 2 x the "
            "change when the grid and track\nspacing are halved (t_grid: that run's seconds) or "
            "the direction cells doubled (t_dir)\n(Richardson, first order); the Monte Carlo's "
            "rate at %lld photons on the same case, its\nnoise (the worst cell) and its time to "
            "noise e: t (noise / e)^2.\n",
            photons);
    fprintf(out, "%-31s %11s %6s %3s %5s %5s %8s %8s %8s  %6s %6s  %8s %7s %10s %8s\n", "case",
            "nodes x cel", "s", "swp", "t_swp", "t_ext", "e", "e_grid", "e_dir", "t_grid", "t_dir",
            "mc ph/s", "noise", "mc s to e", "mc/rte2d");
    return each_case(ctx, mc, photons, out, err);
}
