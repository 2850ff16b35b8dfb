#include "methods/method.h"

int ppb_ctx_ocl(ppb_run_ctx *ctx, ppb_ocl **ocl, ppb_err *err)
{
    if (!ctx->ocl_open) {
        if (ppb_ocl_open(&ctx->ocl, ctx->device_selector, err))
            return -1;
        ctx->ocl_open = 1;
    }
    *ocl = &ctx->ocl;
    return 0;
}

void ppb_ctx_close(ppb_run_ctx *ctx)
{
    if (ctx->ocl_open)
        ppb_ocl_close(&ctx->ocl);
    ctx->ocl_open = 0;
}
