#include "methods/mc/perf_mc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/csv_read.h"
#include "methods/mc/method_mc.h"
#include "model/materials.h"
#include "model/metrics.h"

/* Photons per timed case: enough for a few seconds on a 2-core CPU (the launches then dominate
 * the fixed costs); $PPBENCH_PERF_MC_PHOTONS overrides it for quick or long runs. */
#define PERF_MC_PHOTONS 10000000LL

/* The experiment's scene and MC settings with the given g (under `ppbench perf`, src/drivers/perf.c
 * passes the study defaults: the uniform tube of reference: Cases), so no default is coded twice.
 * The photon range is the timed one and a target noise would cut the timing short. */
static int perf_config(const ppb_run_ctx *ctx, double g, ppb_config *cfg, ppb_err *err)
{
    if (ctx->cfg)
        *cfg = *ctx->cfg;
    else if (ppb_config_defaults(cfg, err))
        return -1;
    cfg->scene.g = g;
    cfg->mc.first = 0, cfg->mc.target_noise = 0;
    return 0;
}

/* noise_rel of the tallies at the Table 2 cells (the x = 0 cells of S1 and S2, reference:
 * Metrics), the larger of the two, as [mc] target_noise measures it (method_mc.c); INFINITY
 * while either has no signal. */
static double table2_noise(const ppb_mc_tallies *t, const ppb_scene *sc, ppb_err *err)
{
    ppb_layout lo = ppb_scene_layout(sc);
    ppb_result r;
    if (ppb_result_init(&r, "mc", &lo, err))
        return NAN;
    ppb_mc_tallies_to_results(t, sc, &r, NULL);
    ppb_point pr[2], pt[2];
    double nr = ppb_noise_points(&r, pr, ppb_cell_points(&lo, PPB_CELL_R_X0, pr, 2));
    double nt = ppb_noise_points(&r, pt, ppb_cell_points(&lo, PPB_CELL_T_X0, pt, 2));
    ppb_result_free(&r);
    return (isnan(nr) || isnan(nt)) ? INFINITY : (nr > nt ? nr : nt);
}

/* Traces count photons; returns wall seconds, scattering events and the Table 2 noise
 * (table2_noise) through the pointers. */
static int perf_trace(ppb_run_ctx *ctx, const ppb_config *cfg, long long count, double *seconds,
                      double *events, double *noise, ppb_err *err)
{
    ppb_run_ctx sub = *ctx;
    sub.cfg = cfg;
    sub.quiet = 1;
    ppb_mc_tallies t;
    if (ppb_mc_tallies_init(&t, &cfg->scene, (uint64_t)cfg->mc.seed, cfg->mc.batches, err))
        return -1;
    ppb_mc_trace_info info;
    int rc = ppb_mc_trace(&sub, 0, count, &t, &info, err);
    if (rc == 0) {
        ppb_mc_totals_stats st;
        ppb_mc_tallies_totals(&t, &cfg->scene, 0, &st);
        *seconds = info.seconds;
        *events = st.events_per_photon * (double)info.traced;
        *noise = table2_noise(&t, &cfg->scene, err);
        if (isnan(*noise))
            rc = -1;
    }
    ppb_mc_tallies_free(&t);
    return rc;
}

/* MCX-CL (pmcxcl, Fang et al.) on the equivalent homogeneous slab: a 100 x 100 x 3 grid of
 * 1 mm voxels with mu_a = 0.05, mu_s = 0.95 /mm (sigma_t = 1, alpha = 0.95, tau = 3), HG g,
 * n = 1 inside and out (no reflection), a pencil beam at normal incidence. It runs in a Python
 * child; pmcxcl builds its kernel on PoCL only with libstdc++ preloaded, and reports its
 * statistics only with the fluence output on, so both are set. Its own device choice is the
 * first OpenCL device (gpuid 1), which it names. The child answers in CSV (Python's csv module,
 * which quotes a device name holding a comma) on its original stdout, read by column name;
 * everything pmcxcl itself prints goes to the discarded stderr. Returns photons/s, or 0 when
 * pmcxcl is not installed or fails (then why goes into note). */
static double mcx_photons_per_s(double g, long long photons, char *device, size_t cap, char *note,
                                size_t note_cap)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "LD_PRELOAD=/usr/lib/x86_64-linux-gnu/libstdc++.so.6 python3 -c '"
             "import csv, os, numpy as np, pmcxcl\n"
             "out = os.fdopen(os.dup(1), \"w\")\n"
             "os.dup2(2, 1)\n"
             "cfg = {\"nphoton\": %lld, \"vol\": np.ones((100, 100, 3), dtype=\"uint8\"),"
             " \"tstart\": 0, \"tend\": 1e-8, \"tstep\": 1e-8,"
             " \"srcpos\": [50, 50, 0], \"srcdir\": [0, 0, 1],"
             " \"prop\": [[0, 0, 1, 1], [0.05, 0.95, %.17g, 1]], \"isreflect\": 0,"
             " \"gpuid\": 1, \"autopilot\": 1, \"issave2pt\": 1}\n"
             "pmcxcl.run(dict(cfg, nphoton=10000))\n"
             "r = pmcxcl.run(cfg)\n"
             "w = csv.writer(out, lineterminator=\"\\n\")\n"
             "w.writerow([\"nphoton\", \"runtime_ms\", \"device\"])\n"
             "w.writerow([r[\"stat\"][\"nphoton\"], r[\"stat\"][\"runtime\"],"
             " pmcxcl.gpuinfo()[0][\"name\"]])\n"
             "out.flush()\n"
             "' 2>/dev/null",
             photons, g);
    FILE *p = popen(cmd, "r");
    if (!p) {
        snprintf(note, note_cap, "cannot start python3");
        return 0;
    }
    double rate = 0;
    snprintf(note, note_cap, "pmcxcl not installed or failed");
    ppb_csv c;
    ppb_err err;
    if (ppb_csv_open_stream(&c, p, "pmcxcl", &err) == 0) {
        int cn = ppb_csv_col(&c, "nphoton"), cms = ppb_csv_col(&c, "runtime_ms");
        int cdev = ppb_csv_col(&c, "device");
        double n, ms;
        if (cn >= 0 && cms >= 0 && ppb_csv_next(&c, &err) == 1 && ppb_csv_double(&c, cn, &n) &&
            ppb_csv_double(&c, cms, &ms) && ms > 0) {
            rate = n / (ms * 1e-3);
            snprintf(device, cap, "%s", ppb_csv_get(&c, cdev));
        }
        ppb_csv_close(&c);
    }
    pclose(p);
    return rate;
}

/* pmcxcl is optional: probed with a plain import. */
static int have_pmcxcl(void)
{
    return system("python3 -c 'import pmcxcl' >/dev/null 2>&1") == 0;
}

/* The multi-channel cases: a material of Jensen et al. 2001 (per mm, its n) in a W x H mm tube,
 * its three channels traced by one hero-sampled run (ppb_mc_trace_channels) and by three
 * single-channel runs of the same photons each. Per channel: the Table 2 noise of each and the
 * noise the separate run would have had in a third of the hero run's time (noise falls as
 * 1/sqrt(time)), so that "equal time" compares one hero run with three runs sharing its time. */
static int perf_channels(ppb_run_ctx *ctx, const char *material, double w, double h,
                         long long photons, FILE *out, ppb_err *err)
{
    ppb_config cfgs[3];
    const ppb_material *m = ppb_material_find(material);
    if (!m)
        return ppb_fail(err, "perf: %s is not in the materials table", material);
    for (int c = 0; c < 3; c++) {
        if (perf_config(ctx, 0.0, &cfgs[c], err))
            return -1;
        ppb_scene *sc = &cfgs[c].scene;
        sc->width = w, sc->height = h, sc->step = PPB_STEP_NONE;
        ppb_material_medium(m, (ppb_channel)c, &sc->sigma_t, &sc->albedo, &sc->g, &sc->n);
    }
    ppb_mc_rgb_params ch;
    if (ppb_mc_rgb_params_of(cfgs, 3, &ch, err))
        return -1;
    ppb_run_ctx sub = *ctx;
    sub.cfg = &cfgs[0];
    sub.quiet = 1;
    ppb_mc_tallies t[3];
    memset(t, 0, sizeof t);
    int rc = 0;
    for (int c = 0; c < 3 && rc == 0; c++)
        rc = ppb_mc_tallies_init(&t[c], &cfgs[c].scene, (uint64_t)cfgs[c].mc.seed,
                                 cfgs[c].mc.batches, err);
    ppb_mc_trace_info info;
    /* Warm-up (the kernel's build), then the timed run. */
    if (rc == 0)
        rc = ppb_mc_trace_channels(&sub, &ch, 0, 20000, t, &info, err);
    for (int c = 0; c < 3 && rc == 0; c++) {
        ppb_mc_tallies_free(&t[c]);
        rc = ppb_mc_tallies_init(&t[c], &cfgs[c].scene, (uint64_t)cfgs[c].mc.seed,
                                 cfgs[c].mc.batches, err);
    }
    if (rc == 0)
        rc = ppb_mc_trace_channels(&sub, &ch, 0, photons, t, &info, err);
    if (rc == 0 && info.traced < photons)
        rc = ppb_fail(err, "perf: interrupted after %lld photons", info.traced);
    double hero_s = info.seconds, hero_noise[3] = {0, 0, 0}, hero_ev = 0;
    for (int c = 0; c < 3 && rc == 0; c++) {
        ppb_mc_totals_stats st;
        ppb_mc_tallies_totals(&t[c], &cfgs[c].scene, 0, &st);
        hero_ev = st.events_per_photon;
        hero_noise[c] = table2_noise(&t[c], &cfgs[c].scene, err);
        if (isnan(hero_noise[c]))
            rc = -1;
    }
    for (int c = 0; c < 3; c++)
        ppb_mc_tallies_free(&t[c]);
    if (rc)
        return -1;
    fprintf(out,
            "three channels (%s, %g x %g mm tube, n = %g): one hero-sampled run of %lld "
            "photons, %.3g s, %.4g photons/s, %.3f events/photon\n",
            material, w, h, cfgs[0].scene.n, photons, hero_s, (double)photons / hero_s, hero_ev);
    fprintf(out, "%-8s %10s %10s %10s %12s %16s\n", "channel", "hero s", "noise", "single s",
            "single noise", "single at T/3");
    double single_total = 0;
    const char *names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; c++) {
        double sec, ev, noise;
        if (perf_trace(ctx, &cfgs[c], 20000, &sec, &ev, &noise, err) ||
            perf_trace(ctx, &cfgs[c], photons, &sec, &ev, &noise, err))
            return -1;
        single_total += sec;
        fprintf(out, "%-8s %10.3g %9.3f%% %10.3g %11.3f%% %15.3f%%\n", names[c], hero_s,
                100 * hero_noise[c], sec, 100 * noise, 100 * noise * sqrt(sec / (hero_s / 3.0)));
    }
    fprintf(out,
            "time for all three channels: hero %.3g s, three single runs %.3g s (%.2f x); "
            "noise per channel at equal time: compare the noise column with the last\n",
            hero_s, single_total, single_total / hero_s);
    return 0;
}

int ppb_perf_mc(ppb_run_ctx *ctx, FILE *out, ppb_err *err)
{
    ppb_ocl *ocl;
    if (ppb_ctx_ocl(ctx, &ocl, err)) /* opened here so the sub-contexts share it */
        return -1;
    long long photons = PERF_MC_PHOTONS;
    const char *env = getenv("PPBENCH_PERF_MC_PHOTONS");
    if (env && atoll(env) > 0)
        photons = atoll(env);
    fprintf(out, "device: %s\n", ocl->name);
    /* Time to a noise floor: noise_rel falls as 1/sqrt(photons) (independent batches), so
     * reaching a floor f from the timed run's noise n in its s seconds takes s (n / f)^2. */
    fprintf(out, "%-28s %12s %14s %16s %10s %10s %10s %10s\n", "case", "photons", "photons/s",
            "events/s", "events/ph", "noise", "s to 1%", "s to 0.5%");
    const double gs[2] = {0.0, 0.5};
    for (int i = 0; i < 2; i++) {
        ppb_config cfg;
        double sec, ev, noise;
        if (perf_config(ctx, gs[i], &cfg, err))
            return -1;
        /* Warm-up: the first launch compiles the kernel for its work-group size. */
        if (perf_trace(ctx, &cfg, 20000, &sec, &ev, &noise, err) ||
            perf_trace(ctx, &cfg, photons, &sec, &ev, &noise, err))
            return -1;
        char name[64];
        snprintf(name, sizeof name, "tube uniform g=%.1f", gs[i]);
        double t1 = sec * (noise / 0.01) * (noise / 0.01);
        double t05 = sec * (noise / 0.005) * (noise / 0.005);
        fprintf(out, "%-28s %12lld %14.4g %16.4g %10.3f %9.3f%% %10.4g %10.4g  %s\n", name, photons,
                (double)photons / sec, ev / sec, ev / (double)photons, 100 * noise, t1, t05,
                ev / sec >= 20e6 ? "(>= 20 M events/s target)"
                                 : "(below the 20 M events/s target)");
    }

    /* Short paths (six events a photon), then long ones (marble, a tenth of the photons). */
    if (perf_channels(ctx, "skimmilk", 4, 2, photons, out, err) ||
        perf_channels(ctx, "marble", 10, 3, photons / 10 > 20000 ? photons / 10 : 20000, out, err))
        return -1;

    /* MCX-CL on the same device, same run, on the equivalent slab: ours in slab mode (the
     * same medium, thickness and beam), photons/s against photons/s. */
    if (!have_pmcxcl()) {
        fprintf(out, "MCX-CL comparison skipped: the Python package pmcxcl is not installed\n");
        return 0;
    }
    const long long mcx_photons = 1000000;
    for (int i = 0; i < 2; i++) {
        ppb_config cfg;
        double sec, ev, noise;
        if (perf_config(ctx, gs[i], &cfg, err))
            return -1;
        cfg.scene.geometry = PPB_GEOM_SLAB;
        if (perf_trace(ctx, &cfg, photons, &sec, &ev, &noise, err))
            return -1;
        char device[512] = "?", note[128];
        double mcx =
            mcx_photons_per_s(gs[i], mcx_photons, device, sizeof device, note, sizeof note);
        double ours = (double)photons / sec;
        if (mcx <= 0) {
            fprintf(out, "slab tau=3 g=%.1f: ppbench %.4g photons/s; MCX-CL: %s\n", gs[i], ours,
                    note);
            continue;
        }
        fprintf(out,
                "slab tau=3 g=%.1f: ppbench %.4g photons/s, MCX-CL (pmcxcl on %s) %.4g "
                "photons/s: ratio %.2f\n",
                gs[i], ours, device, mcx, ours / mcx);
    }
    return 0;
}
