/* method_pbd.h: photon beam diffusion (Habel, Christensen & Jarosz 2013) as pbrt-v4 ships it,
 * applied to the tube as a renderer applies a BSSRDF (reference: Methods, `pbd`): method id
 * `pbd`. Its profile holds single scattering (BeamDiffusionSS), so there is no `pbd+ss`. */
#ifndef PPB_METHOD_PBD_H
#define PPB_METHOD_PBD_H

#include "methods/method.h"

/* `pbd`: fills out[0] (already initialised with the scene's layout). */
int ppb_method_pbd(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Whether pbd has a meaning at cfg's point: it has on every valid medium (the table spans
 * albedos 0 to 1, any g and n); refuses only settings the shared tube code cannot honour. */
int ppb_pbd_check(const ppb_config *cfg, ppb_err *err);

#endif
