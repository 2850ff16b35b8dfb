/* test_object_cli.c: `ppbench object` end to end (drivers/object.c; docs/reference.md, Objects).
 * Expected: the output set's files with the headers the reference documents, the energy
 * balance of totals_mc3d.csv (conservation: 1 to the fixed-point rounding), the set's own
 * config.ini and its object.vox (read back as shape = file) reproducing radiance.csv byte for byte
 * (the same photons through the same voxels), and bad configs refused with exit 2 naming file:line:
 * [section] key before anything is written. */
#include "cliutil.h"

static const char *yokan_ini = "[experiment]\n"
                               "methods = mc3d\n"
                               "[medium]\n"
                               "albedo = 0.9\n"
                               "g = 0.3\n"
                               "[object]\n"
                               "shape = yokan\n"
                               "grid_x = 12\n"
                               "grid_y = 8\n"
                               "grid_z = 10\n"
                               "voxel = 0.5\n"
                               "light_theta = 35\n"
                               "image_width = 24\n"
                               "image_height = 20\n"
                               "patch = 3\n"
                               "[bins]\n"
                               "theta = 3\n"
                               "phi = 4\n"
                               "[mc]\n"
                               "photons = 20000\n"
                               "batches = 4\n";

static int first_line_is(const char *path, const char *line)
{
    const char *t = tu_read_text(path);
    size_t n = strlen(line);
    return strncmp(t, line, n) == 0 && t[n] == '\n';
}

static void test_output_set(void **state)
{
    (void)state;
    const char *cfg = cli_config("objcli", yokan_ini);
    char dir[1400], args[6000], path[1600];
    snprintf(dir, sizeof dir, "%s/out", tu_scratch("objcli-out"));
    snprintf(args, sizeof args, "object --quiet --out %s %s", dir, cfg);
    cli_expect(args, 0, "");
    const char *heads[][2] = {
        {"radiance.csv",
         "method,patch,axis,side,cx,cy,cz,area,region,bin,theta_bin,phi_bin,radiance,se"},
        {"regions.csv", "method,over,region,count,rms,rms_rel,ref_mean,ref_se_mean"},
        {"totals_mc3d.csv", "launched,hits,escaped,escaped_se,ballistic,absorbed,absorbed_se,rgain,"
                            "rloss,balance,events,capped,entry_area"},
        {"timings.csv", "method,seconds,photons"},
        {"provenance.txt", "# ppbench provenance: what produced the files beside this one"}};
    for (int i = 0; i < 5; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, heads[i][0]);
        if (!first_line_is(path, heads[i][1]))
            fail_msg("%s does not start with %s", path, heads[i][1]);
    }
    const char *files[] = {"images/mc3d.exr",        "images/mc3d.png", "images/mc3d1.exr",
                           "images/mc3d1_error.png", "object.vox",      "config.ini"};
    for (int i = 0; i < 6; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        assert_int_equal(access(path, R_OK), 0);
    }
    snprintf(path, sizeof path, "%s/totals_mc3d.csv", dir);
    const char *t = strchr(tu_read_text(path), '\n') + 1;
    double v[13];
    assert_int_equal(sscanf(t, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1],
                            &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9], &v[10], &v[11],
                            &v[12]),
                     13);
    assert_true(v[1] > 0 && v[1] <= v[0]);
    assert_close(v[9], 1.0, 1e-9);
    /* The set's config.ini repeats the run: the same radiance.csv. */
    char again[1400];
    snprintf(again, sizeof again, "%s/again", tu_scratch("objcli-again"));
    snprintf(args, sizeof args, "object --quiet --out %s %s/config.ini", again, dir);
    cli_expect(args, 0, "");
    assert_int_equal(tu_sh("cmp -s %s/radiance.csv %s/radiance.csv", dir, again), 0);
    /* Its object.vox as shape = file: the same voxels and materials, the same radiance.csv. */
    char vox[1400];
    snprintf(vox, sizeof vox, "%s/file", tu_scratch("objcli-file"));
    snprintf(args, sizeof args,
             "object --quiet --out %s --set object.shape=file --set object.voxels=%s/object.vox "
             "%s",
             vox, dir, cfg);
    cli_expect(args, 0, "");
    assert_int_equal(tu_sh("cmp -s %s/radiance.csv %s/radiance.csv", dir, vox), 0);
}

/* The regions of a 4^3 voxel box lit and seen from +y, one face a patch, one bin: by the
 * box's geometry each face has 4 corner voxels (boundary faces of three axes), 8 edge voxels and
 * 4 inner ones, so 24 corner, 48 edge and 24 face patches; every patch but the top's 16 is
 * shadowed (facing away, or grazing the light); the 8 x 8 pixels see the top face, 2 x 2 pixels
 * a voxel: 16 face pixels, 32 edge, 16 corner, none shadowed. */
static void test_regions(void **state)
{
    (void)state;
    const char *cfg = cli_config("objreg", "[experiment]\nmethods = mc3d\n[object]\nshape = box\n"
                                           "grid_x = 4\ngrid_y = 4\ngrid_z = 4\nvoxel = 0.5\n"
                                           "light_theta = 0\ncamera_theta = 0\npatch = 1\n"
                                           "image_width = 8\nimage_height = 8\n[bins]\n"
                                           "theta = 1\nphi = 1\n[mc]\nphotons = 20000\n"
                                           "batches = 4\n");
    char dir[1400], args[6000], path[1600];
    snprintf(dir, sizeof dir, "%s/out", tu_scratch("objreg-out"));
    snprintf(args, sizeof args, "object --quiet --out %s %s", dir, cfg);
    cli_expect(args, 0, "");
    snprintf(path, sizeof path, "%s/regions.csv", dir);
    const char *t = tu_read_text(path);
    const char *want[] = {
        "mc3d,patches,all,96,",     "mc3d,patches,faces,24,",    "mc3d,patches,edges,48,",
        "mc3d,patches,corners,24,", "mc3d,patches,shadowed,80,", "mc3d,patches,inclusion,0,",
        "mc3d,pixels,all,64,",      "mc3d,pixels,faces,16,",     "mc3d,pixels,edges,32,",
        "mc3d,pixels,corners,16,",  "mc3d,pixels,shadowed,0,"};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++)
        if (!strstr(t, want[i]))
            fail_msg("regions.csv lacks %s:\n%s", want[i], t);
}

static void test_refusals(void **state)
{
    (void)state;
    char args[6000], dir[1400];
    snprintf(dir, sizeof dir, "%s/never", tu_scratch("objcli-bad"));
    const char *cases[][3] = {
        {"[experiment]\nmethods = mc3d\n[medium]\nn = 1.33\n", "objbad1.ini:4: [medium] n",
         "n = 1 only"},
        {"[experiment]\nmethods = mc3d, pp\n", "objbad2.ini:2: [experiment] methods",
         "'pp' is no object method"},
        {"[experiment]\nmethods = mc3d\n[object]\nshape = mesh\nmesh = gone.obj\n",
         "objbad3.ini:5: [object] mesh", "gone.obj"},
        {"[experiment]\nmethods = mc3d\n[object]\ngrid_x = 0\n", "objbad4.ini:4: [object] grid_x",
         "out of range"}};
    for (int i = 0; i < 4; i++) {
        char name[32];
        snprintf(name, sizeof name, "objbad%d", i + 1);
        const char *cfg = cli_config(name, cases[i][0]);
        snprintf(args, sizeof args, "object --quiet --out %s %s", dir, cfg);
        cli_expect(args, 2, cases[i][1]);
        cli_expect(args, 2, cases[i][2]);
        assert_int_not_equal(access(dir, F_OK), 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_output_set),
        cmocka_unit_test(test_regions),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
