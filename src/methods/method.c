/* method.c: the run context (method.h) and the sum of methods, the one method made of others. */
#include "methods/method.h"

#include <stdlib.h>
#include <string.h>

#include "base/progress.h"
#include "methods/result_check.h"

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
    ppb_ctx_drop_state(ctx);
}

void ppb_ctx_drop_state(ppb_run_ctx *ctx)
{
    for (int i = 0; i < ctx->nstate; i++)
        if (ctx->state[i].release)
            ctx->state[i].release(ctx->state[i].data);
    ctx->nstate = 0;
}

void *ppb_ctx_state(const ppb_run_ctx *ctx, const char *key)
{
    for (int i = 0; i < ctx->nstate; i++)
        if (strcmp(ctx->state[i].key, key) == 0)
            return ctx->state[i].data;
    return NULL;
}

int ppb_ctx_keep(ppb_run_ctx *ctx, const char *key, void *data, void (*release)(void *),
                 ppb_err *err)
{
    if (ctx->nstate == PPB_MAX_STATES) {
        if (release)
            release(data);
        return ppb_fail(err, "%s: no slot left for a method's run state", key);
    }
    ppb_method_state *s = &ctx->state[ctx->nstate++];
    snprintf(s->key, sizeof s->key, "%s", key);
    s->data = data;
    s->release = release;
    return 0;
}

const ppb_result *ppb_ctx_prior(const ppb_run_ctx *ctx, const char *id)
{
    for (int i = 0; i < ctx->nprior; i++)
        if (strcmp(ctx->prior[i].method, id) == 0 && !ctx->prior[i].partial)
            return &ctx->prior[i];
    return NULL;
}

/* Part `id` of a sum: this experiment's result when it ran before, else computed into own. */
static const ppb_result *sum_part(ppb_run_ctx *ctx, const ppb_method *m, const char *id,
                                  const ppb_layout *lo, ppb_result *own, ppb_err *err)
{
    const ppb_result *r = ppb_ctx_prior(ctx, id);
    if (r)
        return r;
    const ppb_method *self = ctx->self;
    if (ppb_result_init(own, id, lo, err))
        return NULL;
    ctx->self = m;
    int rc = m->run(ctx, own, err);
    ctx->self = self;
    if (rc) {
        ppb_result_free(own);
        return NULL;
    }
    return own;
}

int ppb_method_sum(ppb_run_ctx *ctx, ppb_result *out,
                   const ppb_method *(*find)(const ppb_config *, const char *), ppb_err *err)
{
    const char *const *parts = ctx->self->sum_of;
    int nparts = 0, reused = 0;
    char label[128] = "cells";
    for (; parts[nparts]; nparts++)
        reused += ppb_ctx_prior(ctx, parts[nparts]) != NULL;
    if (reused == nparts) { /* "cells, mp and ss reused," */
        size_t len = strlen(label);
        for (int i = 0; i < nparts; i++)
            len += (size_t)snprintf(label + len, sizeof label - len, "%s%s", i ? " and " : ", ",
                                    parts[i]);
        snprintf(label + len, sizeof label - len, " reused,");
    }
    ppb_progress pr;
    ppb_progress_begin(&pr, out->method, label, (double)out->layout.ncells, ctx->quiet);
    int rc = 0;
    for (int i = 0; i < nparts && rc == 0; i++) {
        ppb_result own = {0};
        const ppb_method *m = find(ctx->cfg, parts[i]);
        const ppb_result *p = m ? sum_part(ctx, m, parts[i], &out->layout, &own, err) : NULL;
        if (!p) {
            rc = m ? -1 : ppb_fail(err, "%s: no method '%s' to sum", out->method, parts[i]);
            break;
        }
        /* A part keeps its own id's checks (mp checks its totals): the sum checks its own. */
        if (i == 0) {
            memcpy(out->radiance, p->radiance, out->layout.ncells * sizeof *out->radiance);
            out->totals = p->totals;
        } else {
            for (size_t c = 0; c < out->layout.ncells; c++)
                out->radiance[c] += p->radiance[c];
            out->totals.R += p->totals.R;
            out->totals.T += p->totals.T;
            out->totals.sides += p->totals.sides;
        }
        out->partial |= p->partial;
        ppb_result_free(&own);
    }
    if (rc)
        return -1;
    ppb_progress_end(&pr, (double)out->layout.ncells);
    return ppb_totals_check_completed(ctx->cfg->name, out, err);
}
