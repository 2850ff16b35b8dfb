/* method_ss.c: single scattering by ray marching (method_ss.h). */
#include "methods/method_ss.h"

#include "methods/method_pp.h"

int ppb_method_ss(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return ppb_pp_pipeline(ctx, out, 0, err);
}

/* At n > 1 ss marches the refracted beam and its reflections (kernels/march.cl): off S2 and S1
 * in the slab and in the tube at normal incidence, off all four faces by the cross-section's
 * mirror images at oblique incidence, which assume one sigma_t: oblique light with a density
 * step at n > 1 is still refused. */
int ppb_ss_check(const ppb_config *cfg, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    if (sc->n > 1.0 && sc->geometry == PPB_GEOM_TUBE && sc->theta_deg != 0.0 &&
        sc->step == PPB_STEP_DENSITY && sc->sigma_t_right != sc->sigma_t)
        return ppb_method_refuse_refractive(cfg, "ss", err);
    return 0;
}
