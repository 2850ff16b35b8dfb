/* method_ppslab.h: the `ppslab` method (reference: Methods): the plane-parallel solution itself
 * (src/physics/ppsolver.h, paper Sec. 2.2) evaluated at the faces of a slab, no ray marching. It is
 * the deterministic slab answer that mc, pp and ss are checked against in slab mode. */
#ifndef PPB_METHOD_PPSLAB_H
#define PPB_METHOD_PPSLAB_H

#include "methods/method.h"

/* Fills out[0]: radiance per bin at S1 and S2 (segment 0), averaged over cfg->samples_dir^2
 * directions per bin, se = 0, and the totals R, T, absorbed, ballistic. Slab geometry only. */
int ppb_method_ppslab(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

#endif
