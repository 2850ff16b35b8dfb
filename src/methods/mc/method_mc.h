/* method_mc.h: the photon Monte Carlo reference (reference: Methods, `mc` and `mc1`): runs
 * kernels/mc.cl over a photon range in chunks, with progress, SIGINT and a target noise.
 *
 * ppb_method_mc is the registry entry; ppb_mc_trace is the building block that sweeps use to
 * trace one shard of a point's photons into integer tallies (src/methods/mc_tally.h), which merge
 * bit-identically. */
#ifndef PPB_METHOD_MC_H
#define PPB_METHOD_MC_H

#include <stdio.h>

#include "methods/mc/mc_rgb_params.h"
#include "methods/mc/mc_tally.h"
#include "methods/method.h"

/* The multi-channel kernel, in the source tree (runtime/ocl.h); it includes mc.cl. */
#define PPB_MC_RGB_KERNEL "src/methods/mc/mc_rgb.cl"

/* The method: traces cfg->mc.photons photons starting at cfg->mc.first and fills out[0] (mc)
 * and out[1] (mc1). Interrupted runs are marked partial with the photons actually traced. */
int ppb_method_mc(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* How a trace ended. */
typedef struct ppb_mc_trace_info {
    long long traced;  /* photons traced: always a prefix [first, first + traced) */
    int interrupted;   /* SIGINT or SIGTERM stopped it after a chunk */
    int reached_noise; /* stopped early at cfg->mc.target_noise */
    double seconds;    /* wall time of the launches */
} ppb_mc_trace_info;

/* Traces photons [first, first + count) of ctx->cfg's scene with ctx->cfg->mc's seed, batches,
 * work-group size (0: 64) and chunk (0: sized to the device, 2^19 photons per compute unit on a
 * CPU), adding them to t (from ppb_mc_tallies_init with the same scene, seed and batches).
 * Stops after the current chunk on SIGINT/SIGTERM (ppb_interrupted) or once noise_rel at the
 * x = 0 cells of S1 and S2 is below cfg->mc.target_noise (checked after every chunk); what was
 * traced is always the prefix [first, first + info->traced), so the result is bit-identical to
 * a run of that many photons. info may be NULL. */
int ppb_mc_trace(ppb_run_ctx *ctx, long long first, long long count, ppb_mc_tallies *t,
                 ppb_mc_trace_info *info, ppb_err *err);

/* ppb_mc_trace for ch->nch channels at once by hero-channel sampling (mc_rgb.cl; docs/methods.md,
 * Monte Carlo: several channels in one run): ctx->cfg is channel 0's experiment (everything but
 * the media, which ch holds), t[c] channel c's tallies (ppb_mc_tallies_init with channel c's
 * scene). The same photon range, chunks, stops and reproducibility as ppb_mc_trace; t changes
 * only when the trace succeeds. */
int ppb_mc_trace_channels(ppb_run_ctx *ctx, const ppb_mc_rgb_params *ch, long long first,
                          long long count, ppb_mc_tallies *t, ppb_mc_trace_info *info,
                          ppb_err *err);

/* The channels' media of cfgs[0 .. nch - 1] for ppb_mc_trace_channels; refuses, naming the
 * channel, experiments that differ in anything but the medium's sigma_t, albedo and g (both
 * sides of a step) or in their [mc] settings, and nch outside 1 .. PPB_MC_MAX_CH. */
int ppb_mc_rgb_params_of(const ppb_config *cfgs, int nch, ppb_mc_rgb_params *ch, ppb_err *err);

/* The registry's run_channels for mc (method.h): every channel's mc and mc1 from one trace,
 * out[2 c] and out[2 c + 1]. Not cached (docs/methods.md says why). */
int ppb_mc_run_channels(ppb_run_ctx *ctx, const ppb_config *cfgs, int nch, ppb_result *out,
                        ppb_err *err);

/* Expected scattering events per photon at cfg's medium (an order of magnitude). */
double ppb_mc_events_per_photon(const ppb_config *cfg);
/* The work line (the registry's work hook): photons x events per photon. */
void ppb_mc_work(const ppb_config *cfg, const char *id, FILE *f);
/* Photons per launch of ctx->cfg's trace on ctx's device: mc.chunk, or when 0 the device's
 * size (its compute units and lanes, $PPBENCH_MC_LANES included). The tallies do not depend on
 * it, but with a target noise the run stops between launches, so the photons traced do: the
 * reference cache's key holds it then (mc_cache.h). */
int ppb_mc_chunk(ppb_run_ctx *ctx, long long *chunk, ppb_err *err);

#endif
