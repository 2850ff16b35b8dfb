/* method_dirpole.h: the directional dipole of Frisvad, Hachisuka & Kjeldsen 2014 applied to the
 * tube as a renderer applies a BSSRDF (reference: Methods, `dirpole`): method id `dirpole`.
 * `dirpole+ss` is the registry's sum of dirpole and ss (method.h: ppb_method_sum). */
#ifndef PPB_METHOD_DIRPOLE_H
#define PPB_METHOD_DIRPOLE_H

#include "methods/method.h"

/* `dirpole`: fills out[0] (already initialised with the scene's layout). */
int ppb_method_dirpole(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Whether dirpole has a meaning at cfg's point: it has on every valid medium (alpha' = 0, no
 * scattering, gives exitance 0); refuses only settings it cannot honour. */
int ppb_dirpole_check(const ppb_config *cfg, ppb_err *err);

#endif
