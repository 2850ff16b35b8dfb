/* method_bdipole.h: d'Eon's better dipole applied to the tube as a renderer applies a BSSRDF
 * (reference: Methods, `bdipole`): method id `bdipole`. `bdipole+ss` is the registry's sum of
 * bdipole and ss (method.h: ppb_method_sum). */
#ifndef PPB_METHOD_BDIPOLE_H
#define PPB_METHOD_BDIPOLE_H

#include "methods/method.h"

/* `bdipole`: fills out[0] (already initialised with the scene's layout). */
int ppb_method_bdipole(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Whether bdipole has a meaning at cfg's point: it has on every valid medium (sigma_t' > 0 and
 * D > 0 for every albedo and g in (-1, 1)); refuses only settings it cannot honour. */
int ppb_bdipole_check(const ppb_config *cfg, ppb_err *err);

#endif
