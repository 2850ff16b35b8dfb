#include "methods/method.h"

#include <string.h>

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

const ppb_result *ppb_ctx_prior(const ppb_run_ctx *ctx, const char *id)
{
    for (int i = 0; i < ctx->nprior; i++)
        if (strcmp(ctx->prior[i].method, id) == 0 && !ctx->prior[i].partial)
            return &ctx->prior[i];
    return NULL;
}
