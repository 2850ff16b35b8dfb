#include "drivers/perf.h"

#include <stdlib.h>
#include <string.h>

#include "drivers/perf_pp.h"
#include "methods/registry.h"

/* Method i's benchmark under its heading; blank line before all but the first section. */
static int perf_method(const ppb_method *m, ppb_run_ctx *ctx, FILE *out, int first, ppb_err *err)
{
    fprintf(out, "%s== %s\n", first ? "" : "\n", m->perf_title);
    return m->perf(ctx, out, err);
}

int ppb_perf_all(ppb_run_ctx *ctx, FILE *out, ppb_err *err)
{
    /* Benchmarks that take a scene start from the study's defaults (uniform g = 0 tube). */
    ppb_config defaults;
    const ppb_config *given = ctx->cfg;
    if (!given) {
        if (ppb_config_defaults(&defaults, err))
            return -1;
        ctx->cfg = &defaults;
    }
    setvbuf(out, NULL, _IOLBF, 0);
    /* The reference method, for benchmarks that put a method's cost beside its. */
    for (int i = 0; i < ppb_method_count(); i++)
        if (ppb_method_at(i)->reference == 1)
            ctx->reference = ppb_method_at(i);
    /* $PPBENCH_PERF_ONLY=ID runs method ID's benchmark alone (paired timing runs of two
     * builds). */
    const char *only = getenv("PPBENCH_PERF_ONLY");
    int rc = 0;
    if (only && *only) {
        const ppb_method *m = ppb_method_find(NULL, only);
        rc = m && m->perf ? perf_method(m, ctx, out, 1, err)
                          : ppb_fail(err,
                                     "$PPBENCH_PERF_ONLY=%s: no method of that id has a "
                                     "benchmark",
                                     only);
        ctx->cfg = given;
        return rc;
    }
    fprintf(out, "== plane-parallel solver (host, LAPACKE)\n");
    rc = ppb_perf_ppsolver(out, err);
    for (int i = 0; rc == 0 && i < ppb_method_count(); i++) {
        const ppb_method *m = ppb_method_at(i);
        if (m->perf)
            rc = perf_method(m, ctx, out, 0, err);
    }
    ctx->cfg = given; /* the defaults live on this stack frame only */
    return rc;
}
