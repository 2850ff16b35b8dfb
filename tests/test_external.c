/* Methods from outside (issue 17, SPEC 13), through the built binary ($PPBENCH):
 * - `ppbench scene` writes scene.json whose sample points and bins are the conventions' own:
 *   checked against kernels/ppb_conventions.h (the point count of the layout, the bin index of
 *   every averaging direction as the Monte Carlo tallies bin it, w_k summing to pi -- SPEC 4:
 *   the bins cover the projected solid angle of the hemisphere, pi);
 * Expected values come from the conventions' functions (an independent path: the tallies'
 * binning of a direction, not the writer's loop), from SPEC 4's sum and from exit codes of
 * README.md. Tiny grids: bookkeeping, not physics. */
#include "cliutil.h"

#include <jansson.h>
#include <sys/stat.h>

static json_t *load_json(const char *path)
{
    json_error_t je;
    json_t *doc = json_load_file(path, 0, &je);
    if (!doc)
        fail_msg("%s:%d: %s", path, je.line, je.text);
    return doc;
}

static double num(const json_t *obj, const char *key)
{
    json_t *v = json_object_get(obj, key);
    if (!json_is_number(v))
        fail_msg("no number '%s'", key);
    return json_number_value(v);
}

static void test_scene_json(void **state)
{
    (void)state;
    const char *dir = tu_scratch("scene");
    char args[2400], path[1200];
    snprintf(args, sizeof args,
             "scene --out %s/out --set bins.theta=3 --set bins.phi=5 --set bins.samples_dir=2 "
             "--set tube.segments_top=7 --set tube.segments_side=3 configs/uniform_g0_normal.ini",
             dir);
    cli_expect(args, 0, "");
    snprintf(path, sizeof path, "%s/out/scene.json", dir);
    json_t *doc = load_json(path);
    json_t *pts = json_object_get(doc, "sample_points");
    json_t *bins = json_object_get(doc, "bins");
    assert_int_equal(json_array_size(pts), 2 * 7 + 2 * 3);
    assert_int_equal(json_array_size(bins), 3 * 5);
    double wsum = 0.0;
    for (size_t i = 0; i < json_array_size(bins); i++) {
        json_t *b = json_array_get(bins, i);
        int index = (int)num(b, "index");
        assert_int_equal(index, (int)i); /* the order of radiance.csv's rows */
        wsum += num(b, "w_k");
        json_t *dirs = json_object_get(b, "directions");
        assert_int_equal(json_array_size(dirs), 2 * 2);
        for (size_t k = 0; k < json_array_size(dirs); k++) {
            json_t *w = json_array_get(dirs, k);
            double n = json_number_value(json_array_get(w, 0));
            double t = json_number_value(json_array_get(w, 1));
            double z = json_number_value(json_array_get(w, 2));
            assert_close(n * n + t * t + z * z, 1.0, 1e-12);
            /* On S4 (n = +x, t = -y): the direction in world coordinates, binned as mc does. */
            assert_int_equal(ppb_dir_bin(PPB_S4, n, -t, z, 3, 5), index);
        }
    }
    assert_close(wsum, PPB_PI, 1e-12);
    /* Every point's frame: t = n x b with b = +z, i.e. t = (n_y, -n_x). */
    for (size_t i = 0; i < json_array_size(pts); i++) {
        json_t *p = json_array_get(pts, i);
        json_t *n = json_object_get(p, "normal"), *t = json_object_get(p, "tangent");
        assert_close(json_number_value(json_array_get(t, 0)),
                     json_number_value(json_array_get(n, 1)), 0);
        assert_close(json_number_value(json_array_get(t, 1)),
                     -json_number_value(json_array_get(n, 0)), 0);
    }
    json_t *first = json_array_get(pts, 0);
    assert_string_equal(json_string_value(json_object_get(first, "surface")), "S1");
    assert_close(num(first, "s"), -5.0 + 0.5 * 10.0 / 7, 1e-12); /* SPEC 2: from x = -W/2 */
    json_decref(doc);
    /* A bad config is refused before anything is written (exit 2, README). */
    snprintf(args, sizeof args,
             "scene --out %s/bad --set medium.albedo=2 "
             "configs/uniform_g0_normal.ini",
             dir);
    cli_expect(args, 2, "albedo");
    struct stat st;
    snprintf(path, sizeof path, "%s/bad", dir);
    assert_int_equal(stat(path, &st), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scene_json),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
