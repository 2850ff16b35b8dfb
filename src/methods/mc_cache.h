/* mc_cache.h: the Monte Carlo reference cache (`--ref-cache DIR`, docs/external.md):
 * tallies of a finished trace stored under DIR by what determines them, so a run that needs the
 * same reference traces no photon.
 *
 * The key hashes the tallies' scene fingerprint (ppb_mc_scene_fingerprint: geometry, medium,
 * light, bins), the seed, the batch count, the photon range [first, first + photons) and the
 * target noise; the file is DIR/mc-<key>.bin in mc_tallies.bin's own format (methods/mc_tally.h:
 * header with the photon range, checksum). A file is used only when its header matches the run
 * in every one of those (a key collision or a stale file is a miss, never a wrong reference).
 * Interrupted traces are never stored. Tallies are bit-identical across work-group sizes and
 * chunkings on one device; across devices they agree within noise, so a cache filled on one
 * device serves another with that device's answer, not this one's. */
#ifndef PPB_MC_CACHE_H
#define PPB_MC_CACHE_H

#include "methods/mc_tally.h"
#include "model/config.h"

/* Loads cfg's reference from dir into an uninitialised t: 1 when found, 0 when not (t then
 * untouched); a file that exists but cannot be used is said on stderr and counts as a miss. */
int ppb_mc_cache_get(const char *dir, const ppb_config *cfg, ppb_mc_tallies *t);

/* Stores t, which holds photons [cfg->mc.first, + traced) of cfg's reference, under dir
 * (made if missing); a failure is said on stderr and is not the run's failure. */
void ppb_mc_cache_put(const char *dir, const ppb_config *cfg, ppb_mc_tallies *t, long long traced);

#endif
