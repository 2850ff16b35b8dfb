/* Config parsing: the keys of the reference's Keys section with their meaning, and every error
 * class reported as file:line: key: reason; the sweep grid a config's lists make; the method-id
 * checks of the registry on a loaded config. Expected values are the literal text of each config
 * (its lines, its keys' values) and the C enum values each documented name stands for. */
#include "testutil.h"

#include "kernels/march_params.h"
#include "methods/registry.h"
#include "model/config.h"
#include "model/grid.h"

static ppb_config cfg;

static void test_spec_example(void **state)
{
    (void)state;
    const char *p = tu_config("spec", "[experiment]\nname = uniform_g0_normal\ngeometry = tube\n"
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
    /* "1e7" is an exact integer (reference: Corrections) */
    assert_true(cfg.mc.photons == 10000000LL);
    assert_int_equal(cfg.pp.directions, 334);
    assert_string_equal(cfg.out_dir, "out/x");
    /* Where each key stood in the file; 0 for a key left at its default. */
    char where[1400];
    ppb_config_key_fail(&cfg, "medium", "g", &err, "x");
    snprintf(where, sizeof where, "%s:13: [medium] g: x", p);
    assert_string_equal(err.msg, where);
    ppb_config_key_fail(&cfg, "pp", "step", &err, "x");
    snprintf(where, sizeof where, "%s:0: [pp] step: x", p);
    assert_string_equal(err.msg, where);
}

static void test_defaults(void **state)
{
    (void)state;
    const char *p = tu_config("defaults", "[experiment]\n");
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    /* Defaults are the study values (reference: Cases). */
    assert_string_equal(cfg.name, "defaults");
    assert_string_equal(cfg.out_dir, "results/defaults");
    assert_true(cfg.scene.width == 10 && cfg.scene.height == 3);
    assert_true(cfg.scene.albedo == 0.95 && cfg.scene.sigma_t == 1);
    assert_int_equal(cfg.scene.ntheta * cfg.scene.nphi, 64);
}

/* Each error class names file, line and key. */
static void expect_error(const char *name, const char *text, const char *needle)
{
    const char *p = tu_config(name, text);
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
    /* A retired key says what replaced it (docs/reference.md, Keys). */
    expect_error("retired", "[rte2d]\ngraded_bins = on\n",
                 ":2: [rte2d] graded_bins: retired key: every deterministic method grades");
    expect_error("nan", "[medium]\ng = abc\n", ":2: [medium] g: 'abc' is not a number");
    expect_error("range", "[medium]\n\ng = 1.5\n", ":3: [medium] g: 1.5 is out of range");
    expect_error("nonint", "[mc]\nphotons = 1.5e0\n", "[mc] photons: '1.5e0' is not an integer");
    expect_error("twice", "[mc]\nseed = 1\nseed = 2\n", ":3: [mc] seed: given twice");
    expect_error("enum", "[medium]\nstep = sideways\n", "[medium] step: 'sideways' is not one of");
    expect_error("twicemethod", "[experiment]\nmethods = mc, mc\n",
                 ":2: [experiment] methods: method 'mc' listed twice");
    expect_error("slabstep", "[experiment]\ngeometry = slab\n[medium]\nstep = shadow\n",
                 ":4: [medium] step: steps are refused in slab mode");
    expect_error("stepx", "[medium]\nstep = density\nstep_x = 7\n", ":3: [medium] step_x:");
    expect_error("syntax", "[medium\ng = 0\n", ":1:");
    /* inih reads on after an error: the first one is reported, with its own key. */
    expect_error("first", "[medium]\ng = 5\n[tube]\nwidth = 5\n",
                 ":2: [medium] g: 5 is out of range");
    expect_error("syntaxfirst", "[medium\n[tube]\nwidth = -1\n", ":1: syntax error");
    /* A list where no grid is given (ppb_config_load): not a sweep. */
    expect_error("nogrid", "[medium]\n\ng = 0, 0.5\n",
                 ":3: [medium] g: a list (a sweep) is not accepted here");
    expect_error("emptylist", "[medium]\ng = 0,,0.5\n", "empty value in list");
    expect_error("badrange", "[medium]\ng = 0:x:0.1\n", "'x' is not a number");
}

/* The config takes any id; the registry refuses unknown ones and slab-only methods in tube
 * mode, naming where the list was set, in the words the config used to refuse them in. */
static void expect_method_error(const char *name, const char *text, const char *why)
{
    const char *p = tu_config(name, text);
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    assert_int_equal(ppb_methods_check(&cfg, &err), -1);
    char want[1400];
    snprintf(want, sizeof want, "%s:%s", p, why);
    assert_string_equal(err.msg, want);
}

static void test_method_checks(void **state)
{
    (void)state;
    expect_method_error("method", "[experiment]\nmethods = mc, xx\n",
                        "2: [experiment] methods: unknown method 'xx' (see ppbench --help)");
    expect_method_error("ppslab", "[experiment]\nname = a\n\nmethods = mc, ppslab\n",
                        "4: [experiment] methods: method 'ppslab' runs in slab mode only");
    /* Unknown ids are refused before slab-only ones, wherever they stand in the list. */
    expect_method_error("both", "[experiment]\nmethods = ppslab, xx\n",
                        "2: [experiment] methods: unknown method 'xx' (see ppbench --help)");
    ppb_err err = {{0}};
    const char *p = tu_config("methodsok", "[experiment]\ngeometry = slab\nmethods = ppslab, mc\n");
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    assert_int_equal(ppb_methods_check(&cfg, &err), 0);
    /* The study's default list is every tube method. */
    assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
    assert_int_equal(ppb_methods_check(&cfg, &err), 0);
    /* A list given by --set is named as such. */
    assert_int_equal(ppb_config_set(&cfg, "experiment", "methods", "mc, zz", &err), 0);
    assert_int_equal(ppb_methods_check(&cfg, &err), -1);
    assert_string_equal(err.msg,
                        "--set experiment.methods: unknown method 'zz' (see ppbench --help)");
    assert_int_equal(ppb_config_set(&cfg, "experiment", "methods", "ppslab", &err), 0);
    assert_int_equal(ppb_methods_check(&cfg, &err), -1);
    assert_string_equal(err.msg,
                        "--set experiment.methods: method 'ppslab' runs in slab mode only");
}

/* Each enum key's documented names parse to the C enum value they are paired with (whatever
 * the enum's order) and print back as the same name; names are case-insensitive. */
static void test_enum_names(void **state)
{
    (void)state;
    struct {
        const char *section, *key, *given, *printed;
        const int *field;
        int value;
    } cases[] = {
        {"experiment", "geometry", "tube", "tube", (const int *)&cfg.scene.geometry, PPB_GEOM_TUBE},
        {"experiment", "geometry", "SLAB", "slab", (const int *)&cfg.scene.geometry, PPB_GEOM_SLAB},
        {"medium", "step", "none", "none", &cfg.scene.step, PPB_STEP_NONE},
        {"medium", "step", "density", "density", &cfg.scene.step, PPB_STEP_DENSITY},
        {"medium", "step", "Albedo", "albedo", &cfg.scene.step, PPB_STEP_ALBEDO},
        {"medium", "step", "shadow", "shadow", &cfg.scene.step, PPB_STEP_SHADOW},
        {"pp", "table", "R", "R", &cfg.pp.table, PPB_TABLE_R},
        {"pp", "table", "s", "S", &cfg.pp.table, PPB_TABLE_S},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        ppb_err err = {{0}};
        assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
        if (ppb_config_set(&cfg, cases[i].section, cases[i].key, cases[i].given, &err))
            fail_msg("%s", err.msg);
        assert_int_equal(*cases[i].field, cases[i].value);
        char *text = NULL, line[128];
        size_t len = 0;
        FILE *out = open_memstream(&text, &len);
        ppb_config_write_resolved(&cfg, out);
        fclose(out);
        snprintf(line, sizeof line, "\n%s.%s = %s\n", cases[i].section, cases[i].key,
                 cases[i].printed);
        if (!strstr(text, line))
            fail_msg("resolved config lacks '%s'", line + 1);
        free(text);
    }
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_set(&cfg, "medium", "step", "sideways", &err), -1);
    assert_string_equal(err.msg,
                        "--set medium.step: 'sideways' is not one of none|density|albedo|shadow");
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
    const char *p = tu_config("sweep", "[medium]\ng = 0, 0.5\nalbedo = 0.5:0.9:0.2\n");
    ppb_err err = {{0}};
    ppb_grid *grid = ppb_grid_new();
    assert_non_null(grid);
    assert_int_equal(ppb_config_load_grid(&cfg, grid, p, &err), 0);
    assert_int_equal(grid->naxes, 2);
    char name[64];
    ppb_config_key_name(grid->axes[1].key, name, sizeof name);
    assert_string_equal(name, "medium.albedo");               /* axes in file order */
    assert_int_equal(ppb_grid_npoints(grid), 6);              /* 2 values x {0.5, 0.7, 0.9} */
    assert_true(cfg.scene.g == 0 && cfg.scene.albedo == 0.5); /* each list's first value */
    ppb_config pt;
    /* Row-major, last axis fastest: point 4 = (g index 1, albedo index 1). */
    assert_int_equal(ppb_config_point(&cfg, grid, 4, &pt, &err), 0);
    assert_true(pt.scene.g == 0.5);
    assert_close(pt.scene.albedo, 0.7, 1e-12);
    assert_int_equal(ppb_config_point(&cfg, grid, 6, &pt, &err), -1);
    /* --set replaces a key's list (the axis moves to the end) or drops it for one value. */
    assert_int_equal(ppb_config_set_grid(&cfg, grid, "medium", "g", "0.1, 0.2, 0.3", &err), 0);
    assert_int_equal(grid->naxes, 2);
    ppb_config_key_name(grid->axes[1].key, name, sizeof name);
    assert_string_equal(name, "medium.g");
    assert_int_equal(ppb_grid_npoints(grid), 9);
    assert_int_equal(ppb_config_point(&cfg, grid, 5, &pt, &err), 0); /* albedo 1, g 2 */
    assert_close(pt.scene.albedo, 0.7, 1e-12);
    assert_true(pt.scene.g == 0.3);
    assert_int_equal(ppb_config_set_grid(&cfg, grid, "medium", "albedo", "0.8", &err), 0);
    assert_int_equal(grid->naxes, 1);
    assert_int_equal(ppb_grid_npoints(grid), 3);
    /* Loading again starts from an empty grid. */
    p = tu_config("plain", "[medium]\ng = 0.5\n");
    assert_int_equal(ppb_config_load_grid(&cfg, grid, p, &err), 0);
    assert_int_equal(grid->naxes, 0);
    assert_int_equal(ppb_grid_npoints(grid), 1);
    ppb_grid_free(grid);
    assert_int_equal(ppb_grid_npoints(NULL), 1);
}

static void test_set_override(void **state)
{
    (void)state;
    const char *p = tu_config("set", "[mc]\nphotons = 1e6\n");
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, p, &err), 0);
    assert_int_equal(ppb_config_set(&cfg, "mc", "photons", "2e3", &err), 0);
    assert_true(cfg.mc.photons == 2000);
    assert_int_equal(ppb_config_set(&cfg, "mc", "nope", "1", &err), -1);
    assert_non_null(strstr(err.msg, "--set mc.nope: unknown key"));
    /* A check across keys names the key --set gave, not the file. */
    assert_int_equal(ppb_config_set(&cfg, "experiment", "geometry", "slab", &err), 0);
    assert_int_equal(ppb_config_set(&cfg, "medium", "step", "density", &err), -1);
    assert_string_equal(
        err.msg, "--set medium.step: steps are refused in slab mode (docs/reference.md, Geometry; "
                 "geometry = slab from --set experiment.geometry)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spec_example),     cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_errors),           cmocka_unit_test(test_method_checks),
        cmocka_unit_test(test_enum_names),       cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_lists_and_points), cmocka_unit_test(test_set_override),
    };
    return cmocka_run_group_tests_name("config", tests, NULL, NULL);
}
