/* mc_cache.h: the Monte Carlo reference cache (docs/external.md "The reference cache"):
 * tallies of a finished trace stored under a directory by everything that determines them, so
 * a run that needs the same reference traces no photon.
 *
 * The key hashes what the tallies depend on: the resolved value of every config key that the
 * key table marks PPB_MC_KEY (model/config.h: the scene, light, bins, photon range, seed,
 * batches, target noise; not the output, the name or another method's settings), in
 * ppb_config_write_resolved's text form; with a target noise, the photons per launch
 * (ppb_mc_chunk in method_mc.h, which the caller passes: the run stops between launches, so they
 * set how many photons it traces); the kernel's source text (ppb_ocl_source_hash: mc.cl and every
 * header it includes, so an edited kernel never reuses old tallies), the device and its driver (two
 * devices agree within noise, not bit for bit), and PPB_MC_CACHE_VERSION, which stands for the host
 * code that turns a config into the kernel's parameters (bumped when that code changes what the
 * kernel receives). The file is DIR/mc-<key>.bin in mc_tally.h's format (header with the photon
 * range, checksum). A file is used only when its header also matches the run in fingerprint, seed,
 * batches and photon range (a stale or damaged file is a miss, never a wrong reference).
 * Interrupted traces are never stored. The directory is ctx->ref_cache; NULL: no cache.
 *
 * The shipped layer (docs/reference.md, Keys: shipped references): a read-only directory,
 * $PPBENCH_REFERENCES or else <source tree>/references, holding <case>/mc-<key>.bin.xz (a tally
 * file, xz-compressed), consulted after a miss in ctx->ref_cache under the same header checks
 * and the same key but for the device line: the key text without the device and driver, so a
 * reference the repository ships serves every device (two devices agree within the reference's
 * noise, which every metric states, not bit for bit; the shipped provenance.txt names the device
 * it was traced on). Never written by a run, and not consulted without a cache (tests run with
 * none, so they trace). */
#ifndef PPB_MC_CACHE_H
#define PPB_MC_CACHE_H

#include "methods/mc/mc_tally.h"
#include "methods/method.h"

/* 2: the key became the text of the table's PPB_MC_KEY keys (version 1 hashed a hand-kept
 * list), so every version 1 file is a miss. */
#define PPB_MC_CACHE_VERSION 2

/* The cache file of ctx->cfg's reference: ctx->ref_cache/mc-<key>.bin (the current directory
 * when ref_cache is NULL). chunk: the trace's photons per launch (ppb_mc_chunk), in the key when
 * cfg has a target noise, else unused. Opens ctx's device (its name is in the key). */
int ppb_mc_cache_path(ppb_run_ctx *ctx, long long chunk, char *buf, size_t cap, ppb_err *err);

/* Loads ctx->cfg's reference from ctx->ref_cache, else from the shipped layer, into an
 * uninitialised t: 1 when found, 0 when not (t then untouched); a file that exists but cannot be
 * used is said on stderr and counts as a miss, as does a kernel source or device that cannot be
 * identified. On a hit ctx->mc_reference names the file and ctx->mc_reference_shipped is 1 when
 * it came from the shipped layer. */
int ppb_mc_cache_get(ppb_run_ctx *ctx, long long chunk, ppb_mc_tallies *t);

/* Sets ctx->mc_shipped_key to the shipped layer's file name of ctx->cfg's reference
 * (mc-<key>.bin, the key without the device), "" without a cache or when it cannot be made;
 * provenance.txt records it (mc.shipped_key) and scripts/references.sh names the file by it. */
void ppb_mc_cache_note_key(ppb_run_ctx *ctx, long long chunk);

/* The shipped layer's directory: $PPBENCH_REFERENCES, else <source tree>/references. */
const char *ppb_mc_shipped_dir(void);

/* Stores t, which holds photons [cfg->mc.first, + traced) of ctx->cfg's reference, under
 * ctx->ref_cache (made if missing); a failure is said on stderr and is not the run's failure. */
void ppb_mc_cache_put(ppb_run_ctx *ctx, long long chunk, ppb_mc_tallies *t, long long traced);

#endif
