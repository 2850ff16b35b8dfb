/* method_mc3d.h: the object Monte Carlo `mc3d` (docs/methods.md, mc3d): the reference every
 * object method is measured against, radiance per patch and bin and per camera pixel, with its
 * once-scattered part `mc3d1`, from photons traced through the voxel grid by mc3d.cl. Also the
 * run's totals (energy balance, events), which the driver records and tests check. */
#ifndef PPB_METHOD_MC3D_H
#define PPB_METHOD_MC3D_H

#include "methods/object_method.h"

/* What one run traced, over its batches: photons launched and reaching the medium, and per
 * incident photon that reached it (weight 1 each) the weight escaped (of it unscattered), absorbed,
 * lost and gained by roulette; escaped + absorbed is 1 within the roulette's noise, and with
 * the roulette's terms 1 to rounding (mc3d_params.h). */
typedef struct ppb_mc3d_totals {
    long long launched, hits, events, capped;
    double escaped, ballistic, absorbed, rgain, rloss;
    double escaped_se, absorbed_se; /* standard errors over the batches */
    double proj_area;               /* the light's entry area, grid box projected across it */
} ppb_mc3d_totals;

/* Traces cfg->mc.photons photons from cfg->mc.first through o; out[0] all scattered light,
 * out[1] the once-scattered part; totals (may be NULL) as above. Refuses n != 1. */
int ppb_mc3d_trace(ppb_run_ctx *ctx, const ppb_object *o, const ppb_object_patches *p,
                   ppb_object_result *out, ppb_mc3d_totals *totals, ppb_err *err);

/* The object method's run (methods/object_method.h). */
int ppb_object_method_mc3d(ppb_run_ctx *ctx, const ppb_object *o, const ppb_object_patches *p,
                           ppb_object_result *out, ppb_err *err);

#endif
