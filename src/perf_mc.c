#include "perf_mc.h"

#include <stdlib.h>
#include <string.h>

#include "method_mc.h"

/* Photons per timed case: enough for a few seconds on a 2-core CPU (the launches then dominate
 * the fixed costs); $PPBENCH_PERF_MC_PHOTONS overrides it for quick or long runs. */
#define PERF_MC_PHOTONS 4000000LL

/* SPEC.md section 6's tube with the given g; the settings that do not change the physics
 * (work-group, chunk) come from the experiment when there is one. */
static void perf_config(const ppb_run_ctx *ctx, double g, ppb_config *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    if (ctx->cfg)
        cfg->mc = ctx->cfg->mc;
    else
        cfg->mc.batches = 16, cfg->mc.seed = 1;
    cfg->mc.first = 0, cfg->mc.target_noise = 0;
    cfg->scene = (ppb_scene){.geometry = PPB_GEOM_TUBE,
                             .width = 10,
                             .height = 3,
                             .segments_top = 128,
                             .segments_side = 36,
                             .sigma_t = 1,
                             .albedo = 0.95,
                             .g = g,
                             .step = PPB_STEP_NONE,
                             .step_x = 0,
                             .sigma_t_right = 0.5,
                             .albedo_right = 0.475,
                             .theta_deg = 0,
                             .ntheta = 8,
                             .nphi = 8};
}

/* Traces count photons; returns wall seconds and scattering events through the pointers. */
static int perf_trace(ppb_run_ctx *ctx, const ppb_config *cfg, long long count, double *seconds,
                      double *events, ppb_err *err)
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
    }
    ppb_mc_tallies_free(&t);
    return rc;
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
    fprintf(out, "%-28s %12s %14s %16s %10s\n", "case", "photons", "photons/s", "events/s",
            "events/ph");
    const double gs[2] = {0.0, 0.5};
    for (int i = 0; i < 2; i++) {
        ppb_config cfg;
        perf_config(ctx, gs[i], &cfg);
        double sec, ev;
        /* Warm-up: the first launch compiles the kernel for its work-group size. */
        if (perf_trace(ctx, &cfg, 20000, &sec, &ev, err) ||
            perf_trace(ctx, &cfg, photons, &sec, &ev, err))
            return -1;
        char name[64];
        snprintf(name, sizeof name, "tube uniform g=%.1f", gs[i]);
        fprintf(out, "%-28s %12lld %14.4g %16.4g %10.3f  %s\n", name, photons,
                (double)photons / sec, ev / sec, ev / (double)photons,
                ev / sec >= 20e6 ? "(>= 20 M events/s target)"
                                 : "(below the 20 M events/s target)");
    }
    return 0;
}
