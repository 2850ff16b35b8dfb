/* perf_rte2d.c: the rte2d benchmark (perf_rte2d.h). */
#include "methods/rte2d/perf_rte2d.h"

#include "methods/rte2d/method_rte2d.h"

int ppb_perf_rte2d(ppb_run_ctx *ctx, FILE *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    ppb_result r;
    if (ppb_result_init(&r, "rte2d", &lo, err))
        return -1;
    /* Timed as a study case runs it: the solve, its exit march and the refinement study. */
    int quiet = ctx->quiet, extras = ctx->extras;
    ctx->quiet = 1;
    ctx->extras = 1;
    ppb_rte2d_stats st;
    int rc = ppb_rte2d_run(ctx, &r, &st, err);
    ctx->quiet = quiet;
    ctx->extras = extras;
    const ppb_rte2d_study *study = r.extra.data;
    if (rc == 0)
        fprintf(out,
                "rte2d %s: %d nodes x %d cells, spacing %g, %d directions/hemisphere: %.2f s per "
                "case, %d refinements at %.3f s each (%.2f s), exit march %.2f s, residual %.2g; "
                "refinement study to K = %d: %d sweeps, %.2f s\n",
                cfg->name[0] ? cfg->name : "uniform_g0_normal", st.nodes, st.cells,
                cfg->rte2d.spacing, cfg->rte2d.directions, st.t_total, st.sweeps,
                st.sweeps ? st.t_sweeps / st.sweeps : 0.0, st.t_sweeps, st.t_exit, st.resid,
                st.record_rungs && study ? study->K[st.record_rungs - 1] : 0, st.record_sweeps,
                st.t_record);
    ppb_result_free(&r);
    return rc;
}
