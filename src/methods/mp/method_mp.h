/* method_mp.h: the multipole diffusion baseline of the paper's comparison (reference: Methods):
 * method ids `mp` (Donner & Jensen 2005 multipole for a slab of the tube's thickness, applied
 * to the tube from 3-D source-to-point distances). `mp+ss` is the registry's sum of mp and ss
 * (method.h: ppb_method_sum). */
#ifndef PPB_METHOD_MP_H
#define PPB_METHOD_MP_H

#include "methods/method.h"

/* `mp`: fills out[0] (already initialised with the scene's layout). */
int ppb_method_mp(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Whether mp (and mp+ss) has a meaning at cfg's point: not at albedo 1 (sigma_tr = 0). Fails
 * with the key and the reason; called at config time (ppb_methods_check) and by the method. */
int ppb_mp_check(const ppb_config *cfg, ppb_err *err);

#endif
