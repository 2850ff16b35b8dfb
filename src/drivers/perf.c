#include "drivers/perf.h"

#include <stdlib.h>
#include <string.h>

#include "drivers/perf_march.h"
#include "drivers/perf_mc.h"
#include "drivers/perf_pp.h"
#include "drivers/perf_rte2d.h"

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
    /* $PPBENCH_PERF_ONLY=mc runs the Monte Carlo alone (paired timing runs of two builds),
     * =rte2d rte2d alone. */
    const char *only = getenv("PPBENCH_PERF_ONLY");
    if (only && strcmp(only, "mc") == 0) {
        fprintf(out, "== Monte Carlo (OpenCL)\n");
        int rc = ppb_perf_mc(ctx, out, err);
        ctx->cfg = given;
        return rc;
    }
    if (only && strcmp(only, "rte2d") == 0) { /* rte2d alone, likewise */
        fprintf(out, "== rte2d: the refinement iterated (OpenCL marches)\n");
        int rc = ppb_perf_rte2d(ctx, out, err);
        ctx->cfg = given;
        return rc;
    }
    fprintf(out, "== plane-parallel solver (host, LAPACKE)\n");
    int rc = ppb_perf_ppsolver(out, err);
    if (rc == 0) {
        fprintf(out, "\n== ray marcher (OpenCL)\n");
        rc = ppb_perf_march(ctx, out, err);
    }
    if (rc == 0) {
        fprintf(out, "\n== Monte Carlo (OpenCL)\n");
        rc = ppb_perf_mc(ctx, out, err);
    }
    if (rc == 0) {
        fprintf(out, "\n== rte2d: the refinement iterated (OpenCL marches)\n");
        rc = ppb_perf_rte2d(ctx, out, err);
    }
    ctx->cfg = given; /* the defaults live on this stack frame only */
    return rc;
}
