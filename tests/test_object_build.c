/* test_object_build.c: the object builders and readers (model/object_build.h). Expected values
 * are geometry and the files' own contents: the octahedron |x| + |y| + |z| <= 1 scan-converted
 * against the inequality at every voxel centre (no centre of the 12^3 grid lies on its
 * surface: the sums are odd multiples of 1/12 away from 1), the shapes' voxels against their
 * defining inequalities, a voxel file read back equal to what was written, and bad files
 * refused naming the file. */
#include "testutil.h"

#include "model/object_build.h"

static char tmpdir[512];

static void path_in_tmp(char *buf, size_t n, const char *name)
{
    const char *t = getenv("TMPDIR");
    snprintf(buf, n, "%s/%s.%d", t && *t ? t : "/tmp", name, (int)getpid());
    (void)tmpdir;
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void test_octahedron(void **state)
{
    (void)state;
    char path[600];
    path_in_tmp(path, sizeof path, "octa.obj");
    write_text(path, "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
                     "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n");
    ppb_mesh m;
    ppb_err err;
    assert_int_equal(ppb_mesh_read_obj(path, &m, &err), 0);
    assert_int_equal(m.nv, 6);
    assert_int_equal(m.nt, 8);
    ppb_object o;
    memset(&o, 0, sizeof o);
    o.nx = o.ny = o.nz = 12, o.voxel = 0.5;
    o.mat = calloc(12 * 12 * 12, 1);
    ppb_mesh_voxelize(&m, &o, 1);
    int wrong = 0, inside = 0;
    for (int k = 0; k < 12; k++)
        for (int j = 0; j < 12; j++)
            for (int i = 0; i < 12; i++) {
                /* the centre in the mesh's frame: the grid's box is [-1, 1]^3 */
                double x = (i + 0.5) / 6 - 1, y = (j + 0.5) / 6 - 1, z = (k + 0.5) / 6 - 1;
                int in = fabs(x) + fabs(y) + fabs(z) < 1;
                inside += in;
                wrong += in != o.mat[ppb_object_voxel(&o, i, j, k)];
            }
    assert_true(inside > 100);
    assert_int_equal(wrong, 0);
    free(o.mat);
    ppb_mesh_free(&m);
    write_text(path, "v 0 0 0\nv 1 0 0\nf 1 2 3\n");
    assert_int_equal(ppb_mesh_read_obj(path, &m, &err), -1);
    assert_non_null(strstr(err.msg, ":3: face vertex"));
    remove(path);
}

static void test_shapes_and_file(void **state)
{
    (void)state;
    ppb_config cfg;
    ppb_err err;
    assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
    const char *sets[][3] = {{"object", "shape", "yokan"},
                             {"object", "grid_x", "10"},
                             {"object", "grid_y", "8"},
                             {"object", "grid_z", "6"},
                             {"object", "inclusion_radius", "0.3"},
                             {"medium", "albedo", "0.8"}};
    for (int i = 0; i < 6; i++)
        assert_int_equal(ppb_config_set(&cfg, sets[i][0], sets[i][1], sets[i][2], &err), 0);
    ppb_object o;
    assert_int_equal(ppb_object_build(&cfg, &o, &err), 0);
    assert_int_equal(o.nmat, 2);
    /* The chestnut: centre (5, 4, 3) voxels, radius 0.3 x 6; the rest of the box material 1. */
    for (int k = 0; k < 6; k++)
        for (int j = 0; j < 8; j++)
            for (int i = 0; i < 10; i++) {
                double x = i + 0.5 - 5, y = j + 0.5 - 4, z = k + 0.5 - 3;
                int want = x * x + y * y + z * z <= 1.8 * 1.8 ? 2 : 1;
                assert_int_equal(o.mat[ppb_object_voxel(&o, i, j, k)], want);
            }
    char path[600];
    path_in_tmp(path, sizeof path, "yokan.vox");
    assert_int_equal(ppb_object_write_voxels(&o, path, &err), 0);
    ppb_object back;
    memset(&back, 0, sizeof back);
    assert_int_equal(ppb_object_read_voxels(path, &back, &err), 0);
    assert_int_equal(back.nx, 10);
    assert_int_equal(back.ny, 8);
    assert_int_equal(back.nz, 6);
    assert_int_equal(back.nmat, 2);
    assert_true(back.voxel == o.voxel);
    assert_true(back.material[1].albedo == 0.8 &&
                back.material[2].sigma_t == o.material[2].sigma_t);
    assert_memory_equal(back.mat, o.mat, 10 * 8 * 6);
    ppb_object_free(&back);
    /* A truncated file and a bad header are refused, naming the file. */
    FILE *f = fopen(path, "r+");
    assert_non_null(f);
    assert_int_equal(ftruncate(fileno(f), 100), 0);
    fclose(f);
    assert_int_equal(ppb_object_read_voxels(path, &back, &err), -1);
    assert_non_null(strstr(err.msg, path));
    write_text(path, "{\"format\": \"ppbench-voxels\", \"version\": 2}\n");
    assert_int_equal(ppb_object_read_voxels(path, &back, &err), -1);
    assert_non_null(strstr(err.msg, "version"));
    remove(path);
    ppb_object_free(&o);
    /* The sphere: the voxels whose centre is within nmin / 2 of the grid's centre. */
    assert_int_equal(ppb_config_set(&cfg, "object", "shape", "sphere", &err), 0);
    assert_int_equal(ppb_object_build(&cfg, &o, &err), 0);
    int n = 0, want = 0;
    for (int k = 0; k < 6; k++)
        for (int j = 0; j < 8; j++)
            for (int i = 0; i < 10; i++) {
                double x = i + 0.5 - 5, y = j + 0.5 - 4, z = k + 0.5 - 3;
                want += x * x + y * y + z * z <= 9;
                n += o.mat[ppb_object_voxel(&o, i, j, k)];
            }
    assert_int_equal(n, want);
    ppb_object_free(&o);
    /* A mesh file that is not there: the key that named it. */
    assert_int_equal(ppb_config_set(&cfg, "object", "shape", "mesh", &err), 0);
    assert_int_equal(ppb_config_set(&cfg, "object", "mesh", "/nonexistent/x.obj", &err), 0);
    assert_int_equal(ppb_object_build(&cfg, &o, &err), -1);
    /* set as --set would: named "--set object.mesh" (a file's key: "file:line: [object] mesh") */
    assert_non_null(strstr(err.msg, "object.mesh"));
    assert_non_null(strstr(err.msg, "/nonexistent/x.obj"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_octahedron),
        cmocka_unit_test(test_shapes_and_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
