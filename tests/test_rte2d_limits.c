/* test_rte2d_limits.c: rte2d's size bounds (reference: Methods, `rte2d`, Refused): a grid whose
 * arrays exceed [run] memory_limit is refused by the method's check (ppb_methods_check, which
 * the runner calls before any work: exit 2) naming the keys that size it and what fits; one
 * whose largest buffer exceeds a device's CL_DEVICE_MAX_MEM_ALLOC_SIZE is refused by the device
 * check; the study's configs are refused by neither. The node count the estimate uses is the
 * grid's own (ppb_rte_grid_make). */
#include "testutil.h"
#include "study_cases.h"

#include <string.h>

#include "methods/registry.h"
#include "methods/rte2d/method_rte2d.h"
#include "methods/rte2d/rte2d_grid.h"
#include "model/config.h"

/* configs/searchlight_strip.ini (a 40 x 20 mfp tube) with rte2d and the given --set values. */
static void load_strip(const char *const *sets, int nsets, ppb_config *cfg)
{
    const char *all[8] = {"experiment.methods=rte2d"};
    for (int i = 0; i < nsets; i++)
        all[1 + i] = sets[i];
    ppb_err err;
    if (ppb_config_load_sets(cfg, NULL, PPB_SOURCE_DIR "/configs/searchlight_strip.ini", all,
                             1 + nsets, &err))
        fail_msg("%s", err.msg);
}

static void assert_has(const char *msg, const char *want)
{
    if (!strstr(msg, want))
        fail_msg("'%s' not in: %s", want, msg);
}

/* The estimate's node count is the grid's: ppb_rte_nodes against ppb_rte_grid_make's nnodes,
 * on a tube without a step, one split at its step, n > 1 and the slab. */
static void test_nodes_exact(void **state)
{
    (void)state;
    const char *names[] = {"uniform_g0_normal", "density_step", "uniform_g0_normal_n14", "slab_g0"};
    for (int c = 0; c < 4; c++) {
        ppb_config cfg;
        study_load_config(names[c], &cfg);
        ppb_rte_grid G;
        ppb_err err;
        const ppb_rte2d_settings *r = &cfg.rte2d;
        if (ppb_rte_grid_make(&cfg.scene, r->spacing, r->directions, r->step, r->moment, NULL, &G,
                              &err))
            fail_msg("%s: %s", names[c], err.msg);
        assert_int_equal((int)ppb_rte_nodes(&cfg.scene, r->spacing), G.nnodes);
        ppb_rte_grid_free(&G);
    }
}

/* The host bound: at memory_limit = 4 GB the 40 x 20 tube is refused through the registry's
 * check (the runner's exit 2), naming the key where it was set, the keys to change, and the
 * exit source's planes: 4 surfaces x 8 x 8 bins x 4^2 samples = 4096 (reference: Bins). The
 * suggested samples_dir = 1 is accepted, 2 is not (the suggestion is the nearest that fits). */
static void test_host_refused(void **state)
{
    (void)state;
    ppb_config cfg;
    ppb_err err;
    const char *sets[] = {"run.memory_limit=4", NULL};
    load_strip(sets, 1, &cfg);
    assert_int_equal(ppb_methods_check(&cfg, &err), -1);
    assert_has(err.msg, "[rte2d] spacing");
    assert_has(err.msg, "memory_limit");
    assert_has(err.msg, "4096 direction samples");
    assert_has(err.msg, "bins.samples_dir");
    assert_has(err.msg, "rte2d.directions");
    assert_has(err.msg, "rte2d.spacing");
    assert_has(err.msg, "bins.samples_dir = 1 fits");
    sets[1] = "bins.samples_dir=2";
    load_strip(sets, 2, &cfg);
    assert_int_equal(ppb_methods_check(&cfg, &err), -1);
    sets[1] = "bins.samples_dir=1";
    load_strip(sets, 2, &cfg);
    if (ppb_methods_check(&cfg, &err))
        fail_msg("samples_dir = 1 refused: %s", err.msg);
}

/* The device bound at 2 GiB, PoCL's CL_DEVICE_MAX_MEM_ALLOC_SIZE on the machine where the 40 x 20
 * tube failed mid-run (configs/searchlight_strip.ini's note: 2.7 GB). The exit source by hand:
 * nodes = 401 columns (40 / 0.1 cells) x 208 rows (reference: Methods, `rte2d`: rows under S1
 * and over S2 from spacing / 16 doubling to spacing / 2, 4 levels each, depth 15/16 spacing;
 * the middle ceil((20 - 2 x 0.09375) / 0.1) = 199 cells; 2 x 4 + 199 + 1 rows), times 4096
 * planes, times 8 bytes = 2.733 GB. samples_dir = 3 (2304 planes, 1.537 GB) fits. */
static void test_device_refused(void **state)
{
    (void)state;
    ppb_config cfg;
    ppb_err err;
    load_strip(NULL, 0, &cfg);
    assert_int_equal((int)ppb_rte_nodes(&cfg.scene, cfg.rte2d.spacing), 401 * 208);
    assert_int_equal(ppb_rte2d_device_check(&cfg, 2147483648.0, "dev", &err), -1);
    assert_has(err.msg, "2.73 GB");
    assert_has(err.msg, "CL_DEVICE_MAX_MEM_ALLOC_SIZE");
    assert_has(err.msg, "bins.samples_dir = 3 fits");
    assert_has(err.msg, "rte2d.spacing");
    const char *sets[] = {"bins.samples_dir=3"};
    load_strip(sets, 1, &cfg);
    if (ppb_rte2d_device_check(&cfg, 2147483648.0, "dev", &err))
        fail_msg("samples_dir = 3 refused: %s", err.msg);
}

/* The study's configs are refused by neither bound on a modest machine: memory_limit = 2 GB
 * (half of 4 GB) and 1 GiB at once, the least CL_DEVICE_MAX_MEM_ALLOC_SIZE OpenCL 3.0 allows a
 * device of at least 4 GiB (min(1 GiB, a quarter of its memory)). */
static void test_study_not_refused(void **state)
{
    (void)state;
    char names[STUDY_MAX_CASES][64];
    int ncase = study_cases(names);
    for (int c = 0; c < ncase; c++) {
        ppb_config cfg;
        ppb_err err;
        study_load_config(names[c], &cfg);
        cfg.memory_limit = 2.0;
        if (ppb_rte2d_check(&cfg, &err) || ppb_rte2d_device_check(&cfg, 1073741824.0, "dev", &err))
            fail_msg("%s refused: %s", names[c], err.msg);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nodes_exact),
        cmocka_unit_test(test_host_refused),
        cmocka_unit_test(test_device_refused),
        cmocka_unit_test(test_study_not_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
