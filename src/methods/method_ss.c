/* method_ss.c: single scattering by ray marching (method_ss.h). */
#include "methods/method_ss.h"

#include "methods/method_pp.h"

int ppb_method_ss(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return ppb_pp_pipeline(ctx, out, 0, err);
}

int ppb_ss_check(const ppb_config *cfg, ppb_err *err)
{
    return ppb_method_refuse_refractive(cfg, "ss", err);
}
