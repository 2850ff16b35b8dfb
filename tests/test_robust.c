/* Robustness over the keys' whole ranges (issue 15): every method, tube and slab, on the grid
 * albedo {0, 0.01, 0.5, 0.95, 0.999, 1} x g {-0.95, 0, 0.95} x H {1e-3, 1, 1e3} x theta_L
 * {0, 45, 80, 89} at coarse settings (bins, segments, solver directions, map and march
 * resolution, photons: the numerics of the corners are what is tested, not accuracy). Asserted
 * at every point:
 *   - no method fails except the documented refusals (README "Known limits": mp and mp+ss at
 *     albedo 1, refused when the config is checked, before any work);
 *   - every radiance and total is finite and no radiance is negative;
 *   - the methods that conserve energy close their balance: mc tracks absorption (capture and
 *     the roulette balance), so R + T + sides + absorbed + ballistic = 1 up to the fixed-point
 *     rounding of its tallies (2^-32 per event, far below 1e-6); ppslab computes absorption
 *     independently from its modes (ppsolver.h), so the same sum is 1 up to the solver's
 *     rounding (1e-6 allows for the 1e3-mfp slabs; the sweep measured 1e-10).
 * The study's own settings are never used here, so the run takes about a minute. */
#include "testutil.h"

#include "drivers/experiment.h"
#include "methods/registry.h"

static ppb_run_ctx g_ctx;

static const double k_albedo[] = {0, 0.01, 0.5, 0.95, 0.999, 1};
static const double k_g[] = {-0.95, 0, 0.95};
static const double k_height[] = {1e-3, 1, 1e3};
static const double k_theta[] = {0, 45, 80, 89};
#define N_OF(a) ((int)(sizeof(a) / sizeof((a)[0])))

/* Conservation tolerance of mc and ppslab (see the header). */
#define BALANCE_TOL 1e-6

static void set(ppb_config *cfg, const char *sec, const char *key, const char *val)
{
    ppb_err err;
    if (ppb_config_set(cfg, sec, key, val, &err))
        fail_msg("set %s.%s = %s: %s", sec, key, val, err.msg);
}

static void setf(ppb_config *cfg, const char *sec, const char *key, double v)
{
    char buf[64];
    snprintf(buf, sizeof buf, "%.17g", v);
    set(cfg, sec, key, buf);
}

/* The coarse settings every point shares. */
static void coarse(ppb_config *cfg, int slab)
{
    ppb_err err;
    if (ppb_config_defaults(cfg, &err))
        fail_msg("%s", err.msg);
    snprintf(cfg->name, sizeof cfg->name, "robust");
    set(cfg, "experiment", "geometry", slab ? "slab" : "tube");
    set(cfg, "tube", "segments_top", "4");
    set(cfg, "tube", "segments_side", "2");
    set(cfg, "bins", "theta", "2");
    set(cfg, "bins", "phi", "2");
    set(cfg, "bins", "samples_dir", "1");
    set(cfg, "bins", "samples_seg", "1");
    set(cfg, "pp", "directions", "16");
    set(cfg, "pp", "step", "1");
    set(cfg, "pp", "map_res", "2");
    set(cfg, "mp", "pairs", "2");
    set(cfg, "mp", "samples", "1");
    set(cfg, "mc", "photons", "2000");
    set(cfg, "mc", "batches", "2");
}

/* One result's checks; returns the number of cells checked. */
static void check_result(const ppb_result *r, const char *where)
{
    for (size_t c = 0; c < r->layout.ncells; c++)
        if (!isfinite(r->radiance[c]) || r->radiance[c] < 0.0)
            fail_msg("%s: %s radiance[%zu] = %g", where, r->method, c, r->radiance[c]);
    ppb_totals t = r->totals;
    ppb_totals_complete(&t);
    double v[5] = {t.R, t.T, t.sides, t.absorbed, t.ballistic};
    for (int i = 0; i < 5; i++)
        if (!isfinite(v[i]))
            fail_msg("%s: %s total %d = %g", where, r->method, i, v[i]);
    if (strcmp(r->method, "mc") == 0 || strcmp(r->method, "ppslab") == 0) {
        if (!r->totals.absorbed_tracked)
            fail_msg("%s: %s does not track absorption", where, r->method);
        double sum = t.R + t.T + t.sides + t.absorbed + t.ballistic;
        if (!(fabs(sum - 1.0) <= BALANCE_TOL))
            fail_msg("%s: %s energy sum %.12g, expected 1 (tol %g)", where, r->method, sum,
                     BALANCE_TOL);
    }
}

static void run_grid(int slab)
{
    int points = 0, refused = 0;
    for (int ia = 0; ia < N_OF(k_albedo); ia++)
        for (int ig = 0; ig < N_OF(k_g); ig++)
            for (int ih = 0; ih < N_OF(k_height); ih++)
                for (int it = 0; it < N_OF(k_theta); it++) {
                    ppb_config cfg;
                    coarse(&cfg, slab);
                    setf(&cfg, "medium", "albedo", k_albedo[ia]);
                    setf(&cfg, "medium", "g", k_g[ig]);
                    setf(&cfg, "tube", "height", k_height[ih]);
                    setf(&cfg, "light", "theta_deg", k_theta[it]);
                    char where[160];
                    snprintf(where, sizeof where, "%s albedo %g g %g H %g theta_L %g",
                             slab ? "slab" : "tube", k_albedo[ia], k_g[ig], k_height[ih],
                             k_theta[it]);
                    /* Every method of the registry that runs in this geometry. */
                    set(&cfg, "experiment", "methods",
                        slab ? "mc, pp, ss, mp, mp+ss, ppslab" : "mc, pp, ss, mp, mp+ss");
                    ppb_err err;
                    int rc = ppb_methods_check(&cfg, &err);
                    if (k_albedo[ia] >= 1.0) {
                        /* The documented refusal, up front. */
                        if (rc == 0 || !strstr(err.msg, "albedo = 1"))
                            fail_msg("%s: mp at albedo 1 not refused up front (%s)", where,
                                     rc ? err.msg : "accepted");
                        refused++;
                        set(&cfg, "experiment", "methods",
                            slab ? "mc, pp, ss, ppslab" : "mc, pp, ss");
                        rc = ppb_methods_check(&cfg, &err);
                    }
                    if (rc)
                        fail_msg("%s: refused: %s", where, err.msg);
                    ppb_experiment ex;
                    if (ppb_experiment_compute(&ex, &cfg, &g_ctx, &err))
                        fail_msg("%s: %s", where, err.msg);
                    if (ex.nfailed)
                        fail_msg("%s: %s failed: %s", where, ex.failed[0], ex.failed_why[0]);
                    for (int m = 0; m < ex.n; m++)
                        check_result(&ex.res[m], where);
                    ppb_experiment_free(&ex);
                    points++;
                }
    assert_int_equal(points, N_OF(k_albedo) * N_OF(k_g) * N_OF(k_height) * N_OF(k_theta));
    assert_int_equal(refused, N_OF(k_g) * N_OF(k_height) * N_OF(k_theta));
}

static void test_robust_tube(void **state)
{
    (void)state;
    run_grid(0);
}

static void test_robust_slab(void **state)
{
    (void)state;
    run_grid(1);
}

int main(void)
{
    g_ctx.quiet = 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_robust_tube),
        cmocka_unit_test(test_robust_slab),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    ppb_ctx_close(&g_ctx);
    return rc;
}
