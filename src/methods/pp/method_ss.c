/* method_ss.c: single scattering by ray marching (method_ss.h). */
#include "methods/pp/method_ss.h"

#include "methods/pp/method_pp.h"

int ppb_method_ss(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return ppb_pp_pipeline(ctx, out, 0, err);
}

/* At n > 1 ss marches the refracted beam and its reflections (kernels/march.cl): off S2 and S1
 * in the slab and in the tube at normal incidence, off all four faces by the cross-section's
 * mirror images at oblique incidence, where a density step's images enter the beam's optical
 * depth (ppb_image_depth). Every n in range has a meaning: nothing is refused. */
int ppb_ss_check(const ppb_config *cfg, ppb_err *err)
{
    (void)cfg;
    (void)err;
    return 0;
}
