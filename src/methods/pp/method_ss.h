/* method_ss.h: single scattering `ss` (reference: Methods; paper Eq. 5 with n = 1): the same
 * ray march as `pp` with the attenuated direct beam as the only source. */
#ifndef PPB_METHOD_SS_H
#define PPB_METHOD_SS_H

#include "methods/method.h"

/* Fills out[0] with the bin-averaged once-scattered exit radiance and its totals. */
int ppb_method_ss(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Whether ss has a meaning at cfg's point (the registry's check hook). */
int ppb_ss_check(const ppb_config *cfg, ppb_err *err);

#endif
