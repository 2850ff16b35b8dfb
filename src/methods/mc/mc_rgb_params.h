/* mc_rgb_params.h: what the multi-channel Monte Carlo kernel (mc_rgb.cl) receives beside mc.cl's
 * parameter block (mc_params.h), shared by the host (method_mc_rgb.c) and the kernel.
 *
 * Owns: the per-channel medium (sigma_t, its logarithm, albedo on each side of the step, the HG
 * g), the kernel's extra argument index and the tally layout of a multi-channel launch: one
 * mc.cl tally set per channel, cells[((channel * batches + batch) * PPB_MC_NTALLY + tally) *
 * ncells + cell] and totals[(channel * batches + batch) * PPB_MC_NTOT + total]. Floats only, so
 * host and device agree on the layout without packing attributes. */
#ifndef PPB_MC_RGB_PARAMS_H
#define PPB_MC_RGB_PARAMS_H

#include "mc_params.h"

/* At most this many channels in one run (R, G, B). */
#define PPB_MC_MAX_CH 3

/* The kernel's arguments: mc.cl's three, then this block by value. */
enum { PPB_MC_RGB_ARG_CHANNELS = PPB_MC_NARGS, PPB_MC_RGB_NARGS = PPB_MC_NARGS + 1 };

typedef struct ppb_mc_rgb_params {
    /* [channel][0]: left of the step (x < step_x), [channel][1]: right, as mc.cl's medium[]
     * array (a side without a step of that kind holds the left value). */
    float sigma_t[PPB_MC_MAX_CH][2];
    float log_sigma_t[PPB_MC_MAX_CH][2]; /* log of the float sigma_t, rounded from double */
    float albedo[PPB_MC_MAX_CH][2];
    /* HG asymmetry as the config gives it (where the channels' g differ the kernel takes
     * |g| < 1e-4 as 0, as the HG sampler then draws isotropic directions) and log(1 - g^2) of
     * that g, the normalisation in the phase ratio. */
    float g[PPB_MC_MAX_CH];
    float log_1mg2[PPB_MC_MAX_CH];
    int same_g; /* every channel has the same g: no phase ratio, mc.cl's scalar HG sampler */
    int nch;    /* channels in the run; the kernel is built for this many (PPB_MC_NCH) */
} ppb_mc_rgb_params;

#endif
