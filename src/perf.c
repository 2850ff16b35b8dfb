#include "perf.h"

#include "perf_march.h"
#include "perf_mc.h"
#include "perf_pp.h"

int ppb_perf_all(ppb_run_ctx *ctx, FILE *out, ppb_err *err)
{
    fprintf(out, "== plane-parallel solver (host, LAPACKE)\n");
    if (ppb_perf_ppsolver(out, err))
        return -1;
    fprintf(out, "\n== ray marcher (OpenCL)\n");
    if (ppb_perf_march(ctx, out, err))
        return -1;
    fprintf(out, "\n== Monte Carlo (OpenCL)\n");
    return ppb_perf_mc(ctx, out, err);
}
