#include "drivers/perf.h"

#include "drivers/perf_march.h"
#include "drivers/perf_mc.h"
#include "drivers/perf_pp.h"

int ppb_perf_all(ppb_run_ctx *ctx, FILE *out, ppb_err *err)
{
    /* Benchmarks that take a scene start from the study's defaults (uniform g = 0 tube). */
    static ppb_config defaults;
    if (!ctx->cfg) {
        if (ppb_config_defaults(&defaults, err))
            return -1;
        ctx->cfg = &defaults;
    }
    setvbuf(out, NULL, _IOLBF, 0);
    fprintf(out, "== plane-parallel solver (host, LAPACKE)\n");
    if (ppb_perf_ppsolver(out, err))
        return -1;
    fprintf(out, "\n== ray marcher (OpenCL)\n");
    if (ppb_perf_march(ctx, out, err))
        return -1;
    fprintf(out, "\n== Monte Carlo (OpenCL)\n");
    return ppb_perf_mc(ctx, out, err);
}
