/* method_pp.c: the paper's method, plane-parallel ray marching (method_pp.h). */
#include "methods/method_pp.h"

#include "methods/march.h"

int ppb_method_pp(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return ppb_march_method(ctx, out, 1, err);
}
