/* mc_tally.h: the photon Monte Carlo's integer tallies and what is derived from them.
 *
 * Owns: the per-batch fixed-point tallies (mc: all scattered exits, mc1: once-scattered exits,
 * per (surface, segment, bin); totals), their binary file form, their merge (plain integer
 * addition, so shards merged in any order give the same bytes as one run with the whole
 * budget), and the conversion to radiance with standard errors from the batch means
 * (reference: Bins, Metrics, Methods). Layout and scale: kernels/mc_params.h. */
#ifndef PPB_MC_TALLY_H
#define PPB_MC_TALLY_H

#include <stddef.h>
#include <stdint.h>

#include "methods/mc/mc_params.h"
#include "base/err.h"
#include "model/result.h"
#include "model/scene.h"

typedef struct ppb_mc_tallies {
    uint64_t fingerprint; /* hash of the scene and bin settings: merges refuse a mismatch */
    uint64_t seed;
    /* The photons these tallies hold, for a shard's file: [first, first + count) of the run's
     * budget [budget_first, budget_first + budget_photons), photon indices as ppb_mc_trace
     * takes them. Zero (unknown) unless the caller sets them; a merge checks that its files'
     * ranges tile the budget (drivers/mc_shard.c). */
    uint64_t budget_first, budget_photons, first, count;
    int batches;
    size_t ncells;
    uint64_t *photons; /* [batches]: photons traced in each batch */
    uint64_t *cells;   /* [batches][PPB_MC_NTALLY][ncells], fixed point (PPB_MC_FIXED_SCALE) */
    uint64_t *totals;  /* [batches][PPB_MC_NTOT] */
} ppb_mc_tallies;

/* Zeroed tallies for a scene, seed and batch count. */
int ppb_mc_tallies_init(ppb_mc_tallies *t, const ppb_scene *sc, uint64_t seed, int batches,
                        ppb_err *err);
void ppb_mc_tallies_free(ppb_mc_tallies *t);

/* Hash of everything that changes what a photon does or where it is tallied. */
uint64_t ppb_mc_scene_fingerprint(const ppb_scene *sc);

/* Total photons over all batches. */
uint64_t ppb_mc_tallies_photons(const ppb_mc_tallies *t);

/* Records photons [first, first + count) as traced: adds them to their batches (i % batches). */
void ppb_mc_tallies_count_range(ppb_mc_tallies *t, uint64_t first, uint64_t count);

/* Whether the photons per batch are those of the range [first, first + count): 1 or 0. */
int ppb_mc_tallies_range_matches(const ppb_mc_tallies *t);

/* 1 when a and b hold the same photons, totals and cells bit for bit (the reproducibility
 * checks: work-group sizes, chunkings, shards, channels), else 0. */
int ppb_mc_tallies_equal(const ppb_mc_tallies *a, const ppb_mc_tallies *b);

/* dst += src, refusing tallies of another scene, seed or batch count, and overflow. */
int ppb_mc_tallies_add(ppb_mc_tallies *dst, const ppb_mc_tallies *src, ppb_err *err);

/* Binary file, every number a little-endian uint64: the magic "PPBMCT03"; the header
 * (fingerprint, seed, batches, ncells, budget_first, budget_photons, first, count); photons
 * [batches]; totals [batches][PPB_MC_NTOT]; cells [batches][PPB_MC_NTALLY][ncells]; last the
 * checksum, ppb_hash64 (base/hash.h) of every byte before it. Written atomically
 * (base/atomic_file.h), so a kill never leaves half a file. */
int ppb_mc_tallies_save(const ppb_mc_tallies *t, const char *path, ppb_err *err);
/* Loads into an uninitialised t (allocates). Refuses, naming path, a file of another version,
 * a truncated or oversized one and one whose checksum does not match (a flipped bit). */
int ppb_mc_tallies_load(ppb_mc_tallies *t, const char *path, ppb_err *err);

/* Radiance (1/sr per E_perp) and standard error per cell, and totals, of mc (all scattered
 * exits) and mc1 (once-scattered exits). Either pointer may be NULL. Both results must have
 * been initialised with the scene's layout. */
void ppb_mc_tallies_to_results(const ppb_mc_tallies *t, const ppb_scene *sc, ppb_result *mc,
                               ppb_result *mc1);

/* Totals of mc (once = 0) or mc1 (once = 1) and their standard errors from the batch means.
 * absorbed is tracked (capture plus the roulette balance); roulette is the roulette balance
 * alone (loss - gain), zero in expectation. */
typedef struct ppb_mc_totals_stats {
    ppb_totals mean, se;
    double roulette, roulette_se;
    double capture, capture_se; /* implicit capture alone */
    double events_per_photon;
} ppb_mc_totals_stats;
/* Allocates nothing, so it cannot fail (it once returned zeroed statistics, silently, when a
 * scratch allocation failed). */
void ppb_mc_tallies_totals(const ppb_mc_tallies *t, const ppb_scene *sc, int once,
                           ppb_mc_totals_stats *st);

/* Attaches mc_totals.csv to mc as its extra output (model/result.h): the totals of mc and mc1
 * with their standard errors from the batch means (reference: Outputs), what a comparison per
 * surface against the Monte Carlo needs (scripts/rte2d_reference.sh). */
int ppb_mc_tallies_attach_totals(const ppb_mc_tallies *t, const ppb_scene *sc, ppb_result *mc,
                                 ppb_err *err);

/* The Monte Carlo kernel, in the source tree (runtime/ocl.h). */
#define PPB_MC_KERNEL "src/methods/mc/mc.cl"

#endif
