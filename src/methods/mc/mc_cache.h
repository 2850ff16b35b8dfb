/* mc_cache.h: the Monte Carlo reference cache (docs/external.md "The reference cache"):
 * tallies of a finished trace stored under a directory by everything that determines them, so
 * a run that needs the same reference traces no photon.
 *
 * The key hashes what the tallies depend on: the tallies' scene fingerprint
 * (ppb_mc_scene_fingerprint: geometry, medium, light, bins), the seed, the batch count, the
 * photon range [first, first + photons), the target noise, the kernel's source text
 * (ppb_ocl_source_hash: kernels/mc.cl and every header it includes, so an edited kernel never
 * reuses old tallies), the device and its driver (two devices agree within noise, not bit for
 * bit), and PPB_MC_CACHE_VERSION, which stands for the host code that turns a config into the
 * kernel's parameters (bumped when that code changes what the kernel receives). The file is
 * DIR/mc-<key>.bin in mc_tally.h's format (header with the photon range, checksum). A file is
 * used only when its header also matches the run in fingerprint, seed, batches and photon
 * range (a stale or damaged file is a miss, never a wrong reference). Interrupted traces are
 * never stored. The directory is ctx->ref_cache; NULL: no cache. */
#ifndef PPB_MC_CACHE_H
#define PPB_MC_CACHE_H

#include "methods/mc/mc_tally.h"
#include "methods/method.h"

#define PPB_MC_CACHE_VERSION 1

/* Loads ctx->cfg's reference from ctx->ref_cache into an uninitialised t: 1 when found, 0 when
 * not (t then untouched); a file that exists but cannot be used is said on stderr and counts as
 * a miss, as does a kernel source or device that cannot be identified. */
int ppb_mc_cache_get(ppb_run_ctx *ctx, ppb_mc_tallies *t);

/* Stores t, which holds photons [cfg->mc.first, + traced) of ctx->cfg's reference, under
 * ctx->ref_cache (made if missing); a failure is said on stderr and is not the run's failure. */
void ppb_mc_cache_put(ppb_run_ctx *ctx, ppb_mc_tallies *t, long long traced);

#endif
