/* Robustness over the keys' whole ranges: every method, tube and slab, on the grid
 * of the issue, albedo {0, 0.01, 0.5, 0.95, 0.999, 1} x g {-0.95, -0.5, 0, 0.5, 0.95} x H
 * {1e-3, 0.1, 1, 100, 1e3} x theta_L {0, 45, 80, 89} (600 points per geometry), at coarse
 * settings (bins, segments, solver directions, albedo nodes, map and march resolution,
 * photons: the numerics of the corners are what is tested, not accuracy). Every point runs in
 * this process through the library (ppb_experiment_compute on a config built in memory), with
 * one OpenCL context and one march-table cache for the whole grid. Asserted at every point:
 *   - no method fails except the documented refusals (README "Known limits": mp and mp+ss at
 *     albedo 1, refused when the config is checked, before any work);
 *   - every radiance and total is finite and no radiance is negative;
 *   - the methods that conserve energy close their balance: mc tracks absorption (capture and
 *     the roulette balance), so R + T + sides + absorbed + ballistic = 1 up to the fixed-point
 *     rounding of its tallies (2^-32 per event, far below 1e-6); ppslab computes absorption
 *     independently from its modes (ppsolver.h), so the same sum is 1 up to the solver's
 *     rounding (1e-6 allows for the 1e3-mfp slabs; the sweep measured 1e-10);
 *   - what the methods say on stderr (lines that begin with the experiment's name) is one of
 *     the counted kinds (a clamp of negative radiance or of mp's diffusion flux, an energy sum
 *     above 1, the Monte Carlo's event cap), nothing else (a failure would say "failed"); lines
 *     of the OpenCL compiler (a kernel built afresh) are only counted. stderr is captured per
 *     point and the counts are printed at the end (where pp, mp and mp+ss clamp), so the suite
 *     prints a few lines instead of hundreds.
 * rte2d is not in the grid: one tube point at H = 1e3 takes 3 s of CPU at spacing 1 and 4
 * directions (a grid of W H / spacing^2 nodes, GMRES to convergence; measured with ppbench run),
 * so the grid would take over an hour; tests/test_rte2d.c covers it. It runs, at spacing 0.5
 * and 16 directions, in the thin, grazing, n > 1 corner (test_robust_corner), with every other
 * tube method. Also here: ss's image-series cost refusal and pp on an albedo step reaching 1. */
#include "testutil.h"

#include "drivers/experiment.h"
#include "methods/registry.h"
#include "methods/work_estimate.h"
#include "physics/march_tables.h"

#include <time.h>

static ppb_run_ctx g_ctx;

static const double k_albedo[] = {0, 0.01, 0.5, 0.95, 0.999, 1};
static const double k_g[] = {-0.95, -0.5, 0, 0.5, 0.95};
static const double k_height[] = {1e-3, 0.1, 1, 100, 1e3};
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
    set(cfg, "pp", "directions", "4");
    set(cfg, "pp", "albedos", "3");
    set(cfg, "pp", "step", "1");
    set(cfg, "pp", "map_res", "1");
    set(cfg, "mp", "pairs", "2");
    set(cfg, "mp", "samples", "1");
    set(cfg, "mc", "photons", "500");
    set(cfg, "mc", "batches", "2");
}

/* What stderr said over the grid, by kind. */
typedef struct said {
    long clamp[PPB_MAX_METHODS]; /* points where a method clamped negative radiance */
    long cells[PPB_MAX_METHODS]; /* cells clamped */
    double low[PPB_MAX_METHODS]; /* most negative value before the clamp */
    char low_at[PPB_MAX_METHODS][160];
    char name[PPB_MAX_METHODS][32];
    int nnames;
    long flux, flux_faces; /* mp's negative diffusion flux clamped (points, faces) */
    double flux_low;
    long excess, cap, other, device;
    char other_line[512];
} said;

static int said_method(said *s, const char *m)
{
    for (int i = 0; i < s->nnames; i++)
        if (strcmp(s->name[i], m) == 0)
            return i;
    if (s->nnames == PPB_MAX_METHODS)
        return PPB_MAX_METHODS - 1;
    snprintf(s->name[s->nnames], sizeof s->name[0], "%s", m);
    return s->nnames++;
}

/* Sorts one captured line of the point `where` into its kind. */
static void said_line(said *s, const char *line, const char *where)
{
    char m[32];
    long n;
    size_t cells;
    double low;
    if (sscanf(line,
               "robust: %31[^:]: warning: %ld of %zu cells had negative radiance (down to %lg)", m,
               &n, &cells, &low) == 4) {
        int i = said_method(s, m);
        s->clamp[i]++;
        s->cells[i] += n;
        if (low < s->low[i]) {
            s->low[i] = low;
            snprintf(s->low_at[i], sizeof s->low_at[i], "%s", where);
        }
    } else if (sscanf(line,
                      "robust: %31[^:]: warning: the diffusion flux was negative at %ld segments "
                      "or faces (down to %lg",
                      m, &n, &low) == 3) {
        s->flux++;
        s->flux_faces += n;
        s->flux_low = fmin(s->flux_low, low);
    } else if (strstr(line, ": warning: R + T + sides + ballistic = "))
        s->excess++;
    else if (strstr(line, "robust: mc: note: ") && strstr(line, "past the event cap"))
        s->cap++;
    else if (strncmp(line, "robust: ", 8) != 0)
        s->device++; /* not ppbench's: the OpenCL compiler's, on a kernel cache miss */
    else {
        if (!s->other++)
            snprintf(s->other_line, sizeof s->other_line, "%.160s: %.300s", where, line);
    }
}

/* stderr goes to a scratch file while a point runs (begin), and what it said is sorted and
 * counted (end). */
static int g_saved = -1;
static FILE *g_capture;

static void capture_begin(void)
{
    fflush(stderr);
    if (!g_capture) {
        g_capture = tmpfile();
        assert_non_null(g_capture);
        g_saved = dup(2);
        assert_true(g_saved >= 0);
    }
    assert_int_equal(ftruncate(fileno(g_capture), 0), 0);
    rewind(g_capture);
    assert_true(dup2(fileno(g_capture), 2) >= 0);
}

static void capture_end(said *s, const char *where)
{
    fflush(stderr);
    dup2(g_saved, 2);
    rewind(g_capture);
    char line[1024];
    while (fgets(line, sizeof line, g_capture))
        said_line(s, line, where);
}

/* One result's checks. */
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
        double sum = t.R + t.T + t.sides + t.absorbed + t.ballistic + t.specular; /* n > 1 */
        if (!(fabs(sum - 1.0) <= BALANCE_TOL))
            fail_msg("%s: %s energy sum %.12g, expected 1 (tol %g)", where, r->method, sum,
                     BALANCE_TOL);
    }
}

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static double wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void run_grid(int slab)
{
    int points = 0, refused = 0;
    said s;
    memset(&s, 0, sizeof s);
    double msec[PPB_MAX_RESULTS] = {0};
    char mname[PPB_MAX_RESULTS][32] = {{0}};
    int nm = 0;
    double w0 = wall_seconds(), c0 = cpu_seconds();
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
                    /* Every method of the registry that runs in this geometry but rte2d (see
                     * the header). */
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
                    capture_begin();
                    rc = ppb_experiment_compute(&ex, &cfg, &g_ctx, &err);
                    capture_end(&s, where);
                    if (rc)
                        fail_msg("%s: %s", where, err.msg);
                    if (ex.nfailed)
                        fail_msg("%s: %s failed: %s", where, ex.failed[0], ex.failed_why[0]);
                    for (int m = 0; m < ex.n; m++) {
                        check_result(&ex.res[m], where);
                        int k = 0;
                        while (k < nm && strcmp(mname[k], ex.res[m].method) != 0)
                            k++;
                        if (k == nm && nm < PPB_MAX_RESULTS)
                            snprintf(mname[nm++], sizeof mname[0], "%s", ex.res[m].method);
                        if (k < nm)
                            msec[k] += ex.seconds[m];
                    }
                    ppb_experiment_free(&ex);
                    points++;
                }
    printf("[ robust   ] %s: %d points, %d refusals (mp, mp+ss at albedo 1), %.1f s wall, "
           "%.1f s CPU\n",
           slab ? "slab" : "tube", points, refused, wall_seconds() - w0, cpu_seconds() - c0);
    printf("[ robust   ] method wall seconds:");
    for (int k = 0; k < nm; k++)
        printf(" %s %.1f", mname[k], msec[k]);
    printf("\n");
    for (int i = 0; i < s.nnames; i++)
        printf("[ robust   ] %s clamped negative radiance at %ld points (%ld cells), down to "
               "%.3g (%s)\n",
               s.name[i], s.clamp[i], s.cells[i], s.low[i], s.low_at[i]);
    printf("[ robust   ] mp clamped a negative diffusion flux at %ld method runs (%ld faces), down "
           "to %.3g\n",
           s.flux, s.flux_faces, s.flux_low);
    printf("[ robust   ] energy sums above 1 reported: %ld; mc event cap reached: %ld points; "
           "device compiler lines: %ld\n",
           s.excess, s.cap, s.device);
    if (s.other)
        fail_msg("%ld unexpected lines on stderr, the first: %s", s.other, s.other_line);
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

/* The thin, grazing, high-index corner, with rte2d at coarse settings (spacing 0.5 mfp, 16
 * directions): H {1e-3, 0.01} x theta_L 89 x n {1.33, 2.5} x albedo {0, 0.95, 1} x g
 * {-0.95, 0.95} (24 points), every tube method (mp and mp+ss but at albedo 1, their documented
 * refusal). Near the critical angle F_b is near 1 (0.90 at 89 deg for both n) and a row of
 * images adds 0.01 mfp of depth: ss's image series ran to the march's d_cap, 3666 rows a leg
 * (hours at the study's bins; see test_image_series_cost). Asserted as in the grid, and that no
 * total (R, T, sides, ballistic) is negative: rte2d wrote sides = -6.3e-13 here (result_check.h
 * now sets a total negative within its round-off to 0). */
static void test_robust_corner(void **state)
{
    (void)state;
    static const double hs[] = {1e-3, 0.01}, ths[] = {89}, ns[] = {1.33, 2.5}, as[] = {0, 0.95, 1},
                        gs[] = {-0.95, 0.95};
    said s;
    memset(&s, 0, sizeof s);
    int points = 0;
    for (int ih = 0; ih < 2; ih++)
        for (int it = 0; it < 1; it++)
            for (int in = 0; in < 2; in++)
                for (int ia = 0; ia < 3; ia++)
                    for (int ig = 0; ig < 2; ig++) {
                        ppb_config cfg;
                        coarse(&cfg, 0);
                        set(&cfg, "rte2d", "spacing", "0.5");
                        set(&cfg, "rte2d", "directions", "16");
                        setf(&cfg, "tube", "height", hs[ih]);
                        setf(&cfg, "light", "theta_deg", ths[it]);
                        setf(&cfg, "medium", "n", ns[in]);
                        setf(&cfg, "medium", "albedo", as[ia]);
                        setf(&cfg, "medium", "g", gs[ig]);
                        set(&cfg, "experiment", "methods",
                            as[ia] < 1 ? "mc, pp, ss, mp, mp+ss, rte2d" : "mc, pp, ss, rte2d");
                        char where[160];
                        snprintf(where, sizeof where, "tube H %g theta_L %g n %g albedo %g g %g",
                                 hs[ih], ths[it], ns[in], as[ia], gs[ig]);
                        ppb_err err;
                        if (ppb_methods_check(&cfg, &err))
                            fail_msg("%s: refused: %s", where, err.msg);
                        ppb_experiment ex;
                        capture_begin();
                        int rc = ppb_experiment_compute(&ex, &cfg, &g_ctx, &err);
                        capture_end(&s, where);
                        if (rc)
                            fail_msg("%s: %s", where, err.msg);
                        if (ex.nfailed)
                            fail_msg("%s: %s failed: %s", where, ex.failed[0], ex.failed_why[0]);
                        for (int m = 0; m < ex.n; m++) {
                            const ppb_result *r = &ex.res[m];
                            check_result(r, where);
                            const ppb_totals *t = &r->totals;
                            if (t->R < 0 || t->T < 0 || t->sides < 0 || t->ballistic < 0)
                                fail_msg("%s: %s: a negative total: R %g T %g sides %g "
                                         "ballistic %g",
                                         where, r->method, t->R, t->T, t->sides, t->ballistic);
                        }
                        ppb_experiment_free(&ex);
                        points++;
                    }
    if (s.other)
        fail_msg("%ld unexpected lines on stderr, the first: %s", s.other, s.other_line);
    assert_int_equal(points, 24);
}

/* An albedo step whose range reaches 1 (0.95 -> 1): pp's albedo nodes then include the
 * conservative slab, whose degenerate pair at lambda = 0 is one mode (m - 1 modes against m);
 * the march tables refused the valid config ("the slab solutions disagree on the mode count").
 * Expected: pp runs and its result passes the grid's checks. */
static void test_albedo_step_to_one(void **state)
{
    (void)state;
    ppb_config cfg;
    coarse(&cfg, 0);
    set(&cfg, "experiment", "methods", "pp");
    set(&cfg, "medium", "step", "albedo");
    set(&cfg, "medium", "albedo", "0.95");
    set(&cfg, "medium", "albedo_right", "1");
    ppb_err err;
    assert_int_equal(ppb_methods_check(&cfg, &err), 0);
    ppb_experiment ex;
    said s;
    memset(&s, 0, sizeof s);
    capture_begin();
    int rc = ppb_experiment_compute(&ex, &cfg, &g_ctx, &err);
    capture_end(&s, "albedo step 0.95 -> 1");
    if (rc)
        fail_msg("%s", err.msg);
    if (ex.nfailed)
        fail_msg("%s failed: %s", ex.failed[0], ex.failed_why[0]);
    assert_int_equal(ex.n, 1);
    check_result(&ex.res[0], "albedo step 0.95 -> 1");
    ppb_experiment_free(&ex);
}

/* The work lines say what pp's tables cost (methods/work_estimate.h): an albedo step at n = 1.5
 * and 45 deg builds pp.albedos = 9 slab solutions (one for one albedo) and 4 direction variants
 * (the tube at n > 1) of the 4096 table directions of the default bins (4 surfaces x 64 bins x
 * 4^2 samples: 16384 in all); one albedo at n = 1 builds one solution of 4096. The line was not
 * printed: a run that took 17 minutes said only its march steps. */
static void test_pp_table_work(void **state)
{
    (void)state;
    ppb_config cfg;
    ppb_err err;
    assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
    snprintf(cfg.name, sizeof cfg.name, "w");
    set(&cfg, "experiment", "methods", "pp");
    set(&cfg, "medium", "step", "albedo");
    set(&cfg, "medium", "albedo_right", "0.475");
    set(&cfg, "medium", "n", "1.5");
    set(&cfg, "light", "theta_deg", "45");
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    ppb_work_print(f, &cfg);
    fclose(f);
    if (!strstr(text, "w: pp: work: tables: 9 slab solves of 334 directions, 1.64e+04 table "
                      "directions"))
        fail_msg("work lines:\n%s", text);
    free(text);
    set(&cfg, "medium", "step", "none");
    set(&cfg, "medium", "n", "1");
    double solves, ndir;
    ppb_march_tables_work(&cfg.scene, &cfg.pp, cfg.samples_dir, 64, &solves, &ndir);
    if (!(solves == 1.0 && ndir == 4096.0))
        fail_msg("uniform n = 1: %g solves, %g directions", solves, ndir);
}

/* ss's image series is refused before any work when its estimated terms exceed
 * PPB_WORK_IMAGE_TERMS_MAX (method_ss.h): the study's bins on a 0.01-mfp tube at 89 deg and
 * n = 2.5 need up to 7.6e12 terms (1.34e6 rays x 4000 legs x 353 rows x 4 tiles, from the
 * formulas of method_ss.h); ss ran there for over 5 minutes, deaf to SIGTERM. pp, which does
 * not sum the images, is not refused; nor is the study's oblique n = 1.4 case (6e8 terms). */
static void test_image_series_cost(void **state)
{
    (void)state;
    ppb_config cfg;
    ppb_err err;
    assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
    set(&cfg, "experiment", "methods", "ss");
    set(&cfg, "tube", "height", "0.01");
    set(&cfg, "light", "theta_deg", "89");
    set(&cfg, "medium", "n", "2.5");
    set(&cfg, "medium", "g", "-0.95");
    set(&cfg, "medium", "albedo", "0");
    assert_int_equal(ppb_methods_check(&cfg, &err), -1);
    if (!strstr(err.msg, "ss: the beam's images need up to 7.59e+12 terms"))
        fail_msg("unexpected: %s", err.msg);
    set(&cfg, "experiment", "methods", "pp");
    assert_int_equal(ppb_methods_check(&cfg, &err), 0);
    assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
    set(&cfg, "experiment", "methods", "ss");
    set(&cfg, "light", "theta_deg", "45");
    set(&cfg, "medium", "n", "1.4");
    assert_int_equal(ppb_methods_check(&cfg, &err), 0);
}

/* The experiment's result arrays are checked against [run] memory_limit before any is allocated
 *: mp alone on the coarse tube holds one result of ncells radiances and standard
 * errors, 16 ncells bytes (expected value from the layout); a limit 1 % below that refuses the
 * run with the estimate in the message, one 1 % above lets it run. */
static void test_result_memory_checked(void **state)
{
    (void)state;
    ppb_config cfg;
    coarse(&cfg, 0);
    set(&cfg, "experiment", "methods", "mp");
    double bytes = 16.0 * (double)ppb_scene_layout(&cfg.scene).ncells;
    setf(&cfg, "run", "memory_limit", 0.99 * bytes / 1e9);
    ppb_experiment ex;
    ppb_err err;
    assert_int_not_equal(ppb_experiment_compute(&ex, &cfg, &g_ctx, &err), 0);
    if (!strstr(err.msg, "the experiment needs about") || !strstr(err.msg, "memory_limit"))
        fail_msg("unexpected refusal: %s", err.msg);
    assert_int_equal(ex.n, 0);
    setf(&cfg, "run", "memory_limit", 1.01 * bytes / 1e9);
    if (ppb_experiment_compute(&ex, &cfg, &g_ctx, &err))
        fail_msg("refused at a limit above the estimate: %s", err.msg);
    assert_int_equal(ex.n, 1);
    ppb_experiment_free(&ex);
}

int main(void)
{
    g_ctx.quiet = 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_robust_tube),           cmocka_unit_test(test_robust_slab),
        cmocka_unit_test(test_result_memory_checked), cmocka_unit_test(test_image_series_cost),
        cmocka_unit_test(test_albedo_step_to_one),    cmocka_unit_test(test_pp_table_work),
        cmocka_unit_test(test_robust_corner),
    };
    if (getenv("PPB_TEST_FILTER")) /* one test by name, e.g. when checking a fix */
        cmocka_set_test_filter(getenv("PPB_TEST_FILTER"));
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    long hits = 0, builds = 0;
    const ppb_march_cache *kept = ppb_ctx_state(&g_ctx, "pp.march_tables");
    if (kept)
        ppb_march_cache_stats(kept, &hits, &builds);
    printf("[ robust   ] march tables: %ld built, %ld reused\n", builds, hits);
    ppb_ctx_close(&g_ctx);
    return rc;
}
