/* method_ppslab.c: the plane-parallel solution evaluated at the slab's faces (reference:
 * Methods; paper Sec. 2.2 through src/physics/ppsolver.h). */
#include "methods/ppslab/method_ppslab.h"

#include <math.h>

#include "kernels/ppb_bin_samples.h"
#include "base/progress.h"
#include "physics/ppsolver.h"

/* Bin average over samples x samples directions, each weighted (ppb_bin_sample_dir: the
 * midpoints in projected solid angle, the first and last theta rows graded toward the normal and
 * the tangent plane; reference: Bins), so the bins match every other method's. */
static double bin_average(const pp_solution *s, const ppb_scene *sc, int surf, int bin, int samples,
                          double tau)
{
    double sum = 0.0;
    for (int a = 0; a < samples; a++)
        for (int b = 0; b < samples; b++) {
            double w[3];
            double wk = ppb_bin_sample_dir(surf, bin, a, b, samples, sc->ntheta, sc->nphi, &w[0],
                                           &w[1], &w[2]);
            /* n > 1: air-side bins, the n^2 law (ppsolver.h); n = 1 as it always was */
            sum += wk * (sc->n > 1.0 ? pp_exit_radiance(s, w) : pp_radiance(s, tau, w));
        }
    return sum / ((double)samples * samples);
}

int ppb_method_ppslab(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    const ppb_scene *sc = &cfg->scene;
    if (sc->geometry != PPB_GEOM_SLAB)
        return ppb_fail(err, "ppslab: needs geometry = slab (it is the slab's own solution)");
    double tau0 = sc->height * sc->sigma_t;
    pp_params p = {tau0, sc->albedo, sc->g, ppb_scene_cos_theta_l(sc), cfg->pp.directions};
    pp_solution *s = NULL;
    if (pp_solve_collars(&p, sc->n, cfg->pp.delta_m, cfg->pp.collars, NULL, &s, NULL, err) != 0)
        return -1;
    int samples = cfg->samples_dir > 0 ? cfg->samples_dir : 1;
    ppb_progress pr; /* the bins take longer than the solve at large directions */
    ppb_progress_begin(&pr, out->method, "bins", out->layout.nbins, ctx->quiet);
    for (int bin = 0; bin < out->layout.nbins; bin++) {
        if (ppb_interrupted()) {
            ppb_progress_end(&pr, bin);
            pp_free(s);
            return ppb_fail(err, "ppslab: interrupted");
        }
        ppb_progress_update(&pr, bin);
        out->radiance[ppb_cell(&out->layout, PPB_S1, 0, bin)] =
            bin_average(s, sc, PPB_S1, bin, samples, 0.0);
        out->radiance[ppb_cell(&out->layout, PPB_S2, 0, bin)] =
            bin_average(s, sc, PPB_S2, bin, samples, tau0);
    }
    ppb_progress_end(&pr, out->layout.nbins);
    ppb_totals *t = &out->totals;
    pp_totals(s, &t->R, &t->T, &t->ballistic);
    double ballistic_top;
    pp_boundary_totals(s, &t->specular, &ballistic_top);
    t->sides = 0.0;
    t->absorbed = pp_absorbed(s);
    t->absorbed_tracked = 1;
    pp_free(s);
    return 0;
}
