/* perf_pp.c: benchmark of the plane-parallel solver (perf_pp.h). */
#include "drivers/perf_pp.h"

#include "kernels/ppb_conventions.h"

#include <cblas.h>
#include <math.h>

#include "base/clock.h"
#include "kernels/ppb_sort.h"
#include "physics/ppsolver.h"

#define PERF_RUNS 7

static double median(double *v, int n)
{
    ppb_sort_doubles(v, n);
    return v[n / 2];
}

/* Median stage times of PERF_RUNS solves of the study's slab (tau0 = 3, alpha = 0.95,
 * g = 0.5, theta_L = 45 deg) and of one pp_radiance call. */
static int bench_one(FILE *out, int directions, ppb_err *err)
{
    double phase[PERF_RUNS], eigen[PERF_RUNS], bound[PERF_RUNS], total[PERF_RUNS];
    double eval[PERF_RUNS];
    pp_params p = {3.0, 0.95, 0.5, cos(45.0 * PPB_PI / 180.0), directions};
    for (int r = 0; r < PERF_RUNS; r++) {
        pp_solution *s;
        pp_timing t;
        if (pp_solve_ex(&p, NULL, &s, &t, err) != 0)
            return -1;
        phase[r] = t.phase, eigen[r] = t.eigen, bound[r] = t.boundary;
        total[r] = t.phase + t.eigen + t.boundary;
        double w[3] = {0.3, 0.9, 0.1}, norm = sqrt(0.91), t0 = ppb_now(), sink = 0.0;
        for (int k = 0; k < 3; k++)
            w[k] /= norm;
        for (int k = 0; k < 20; k++)
            sink += pp_radiance(s, 0.0, w);
        eval[r] = (ppb_now() - t0) / 20 + 0.0 * sink;
        pp_free(s);
    }
    fprintf(out,
            "ppsolver M=%-4d phase %7.2f ms  decomposition %7.2f ms  boundary %6.2f ms  "
            "full solve %7.2f ms (%.2f ms without phase)  per direction %6.3f ms\n",
            2 * directions, 1e3 * median(phase, PERF_RUNS), 1e3 * median(eigen, PERF_RUNS),
            1e3 * median(bound, PERF_RUNS), 1e3 * median(total, PERF_RUNS),
            1e3 * (median(eigen, PERF_RUNS) + median(bound, PERF_RUNS)),
            1e3 * median(eval, PERF_RUNS));
    return 0;
}

int ppb_perf_ppsolver(FILE *out, ppb_err *err)
{
    openblas_set_num_threads(1); /* one core, as the issue asks */
    fprintf(out,
            "ppsolver: tau0 3, albedo 0.95, g 0.5, theta_L 45 deg; one thread; median "
            "of %d\n",
            PERF_RUNS);
    return (bench_one(out, 334, err) != 0 || bench_one(out, 64, err) != 0) ? -1 : 0;
}
