/* Config parsing: SPEC.md section 9's keys with their meaning, and every error class reported
 * as file:line: key: reason. Expected values are the literal text of each config. */
#include "testutil.h"

#include "model/config.h"

static const char *write_cfg(const char *name, const char *text)
{
    static char path[1200];
    snprintf(path, sizeof path, "%s/%s.ini", tu_scratch(name), name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

static ppb_config cfg;

static void test_spec_example(void **state)
{
    (void)state;
    const char *p = write_cfg("spec", "[experiment]\nname = uniform_g0_normal\ngeometry = tube\n"
                                      "methods = mc, pp, ss, mp, mp+ss\n"
                                      "[tube]\nwidth = 10\nheight = 3\nsegments_top = 128\n"
                                      "segments_side = 36\n"
                                      "[medium]\nsigma_t = 1\nalbedo = 0.95\ng = 0\n"
                                      "step = density ; a comment\nstep_x = 0\n"
                                      "sigma_t_right = 0.5\nalbedo_right = 0.475\n"
                                      "[light]\ntheta_deg = 45\n[bins]\ntheta = 8\nphi = 8\n"
                                      "[mc]\nphotons = 1e7\nbatches = 16\nseed = 1\n"
                                      "[pp]\ndirections = 334\n[output]\ndir = out/x\n");
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    assert_string_equal(cfg.name, "uniform_g0_normal");
    assert_int_equal(cfg.scene.geometry, PPB_GEOM_TUBE);
    assert_int_equal(cfg.nmethods, 5);
    assert_string_equal(cfg.methods[4], "mp+ss");
    assert_int_equal(cfg.scene.segments_top, 128);
    assert_int_equal(cfg.scene.step, PPB_STEP_DENSITY);
    assert_true(cfg.scene.theta_deg == 45.0);
    assert_true(cfg.mc.photons == 10000000LL); /* "1e7" is an exact integer (SPEC.md 10) */
    assert_int_equal(cfg.pp.directions, 334);
    assert_string_equal(cfg.out_dir, "out/x");
    assert_int_equal(cfg.naxes, 0);
}

static void test_defaults(void **state)
{
    (void)state;
    const char *p = write_cfg("defaults", "[experiment]\n");
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    /* Defaults are SPEC.md section 6's study values. */
    assert_string_equal(cfg.name, "defaults");
    assert_string_equal(cfg.out_dir, "results/defaults");
    assert_true(cfg.scene.width == 10 && cfg.scene.height == 3);
    assert_true(cfg.scene.albedo == 0.95 && cfg.scene.sigma_t == 1);
    assert_int_equal(cfg.scene.ntheta * cfg.scene.nphi, 64);
}

/* Each error class names file, line and key. */
static void expect_error(const char *name, const char *text, const char *needle)
{
    const char *p = write_cfg(name, text);
    ppb_err err = {{0}};
    if (ppb_config_load(&cfg, p, &err) != -1)
        fail_msg("config '%s' was accepted", name);
    if (!strstr(err.msg, needle) || !strstr(err.msg, p))
        fail_msg("error '%s' lacks '%s' or the path", err.msg, needle);
}

static void test_errors(void **state)
{
    (void)state;
    expect_error("unksec", "[experiment]\n\n[nope]\nx = 1\n", ":4: [nope] x: unknown section");
    expect_error("unkkey", "[medium]\nalbdo = 0.9\n", ":2: [medium] albdo: unknown key");
    expect_error("nan", "[medium]\ng = abc\n", ":2: [medium] g: 'abc' is not a number");
    expect_error("range", "[medium]\n\ng = 1.5\n", ":3: [medium] g: 1.5 is out of range");
    expect_error("nonint", "[mc]\nphotons = 1.5e0\n", "[mc] photons: '1.5e0' is not an integer");
    expect_error("twice", "[mc]\nseed = 1\nseed = 2\n", ":3: [mc] seed: given twice");
    expect_error("enum", "[medium]\nstep = sideways\n", "[medium] step: 'sideways' is not one of");
    expect_error("method", "[experiment]\nmethods = mc, xx\n", "unknown method 'xx'");
    expect_error("slabstep", "[experiment]\ngeometry = slab\n[medium]\nstep = shadow\n",
                 ":4: [medium] step: steps are refused in slab mode");
    expect_error("stepx", "[medium]\nstep = density\nstep_x = 7\n", ":3: [medium] step_x:");
    expect_error("ppslab", "[experiment]\nmethods = ppslab\n", "runs in slab mode only");
    expect_error("syntax", "[medium\ng = 0\n", ":1:");
    expect_error("emptylist", "[medium]\ng = 0,,0.5\n", "empty value in list");
    expect_error("badrange", "[medium]\ng = 0:x:0.1\n", "'x' is not a number");
}

static void test_missing_file(void **state)
{
    (void)state;
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, "/nonexistent/x.ini", &err), -1);
    assert_non_null(strstr(err.msg, "/nonexistent/x.ini: cannot open config"));
}

static void test_lists_and_points(void **state)
{
    (void)state;
    const char *p = write_cfg("sweep", "[medium]\ng = 0, 0.5\nalbedo = 0.5:0.9:0.2\n");
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    assert_int_equal(cfg.naxes, 2);
    assert_int_equal(ppb_config_npoints(&cfg), 6); /* 2 values x {0.5, 0.7, 0.9} */
    static ppb_config pt;
    /* Row-major, last axis fastest: point 4 = (g index 1, albedo index 1). */
    assert_int_equal(ppb_config_point(&cfg, 4, &pt, &err), 0);
    assert_true(pt.scene.g == 0.5);
    assert_true(fabs(pt.scene.albedo - 0.7) < 1e-12);
    assert_int_equal(pt.naxes, 0);
    assert_int_equal(ppb_config_point(&cfg, 6, &pt, &err), -1);
}

static void test_set_override(void **state)
{
    (void)state;
    const char *p = write_cfg("set", "[mc]\nphotons = 1e6\n");
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    assert_int_equal(ppb_config_set(&cfg, "mc", "photons", "2e3", &err), 0);
    assert_true(cfg.mc.photons == 2000);
    assert_int_equal(ppb_config_set(&cfg, "mc", "nope", "1", &err), -1);
    assert_non_null(strstr(err.msg, "--set mc.nope: unknown key"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spec_example),     cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_errors),           cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_lists_and_points), cmocka_unit_test(test_set_override),
    };
    return cmocka_run_group_tests_name("config", tests, NULL, NULL);
}
