/* mc_shard.h: one Monte Carlo run split across machines: each shard traces a
 * disjoint photon range of the same config into integer tallies (mc_tallies.bin), and the
 * merge adds them and writes the experiment's outputs for mc and mc1 -- byte-identical to one
 * `ppbench run` of the whole budget with methods = mc, since photon i's random numbers and
 * batch depend on i alone and the tallies add as integers. */
#ifndef PPB_MC_SHARD_H
#define PPB_MC_SHARD_H

#include "model/config.h"
#include "base/err.h"

/* Traces part i (1-based) of n of cfg's photons into <out_dir>/mc_tallies.bin. */
int ppb_mc_shard_run(const ppb_config *cfg, const char *device, int quiet, int i, int n,
                     ppb_err *err);

/* What ppb_mc_shard_merge returns when the shards will not do (a directory without tallies, a
 * shard of another config, photons missing or twice): bad input, exit code 2. */
enum { PPB_MC_MERGE_BAD_SHARDS = -2 };

/* Adds the tallies found in dirs and writes cfg's outputs (mc, mc1) under cfg->out_dir: 0, -1
 * (writing failed) or PPB_MC_MERGE_BAD_SHARDS. */
int ppb_mc_shard_merge(const ppb_config *cfg, const char *const *dirs, int ndirs, ppb_err *err);

#endif
