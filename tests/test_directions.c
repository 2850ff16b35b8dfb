/* test_directions.c: the equal-area direction cells (src/physics/directions.h): exact solid angles
 * and mean cosines, the two mirror symmetries, closure under w -> -w, cell lookup, and the
 * quadrature nodes. */
#include "testutil.h"

#include <math.h>

#include "physics/directions.h"

#define PI 3.14159265358979323846

static const int sizes[] = {2, 7, 64, 334, 1000};

/* Both partitions (default and antipodal): every cell 2 pi / N, so the 2N cells cover 4 pi exactly;
 * each ring's mu span times 2 pi is its cells' total (dOmega = dmu dphi: the exact area of a (mu,
 * phi) rectangle). */
static void test_solid_angles_exact(void **state)
{
    (void)state;
    for (size_t t = 0; t < 2 * sizeof sizes / sizeof *sizes; t++) {
        pp_dirs d;
        ppb_err err;
        int n = sizes[t % (sizeof sizes / sizeof *sizes)];
        assert_int_equal(t < sizeof sizes / sizeof *sizes ? pp_dirs_make(n, &d, &err)
                                                          : pp_dirs_make_antipodal(n, &d, &err),
                         0);
        assert_true(fabs(2 * d.n * d.solid - 4 * PI) < 1e-12);
        double mu_sum = 0.0;
        for (int r = 0; r < d.nrings; r++) {
            int count = d.ring_first[r + 1] - d.ring_first[r];
            double area = (d.mu_edge[r] - d.mu_edge[r + 1]) * 2 * PI;
            assert_true(fabs(area - count * d.solid) < 1e-13);
            mu_sum += d.mu_edge[r] - d.mu_edge[r + 1];
        }
        assert_true(fabs(mu_sum - 1.0) < 1e-15 && d.mu_edge[d.nrings] == 0.0);
        pp_dirs_free(&d);
    }
}

/* k_i = |Omega|^-1 integral of mu over the cell: compared with the order-8 node quadrature of
 * mu (exact to rounding for this polynomial-in-cos integrand). */
static void test_mean_cosines_exact(void **state)
{
    (void)state;
    pp_dirs d;
    ppb_err err;
    assert_int_equal(pp_dirs_make(334, &d, &err), 0);
    for (int i = 0; i < 2 * d.n; i++) {
        const double *nodes = pp_dirs_nodes(&d, i, 8, &err);
        assert_non_null(nodes);
        double mu = 0.0, wsum = 0.0;
        for (int a = 0; a < 64; a++)
            mu += nodes[4 * a + 1] * nodes[4 * a + 3], wsum += nodes[4 * a + 3];
        assert_true(fabs(wsum - d.solid) < 1e-15);
        assert_true(fabs(mu / d.solid - d.k[i]) < 1e-12);
    }
    pp_dirs_free(&d);
}

/* Cell N + i is the y-mirror of cell i; the z-mirror keeps the ring and flips phi. */
static void test_mirror_symmetries(void **state)
{
    (void)state;
    for (size_t t = 0; t < 2 * sizeof sizes / sizeof *sizes; t++) {
        pp_dirs d;
        ppb_err err;
        int n = sizes[t % (sizeof sizes / sizeof *sizes)];
        assert_int_equal(t < sizeof sizes / sizeof *sizes ? pp_dirs_make(n, &d, &err)
                                                          : pp_dirs_make_antipodal(n, &d, &err),
                         0);
        for (int i = 0; i < d.n; i++) {
            const double *c = d.centre + 3 * i;
            double down[3] = {c[0], -c[1], c[2]}, zm[3] = {c[0], c[1], -c[2]};
            assert_int_equal(pp_dirs_cell_of(&d, c), i);
            assert_int_equal(pp_dirs_cell_of(&d, down), d.n + i);
            int m = pp_dirs_zmirror(&d, i);
            assert_int_equal(pp_dirs_cell_of(&d, zm), m);
            assert_int_equal(d.ring[m], d.ring[i]);
            assert_true(d.k[d.n + i] == -d.k[i]);
        }
        pp_dirs_free(&d);
    }
}

/* The antipodal partition is closed under w -> -w (directions.h: the polar ring is a cap or
 * four wedges and every collar count is even): the antipode of a cell holds minus its centre
 * and minus every one of its nodes, is an involution, and lies in the other hemisphere. For odd
 * N it is the default partition; for even N the default one has no antipodes. */
static void test_partition_is_antipodal(void **state)
{
    (void)state;
    for (size_t t = 0; t < sizeof sizes / sizeof *sizes; t++) {
        pp_dirs d, plain;
        ppb_err err;
        assert_int_equal(pp_dirs_make_antipodal(sizes[t], &d, &err), 0);
        assert_int_equal(pp_dirs_make(sizes[t], &plain, &err), 0);
        if (sizes[t] % 2) {
            assert_int_equal(plain.nrings, d.nrings);
            for (int r = 0; r <= d.nrings; r++)
                assert_int_equal(plain.ring_first[r], d.ring_first[r]);
        } else if (sizes[t] > 2) {
            assert_int_equal(pp_dirs_antipode(&plain, 1), -1);
        }
        pp_dirs_free(&plain);
        for (int r = 0; r < d.nrings; r++) {
            int count = d.ring_first[r + 1] - d.ring_first[r];
            assert_true(count == 1 || count % 2 == 0);
        }
        for (int i = 0; i < 2 * d.n; i++) {
            int a = pp_dirs_antipode(&d, i);
            assert_true(a >= 0 && a < 2 * d.n && (a < d.n) != (i < d.n));
            assert_int_equal(pp_dirs_antipode(&d, a), i);
            const double *c = d.centre + 3 * i;
            double minus[3] = {-c[0], -c[1], -c[2]};
            assert_int_equal(pp_dirs_cell_of(&d, minus), a);
            const double *nodes = pp_dirs_nodes(&d, i, 3, &err);
            for (int m = 0; m < 9; m++) {
                double v[3] = {-nodes[4 * m], -nodes[4 * m + 1], -nodes[4 * m + 2]};
                assert_int_equal(pp_dirs_cell_of(&d, v), a);
            }
        }
        pp_dirs_free(&d);
    }
}

/* Every node lies in its own cell, and the lookup of random directions agrees with the
 * bounds. */
static void test_nodes_lie_in_their_cell(void **state)
{
    (void)state;
    pp_dirs d;
    ppb_err err;
    assert_int_equal(pp_dirs_make(64, &d, &err), 0);
    for (int i = 0; i < 2 * d.n; i++) {
        const double *nodes = pp_dirs_nodes(&d, i, 5, &err);
        for (int a = 0; a < 25; a++)
            assert_int_equal(pp_dirs_cell_of(&d, nodes + 4 * a), i);
    }
    pp_dirs_free(&d);
    assert_int_equal(pp_dirs_make(0, &d, &err), -1);
    assert_non_null(strstr(err.msg, "cells per hemisphere"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_solid_angles_exact),
        cmocka_unit_test(test_mean_cosines_exact),
        cmocka_unit_test(test_mirror_symmetries),
        cmocka_unit_test(test_partition_is_antipodal),
        cmocka_unit_test(test_nodes_lie_in_their_cell),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
