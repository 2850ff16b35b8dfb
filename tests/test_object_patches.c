/* test_object_patches.c: the three-dimensional objects' boundary patches (model/object.h).
 * Expected values are geometry: a box's faces and surface area, a shape's boundary faces counted
 * independently by a direct scan of every voxel's six neighbours, and each face's patch holding
 * that face's centre within its patch's extent. */
#include "testutil.h"

#include "model/object.h"

/* An object of nx x ny x nz voxels of edge h, medium where keep(i, j, k) says so. */
static ppb_object make(int nx, int ny, int nz, double h, int patch,
                       int (*keep)(int, int, int, int, int, int))
{
    ppb_object o;
    memset(&o, 0, sizeof o);
    snprintf(o.name, sizeof o.name, "test");
    o.nx = nx, o.ny = ny, o.nz = nz, o.voxel = h, o.patch = patch, o.nmat = 1;
    o.mat = calloc((size_t)nx * ny * nz, 1);
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++)
                o.mat[ppb_object_voxel(&o, i, j, k)] = (unsigned char)keep(i, j, k, nx, ny, nz);
    return o;
}

static int all(int i, int j, int k, int nx, int ny, int nz)
{
    (void)i, (void)j, (void)k, (void)nx, (void)ny, (void)nz;
    return 1;
}

/* A ball of radius 0.45 n about the grid's centre (n = nx = ny = nz). */
static int ball(int i, int j, int k, int nx, int ny, int nz)
{
    double c = 0.5 * nx, r = 0.45 * nx, x = i + 0.5 - c, y = j + 0.5 - c, z = k + 0.5 - c;
    (void)ny, (void)nz;
    return x * x + y * y + z * z <= r * r;
}

static void test_box(void **state)
{
    (void)state;
    ppb_object o = make(6, 4, 5, 0.5, 1, all);
    ppb_object_patches p;
    ppb_err err;
    assert_int_equal(ppb_object_patches_build(&o, &p, &err), 0);
    /* One face a patch: 2 (nx ny + ny nz + nz nx) faces. */
    assert_int_equal(p.npatch, 2 * (6 * 4 + 4 * 5 + 5 * 6));
    double area = 0;
    for (int i = 0; i < p.npatch; i++)
        area += p.patch[i].area;
    /* The box's surface area: 2 (3 x 2 + 2 x 2.5 + 2.5 x 3). */
    assert_close(area, 2 * (3 * 2 + 2 * 2.5 + 2.5 * 3), 1e-12);
    ppb_object_patches_free(&p);
    /* Patches of 2 x 2 faces: ceil(nu / 2) ceil(nv / 2) per face of the box. */
    o.patch = 2;
    assert_int_equal(ppb_object_patches_build(&o, &p, &err), 0);
    assert_int_equal(p.npatch, 2 * (3 * 2 + 2 * 3 + 3 * 3));
    ppb_object_patches_free(&p);
    free(o.mat);
}

static void test_ball_faces(void **state)
{
    (void)state;
    ppb_object o = make(12, 12, 12, 1.0, 3, ball);
    ppb_object_patches p;
    ppb_err err;
    assert_int_equal(ppb_object_patches_build(&o, &p, &err), 0);
    int faces = 0, mapped = 0;
    for (int k = 0; k < 12; k++)
        for (int j = 0; j < 12; j++)
            for (int i = 0; i < 12; i++) {
                size_t v = ppb_object_voxel(&o, i, j, k);
                for (int f = 0; f < 6; f++) {
                    int a = f / 2, s = f % 2 ? 1 : -1, c[3] = {i, j, k};
                    c[a] += s;
                    int out =
                        c[a] < 0 || c[a] >= 12 || !o.mat[ppb_object_voxel(&o, c[0], c[1], c[2])];
                    int q = p.face_patch[6 * v + (size_t)f];
                    if (o.mat[v] && out) {
                        faces++;
                        assert_true(q >= 0 && q < p.npatch);
                        const ppb_object_patch *pa = &p.patch[q];
                        /* The face's centre lies in its patch's plane, on its side, within 3 faces.
                         */
                        double fc[3] = {i + 0.5, j + 0.5, k + 0.5};
                        fc[a] += 0.5 * s;
                        assert_int_equal(pa->axis, a);
                        assert_int_equal(pa->side, s);
                        assert_close(pa->c[a], fc[a], 1e-12);
                        for (int b = 0; b < 3; b++)
                            assert_true(fabs(pa->c[b] - fc[b]) < 3.0);
                        mapped++;
                    } else {
                        assert_int_equal(q, -1);
                    }
                }
            }
    double area = 0;
    for (int i = 0; i < p.npatch; i++)
        area += p.patch[i].area;
    assert_int_equal(mapped, faces);
    assert_close(area, (double)faces, 1e-9);
    ppb_object_patches_free(&p);
    free(o.mat);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_box),
        cmocka_unit_test(test_ball_faces),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
