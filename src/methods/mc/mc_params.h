/* mc_params.h: the one definition of what the photon Monte Carlo kernel (mc.cl) receives, shared
 * by the host (src/methods/method_mc.c) and the kernel, and the fixed-point tally conventions.
 *
 * Owns: the parameter struct passed by value, the kernel argument indices, the layout of the
 * integer tally buffers and their fixed-point scale. Tallies are integers so that their sums do
 * not depend on the order of accumulation: the result is bit-identical whatever the work-group
 * size, the chunking or the split into shards (reference: Corrections). */
#ifndef PPB_MC_PARAMS_H
#define PPB_MC_PARAMS_H

#include "ppb_medium.h"

#ifdef __OPENCL_VERSION__
typedef ulong ppb_u64;
typedef uint ppb_u32;
#else
#include <stdint.h>
typedef uint64_t ppb_u64;
typedef uint32_t ppb_u32;
#endif

/* One exit weight w in [0, 1] is tallied as round(w * 2^32). A per-batch sum stays below 2^64
 * while a batch holds fewer than 2^31 photons (weights never exceed 1; roulette gains are
 * bounded by the same sum), which the host checks. */
#define PPB_MC_FIXED_SCALE 4294967296.0f

/* Russian roulette (unbiased): below this weight a photon survives with probability
 * 1 / PPB_MC_ROULETTE_M and has its weight multiplied by PPB_MC_ROULETTE_M (a power of two, so
 * the survival test and the new weight are exact in float). */
#define PPB_MC_ROULETTE_W 1e-3f
#define PPB_MC_ROULETTE_M 8.0f

/* Event cap: past PPB_MC_EVENT_CAP scatterings every further interaction is a
 * roulette with the same survival probability 1 / PPB_MC_ROULETTE_M and weight factor, whatever
 * the weight. Roulette is unbiased wherever it is applied, so the estimate keeps its
 * expectation; what changes is the work: a photon that would wander on (at albedo 1 in a thick
 * medium the weight never falls, so the weight test never ends it) survives k more events with
 * probability 8^-k. So that no weight can overflow the fixed-point tallies, the capped roulette
 * stops once the weight has reached PPB_MC_CAP_WMAX (after three survivals, probability 1/512
 * per capped photon); such a photon goes on unrouletted until it leaves, which it does in
 * finite expected time in every geometry here (the medium is bounded in y), and its weight, at
 * most 8 PPB_MC_CAP_WMAX, keeps every tally within range. No photon of the study reaches the
 * cap (its albedos are below 1: a weight falls below PPB_MC_ROULETTE_W within a few hundred
 * events and each roulette ends it with probability 7/8), so its results are unchanged bit for
 * bit; PPB_MC_T_CAPPED counts the capped roulettes. */
#define PPB_MC_CAP_WMAX  512.0f
#define PPB_MC_EVENT_CAP 10000

/* Up to this many phi bins the kernel bins exits by the precomputed edges of mc.cl's
 * ppb_mc_phi_bin; more (the config allows 64) take ppb_phi_bin's atan2, the same bins. */
#define PPB_MC_MAX_PHI 64

/* Per-batch totals (each a fixed-point weight sum unless noted). */
enum {
    PPB_MC_T_BALLISTIC = 0, /* unscattered exits, any surface */
    PPB_MC_T_CAPTURE = 1,   /* weight removed by implicit capture, w (1 - alpha) per scattering */
    PPB_MC_T_RGAIN = 2,     /* weight added by roulette survivors */
    PPB_MC_T_RLOSS = 3,     /* weight of photons ended by roulette */
    PPB_MC_T_EVENTS = 4,    /* scattering events (a plain count) */
    PPB_MC_T_CAPPED = 5,    /* roulettes forced by PPB_MC_EVENT_CAP (a plain count) */
    PPB_MC_NTOT = 8         /* padded: room for more without changing the file format */
};

/* The two cell tallies of every batch: all scattered exits (mc) and once-scattered exits (mc1).
 * Buffer layout: cells[(batch * PPB_MC_NTALLY + tally) * ncells + cell]. */
enum { PPB_MC_TALLY_ALL = 0, PPB_MC_TALLY_ONCE = 1, PPB_MC_NTALLY = 2 };

/* Kernel arguments of ppb_mc_trace_kernel, by index. */
enum { PPB_MC_ARG_PARAMS = 0, PPB_MC_ARG_CELLS = 1, PPB_MC_ARG_TOTALS = 2, PPB_MC_NARGS = 3 };

/* Parameters of one launch, passed by value. 64-bit members first so host and device agree on
 * the layout without packing attributes; the host asserts the size. */
typedef struct ppb_mc_params {
    ppb_u64 seed;   /* Philox key */
    ppb_u64 first;  /* photon index of work-item 0 */
    ppb_u64 count;  /* photons in this launch */
    ppb_u64 ncells; /* cells of one tally (layout.ncells) */
    /* The medium block (ppb_medium_of): med.n <= 1 runs no boundary code. The kernel steps in
     * float: it rounds W, H, step_x, the sigma_t and albedos and g to float where it reads them
     * (mc.cl: ppb_mc_segment, ppb_mc_vbins, ppb_mc_step). */
    ppb_medium med;
    int batches;      /* batch of photon i is i % batches */
    int ntheta, nphi; /* direction bins */
    int nseg[4];      /* segments per surface (slab: 1, 1, 0, 0) */
    int offset[4];    /* first segment row of each surface, as ppb_layout */
    float light_x;    /* w_L = (light_x, light_y, 0), refracted into the medium at n > 1 */
    float light_y;
    float enter_x0; /* photons enter S1 uniformly in [enter_x0, enter_x0 + enter_width) */
    float enter_width;
    float entry_weight; /* 1 - F(cos theta_L) at n > 1 (the rest is specular), else 1 */
} ppb_mc_params;

#endif
