/* test_rte2d_cells.c: which direction cells rte2d transports (ppb_rte_partition; reference:
 * Methods, `rte2d`, the cells), case by case, against the rule as the reference states it:
 * - at n > 1 a ring edge at the critical cosine sqrt(1 - 1 / n^2); in the tube without the
 *   split beside it, in the slab with it (ppslab's cells, which slab mode reproduces);
 * - graded polar rings from h = 1 - g* at the pole at normal light where 1 - g* is below the
 *   square cell's side sqrt(2 pi / N), g* the retained function's first moment (delta-M's
 *   (g - f) / (1 - f), f = g^sqrt(2N)); none at oblique light or where the peak is resolved.
 * Of the study's cases only realistic_g09_normal_n14 gets the rings (1 - g* = 0.123 against a
 * side of 0.222 at 128 cells). The grids are then built and their partitions checked, and
 * where the default first-moment correction applies (in the tube, g* > 0 on near-square
 * cells: the uniform g = 0.5 cases and realistic_g08_step_oblique_n14; not in the slab). */
#include "testutil.h"
#include "study_cases.h"

#include "methods/rte2d/rte2d_grid.h"
#include "model/config.h"

/* The scaled scene and retained function rte2d solves cfg's case with (method_rte2d.c). */
static pp_phase_fn retained(const ppb_config *cfg, ppb_scene *scaled)
{
    double f = ppb_rte_delta_m(&cfg->scene, cfg->rte2d.directions, 0, scaled);
    (void)f;
    return (pp_phase_fn){scaled->g, 0, {0}};
}

static void test_study_cases(void **state)
{
    (void)state;
    char names[STUDY_MAX_CASES][64];
    int n = study_cases(names), graded = 0;
    for (int c = 0; c < n; c++) {
        ppb_config cfg;
        study_load_config(names[c], &cfg);
        ppb_scene sc;
        pp_phase_fn ph = retained(&cfg, &sc);
        int N = cfg.rte2d.directions;
        pp_dirs_spec spec = ppb_rte_partition(&sc, &ph, N);
        int tube = sc.geometry == PPB_GEOM_TUBE;
        if (sc.n > 1.0) {
            assert_close(spec.mu_snap, sqrt(1.0 - 1.0 / (sc.n * sc.n)), 1e-15);
            assert_int_equal(spec.whole_snap, tube);
        } else {
            assert_true(spec.mu_snap == 0.0);
        }
        int want = sc.theta_deg == 0.0 && sc.g > 0.0 && 1.0 - sc.g < sqrt(2.0 * PPB_PI / N);
        printf("%s: g* %.4f, 1 - g* %.4f against %.4f: %s\n", names[c], sc.g, 1.0 - sc.g,
               sqrt(2.0 * PPB_PI / N), want ? "graded rings" : "near-square cells");
        if (want) {
            assert_close(spec.h_pole, 1.0 - sc.g, 1e-15);
            graded++;
        } else
            assert_true(spec.h_pole == 0.0);
        ppb_rte_grid G;
        ppb_err err;
        if (ppb_rte_grid_make(&sc, 0.5, N, 0.5, 0, &ph, &G, &err))
            fail_msg("%s: %s", names[c], err.msg);
        assert_int_equal(G.dirs.polar, want);
        /* the first-moment correction by default: g* > 0 on the near-square cells */
        assert_int_equal(ppb_rte_moment_applies(PPB_RTE_MOMENT_AUTO, &sc, &G.dirs),
                         sc.g > 0.0 && !want && tube);
        assert_true(G.moment_b == 0.0); /* built with moment off */
        ppb_rte_grid_free(&G);
    }
    assert_int_equal(graded, 1);
}

/* The same medium at oblique light gets no rings, and in slab mode at n > 1 the split stays. */
static void test_oblique_and_slab(void **state)
{
    (void)state;
    ppb_config cfg;
    study_load_config("realistic_g09_normal_n14", &cfg);
    cfg.scene.theta_deg = 30.0;
    ppb_scene sc;
    pp_phase_fn ph = retained(&cfg, &sc);
    pp_dirs_spec spec = ppb_rte_partition(&sc, &ph, cfg.rte2d.directions);
    assert_true(spec.h_pole == 0.0);
    assert_int_equal(spec.whole_snap, 1);
    cfg.scene.theta_deg = 0.0;
    cfg.scene.geometry = PPB_GEOM_SLAB;
    ph = retained(&cfg, &sc);
    spec = ppb_rte_partition(&sc, &ph, cfg.rte2d.directions);
    assert_int_equal(spec.whole_snap, 0);
    assert_true(spec.h_pole > 0.0);
    /* the slab's near-square cells get no first-moment correction by default */
    pp_dirs d;
    ppb_err err;
    if (pp_dirs_make(cfg.rte2d.directions, &d, &err))
        fail_msg("%s", err.msg);
    assert_false(ppb_rte_moment_applies(PPB_RTE_MOMENT_AUTO, &sc, &d));
    sc.geometry = PPB_GEOM_TUBE;
    assert_true(ppb_rte_moment_applies(PPB_RTE_MOMENT_AUTO, &sc, &d));
    pp_dirs_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_study_cases),
        cmocka_unit_test(test_oblique_and_slab),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
