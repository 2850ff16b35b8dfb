/* test_directions.c: the equal-area direction cells (src/physics/directions.h): cell areas
 * and mean cosines from the cells' edges as the membership function draws them, solid angles
 * and mean cosines against a Monte Carlo over the sphere, the two mirror symmetries, closure
 * under w -> -w, cell lookup, and the quadrature nodes. */
#include "testutil.h"

#include <math.h>

#include "physics/directions.h"

#define PI 3.14159265358979323846

static const int sizes[] = {2, 7, 64, 334, 1000};

/* The direction at (mu, phi) (directions.h's frame: mu = w.y, phi from +x toward +z). */
static int cell_at(const pp_dirs *d, double mu, double phi)
{
    double st = sqrt(fmax(0.0, 1.0 - mu * mu));
    double w[3] = {st * cos(phi), mu, st * sin(phi)};
    return pp_dirs_cell_of(d, w);
}

/* Where cell i ends, found with the membership function alone: from t0 (inside) along mu at
 * phi = fixed (walk_mu) or along phi at mu = fixed, in steps of step until the cell changes or
 * the walk reaches end, then bisected to 1e-14. *open: the cell still holds end (the pole, or a
 * whole turn in phi). */
static double edge_of(const pp_dirs *d, int i, int walk_mu, double fixed, double t0, double step,
                      double end, int *open)
{
    double a = t0, b = t0;
    *open = 0;
    for (;;) {
        b = a + step;
        if ((step > 0) == (b >= end)) {
            b = end;
            if ((walk_mu ? cell_at(d, end, fixed) : cell_at(d, fixed, end)) == i) {
                *open = 1;
                return end;
            }
            break;
        }
        if ((walk_mu ? cell_at(d, b, fixed) : cell_at(d, fixed, b)) != i)
            break;
        a = b;
    }
    while (fabs(b - a) > 1e-14) {
        double m = 0.5 * (a + b);
        if ((walk_mu ? cell_at(d, m, fixed) : cell_at(d, fixed, m)) == i)
            a = m;
        else
            b = m;
    }
    return 0.5 * (a + b);
}

/* Cell i's (mu, phi) rectangle found by probing the membership function pp_dirs_cell_of (not
 * from the partition's tables): walks from the cell's centre along its meridian and its parallel
 * to where the cell ends (edge_of), checks that the cell is the rectangle those edges bound (9
 * points inside belong to it; points 1e-9 beyond each edge, 3 per edge, do not), and returns
 * its area by Archimedes (the area of a zone is 2 pi times its height): |Omega_i| = (mu_hi -
 * mu_lo)(phi_hi - phi_lo). The bisection leaves each edge within 1e-14, so the area within about
 * 1e-13. */
static double probed_area(const pp_dirs *d, int i, double *mu_lo_out, double *mu_hi_out)
{
    int n = d->n;
    double hmu = 1.0 / (16.0 * n), hphi = 2.0 * PI / (16.0 * n);
    const double *c = d->centre + 3 * i;
    double mu0 = c[1], phi0 = atan2(c[2], c[0]);
    assert_int_equal(cell_at(d, mu0, phi0), i);
    int open_hi, open_lo, open_p, open_m;
    double mu_hi = edge_of(d, i, 1, phi0, mu0, hmu, 1.0, &open_hi);
    double mu_lo = edge_of(d, i, 1, phi0, mu0, -hmu, -1.0, &open_lo);
    double phi_hi = edge_of(d, i, 0, mu0, phi0, hphi, phi0 + 2 * PI, &open_p);
    double phi_lo = edge_of(d, i, 0, mu0, phi0, -hphi, phi0 - 2 * PI, &open_m);
    int whole = open_p || open_m; /* a polar cap: the whole turn */
    if (whole)
        phi_lo = phi0 - PI, phi_hi = phi0 + PI;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double f[3] = {0.1, 0.5, 0.9};
            double mu = mu_lo + f[a] * (mu_hi - mu_lo), ph = phi_lo + f[b] * (phi_hi - phi_lo);
            if (cell_at(d, mu, ph) != i)
                fail_msg("N = %d cell %d: (mu %.6f, phi %.6f) inside its edges is cell %d", n, i,
                         mu, ph, cell_at(d, mu, ph));
            if (!open_hi && mu_hi + 1e-9 <= 1.0 && cell_at(d, mu_hi + 1e-9, ph) == i)
                fail_msg("N = %d cell %d extends above mu %.15f", n, i, mu_hi);
            if (!open_lo && mu_lo - 1e-9 >= -1.0 && cell_at(d, mu_lo - 1e-9, ph) == i)
                fail_msg("N = %d cell %d extends below mu %.15f", n, i, mu_lo);
            if (!whole &&
                (cell_at(d, mu, phi_hi + 1e-9) == i || cell_at(d, mu, phi_lo - 1e-9) == i))
                fail_msg("N = %d cell %d extends beyond phi [%.15f, %.15f]", n, i, phi_lo, phi_hi);
        }
    if (fabs(0.5 * (mu_lo + mu_hi) - d->k[i]) > 1e-12)
        fail_msg("N = %d cell %d: mu [%.15f, %.15f]: mean cosine %.15g, k = %.15g", n, i, mu_lo,
                 mu_hi, 0.5 * (mu_lo + mu_hi), d->k[i]);
    *mu_lo_out = mu_lo, *mu_hi_out = mu_hi;
    return (mu_hi - mu_lo) * (phi_hi - phi_lo);
}

/* Every cell's probed area must be 2 pi / N (directions.h) to 1e-11, the cells must cover 4 pi,
 * and the mean cosine of a (mu, phi) rectangle, (mu_lo + mu_hi) / 2, must be k_i (reference:
 * Corrections). Both equal-area partitions. */
static void test_cell_areas_from_membership(void **state)
{
    (void)state;
    for (size_t t = 0; t < 2 * sizeof sizes / sizeof *sizes; t++) {
        pp_dirs d;
        ppb_err err;
        int n = sizes[t % (sizeof sizes / sizeof *sizes)], anti = t >= sizeof sizes / sizeof *sizes;
        assert_int_equal(anti ? pp_dirs_make_antipodal(n, &d, &err) : pp_dirs_make(n, &d, &err), 0);
        double total = 0.0, lo, hi;
        for (int i = 0; i < 2 * n; i++) {
            double area = probed_area(&d, i, &lo, &hi);
            if (fabs(area - 2 * PI / n) > 1e-11 || d.area[i % n] != d.solid)
                fail_msg("N = %d%s cell %d: area %.15g (2 pi / N = %.15g, stored %.15g)", n,
                         anti ? " antipodal" : "", i, area, 2 * PI / n, d.area[i % n]);
            total += area;
        }
        assert_close(total, 4 * PI, 1e-10);
        assert_close(d.solid, 2 * PI / n, 1e-15);
        assert_false(d.polar);
        pp_dirs_free(&d);
    }
}

/* The stored areas of a partition with polar rings against the rectangles probed through
 * cell_of (to 1e-11), and their sum 4 pi. */
static void assert_probed_areas(const pp_dirs *d, const char *what)
{
    double total = 0.0, lo, hi;
    for (int i = 0; i < 2 * d->n; i++) {
        double area = probed_area(d, i, &lo, &hi);
        if (fabs(area - d->area[i % d->n]) > 1e-11)
            fail_msg("%s, N = %d, cell %d: probed area %.15g, stored %.15g", what, d->n, i, area,
                     d->area[i % d->n]);
        total += area;
    }
    assert_close(total, 4 * PI, 1e-10);
}

/* The polar-ring partition (pp_dirs_make_collars, collars > 0), probed as above: the stored
 * areas are the probed rectangles' to 1e-11 and cover 4 pi; collars + 1 rings of equal polar
 * width pi / 2 / (collars + 1) without a snap (the cap one of them, one cell; every other ring
 * two at least); with the snap at n = 1.5's critical cosine, that cosine is a ring edge (to
 * 1e-14) and the rings on either side of it are of equal width each, four of them split in
 * four; below the cap each ring's cell count is its share of the N - 1 cells by area to within
 * two (the rounding in steps of two) above the floors (three cells for an odd first collar). */
static void test_polar_partition(void **state)
{
    (void)state;
    const int ns[] = {334, 334, 201, 60};
    const int collars[] = {79, 55, 30, 20};
    const double snaps[] = {0.0, 0.74535599249992989880, 0.5, 0.0};
    for (int t = 0; t < 4; t++) {
        pp_dirs d;
        ppb_err err;
        int n = ns[t];
        assert_int_equal(pp_dirs_make_collars(n, t == 3, snaps[t], collars[t], &d, &err), 0);
        assert_true(d.polar);
        assert_probed_areas(&d, "collars");
        assert_int_equal(d.ring_first[1], t == 3 ? 4 : 1); /* the cap (four wedges: antipodal) */
        int snapped = snaps[t] > 0.0, found = 0;
        if (!snapped)
            assert_int_equal(d.nrings, collars[t] + 1);
        else
            assert_int_equal(d.nrings, collars[t] + 1 + 6);
        double width = 0.5 * PI / (collars[t] + 1);
        for (int r = 0; r < d.nrings; r++) {
            int count = d.ring_first[r + 1] - d.ring_first[r];
            double t0 = acos(d.mu_edge[r]), t1 = acos(d.mu_edge[r + 1]);
            if (r > 0)
                assert_true(count >= 2);
            if (!snapped)
                assert_close(t1 - t0, width, 1e-12);
            if (fabs(d.mu_edge[r] - snaps[t]) < 1e-14)
                found = 1;
            double share = (n - 1) * (d.mu_edge[r] - d.mu_edge[r + 1]) / d.mu_edge[1];
            if (r > 0 && count > 3 && fabs(count - share) > 2.0)
                fail_msg("N = %d ring %d: %d cells for a share of %.2f", n, r, count, share);
        }
        assert_true(found == snapped);
        pp_dirs_free(&d);
    }
}

/* The graded polar rings (pp_dirs_make_spec, h_pole), probed through cell_of as above: the
 * stored areas are the probed rectangles and cover the sphere; the cap has radius
 * h_pole / sqrt(pi) (a near-square cell of side h_pole); the widths of the rings below it grow
 * monotonically from about h_pole toward the square cell's side sqrt(2 pi / N) (geometric
 * growth, up to the snap's rescaling); the snap edge lies at the critical cosine exactly; the
 * cells follow the rings' areas within the rounding. The cases: g 0.9's retained peak on the
 * study's 128 cells (h 0.123, n 1.4's snap), the same without the snap, on 256 cells, and the
 * antipodal variant (four wedges). And the tube's whole snap: the near-square cells with the
 * edge at the critical cosine but without the split's six extra rings. */
static void test_graded_partition(void **state)
{
    (void)state;
    const int ns[] = {128, 128, 256, 128};
    const double hs[] = {0.1227, 0.1227, 0.110, 0.15};
    const double snaps[] = {0.69985421222376, 0.0, 0.69985421222376, 0.0};
    for (int t = 0; t < 4; t++) {
        pp_dirs d;
        ppb_err err;
        int n = ns[t];
        pp_dirs_spec spec = {.antipodal = t == 3, .mu_snap = snaps[t], .h_pole = hs[t]};
        assert_int_equal(pp_dirs_make_spec(n, &spec, &d, &err), 0);
        assert_true(d.polar);
        assert_probed_areas(&d, "graded");
        assert_int_equal(d.ring_first[1], t == 3 ? 4 : 1);
        assert_close(acos(d.mu_edge[1]), hs[t] / sqrt(PI), 1e-12);
        double side = sqrt(2.0 * PI / n), prev = 0.0;
        int found = 0;
        for (int r = 1; r < d.nrings; r++) {
            double w = acos(d.mu_edge[r + 1]) - acos(d.mu_edge[r]);
            int count = d.ring_first[r + 1] - d.ring_first[r];
            assert_true(count >= 2);
            if (snaps[t] == 0.0) {
                if (r == 1)
                    assert_rel(w, hs[t], 0.15);
                assert_true(w >= prev - 1e-12);
                assert_true(w <= 1.15 * side);
            }
            prev = w;
            if (fabs(d.mu_edge[r] - snaps[t]) < 1e-14)
                found = 1;
            double share = (n - d.ring_first[1]) * (d.mu_edge[r] - d.mu_edge[r + 1]) / d.mu_edge[1];
            if (count > 3 && fabs(count - share) > 2.0)
                fail_msg("N = %d ring %d: %d cells for a share of %.2f", n, r, count, share);
        }
        assert_true(found == (snaps[t] > 0.0));
        pp_dirs_free(&d);
    }
    /* the whole snap: the edge at the critical cosine within the counts' rounding (1/N in mu,
     * pp_dirs_make_snap), and six rings fewer than with the split */
    pp_dirs a, b;
    ppb_err err;
    pp_dirs_spec whole = {.mu_snap = snaps[0], .whole_snap = 1};
    assert_int_equal(pp_dirs_make_spec(128, &whole, &a, &err), 0);
    assert_int_equal(pp_dirs_make_snap(128, 0, snaps[0], &b, &err), 0);
    assert_false(a.polar);
    assert_int_equal(a.nrings + 6, b.nrings);
    double near = 1.0;
    for (int r = 0; r <= a.nrings; r++)
        near = fmin(near, fabs(a.mu_edge[r] - snaps[0]));
    assert_true(near <= 1.0 / 128);
    pp_dirs_free(&a);
    pp_dirs_free(&b);
}

/* splitmix64 (Steele, Lea & Flood 2014): the test's own uniform stream, to (0, 1). */
static double uniform01(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return ((double)((z ^ (z >> 31)) >> 11) + 0.5) * 0x1p-53;
}

/* Monte Carlo over the sphere, independent of how the cells were built: directions uniform on
 * the sphere as normalised Gaussian vectors (Box-Muller; Marsaglia 1972), 500 per cell, looked up
 * with pp_dirs_cell_of. (1) The counts: each cell should get the fraction |Omega_i| / (4 pi) =
 * 1 / (2N); Pearson's chi-square over the 2N cells (2N - 1 degrees of freedom) must have
 * p > 1e-4. (2) The mean of mu over the directions that land in cell i estimates k_i (reference:
 * Corrections: k_i = |Omega_i|^-1 integral of mu over the cell); the z-scores against k_i, with
 * the sample standard deviation, summed in squares over the cells, are again chi-square with 2N
 * degrees of freedom. This replaces the check that the 2N cells of 2 pi / N cover 4 pi, which
 * holds by the definition of |Omega|. */
static void test_cells_by_monte_carlo(void **state)
{
    (void)state;
    assert_rel(tu_chi2_pvalue(20, 2), exp(-10), 1e-13); /* two degrees of freedom: exp(-x/2) */
    uint64_t rng = 12345;
    for (size_t t = 0; t < 2 * sizeof sizes / sizeof *sizes; t++) {
        pp_dirs d;
        ppb_err err;
        int n = sizes[t % (sizeof sizes / sizeof *sizes)], m = 2 * n;
        assert_int_equal(t < sizeof sizes / sizeof *sizes ? pp_dirs_make(n, &d, &err)
                                                          : pp_dirs_make_antipodal(n, &d, &err),
                         0);
        long total = 500L * m, *count = calloc((size_t)m, sizeof *count);
        double *sum = calloc((size_t)m, sizeof *sum), *sum2 = calloc((size_t)m, sizeof *sum2);
        assert_true(count && sum && sum2);
        for (long k = 0; k < total; k++) {
            double w[3], norm = 0;
            for (int c = 0; c < 3; c++) {
                w[c] = sqrt(-2 * log(uniform01(&rng))) * cos(2 * PI * uniform01(&rng));
                norm += w[c] * w[c];
            }
            for (int c = 0; c < 3; c++)
                w[c] /= sqrt(norm);
            int i = pp_dirs_cell_of(&d, w);
            assert_in_range(i, 0, m - 1);
            count[i]++, sum[i] += w[1], sum2[i] += w[1] * w[1];
        }
        double e = (double)total / m, chi2 = 0, z2 = 0;
        for (int i = 0; i < m; i++) {
            chi2 += (count[i] - e) * (count[i] - e) / e;
            double mean = sum[i] / count[i];
            double var = (sum2[i] - count[i] * mean * mean) / (count[i] - 1);
            z2 += (mean - d.k[i]) * (mean - d.k[i]) / (var / count[i]);
        }
        double p_count = tu_chi2_pvalue(chi2, m - 1), p_k = tu_chi2_pvalue(z2, m);
        if (!(p_count > 1e-4 && p_k > 1e-4))
            fail_msg("N = %d%s: cell counts chi^2 = %.1f (p = %.3g), mean cosines chi^2 = %.1f (p "
                     "= %.3g) over %d cells",
                     n, t < sizeof sizes / sizeof *sizes ? "" : " antipodal", chi2, p_count, z2,
                     p_k, m);
        free(count), free(sum), free(sum2);
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
        assert_close(wsum, d.solid, 1e-15);
        assert_close(mu / d.solid, d.k[i], 1e-12);
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
            assert_close(d.k[d.n + i], -d.k[i], 0.0);
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
            if (!(count == 1 || count % 2 == 0))
                fail_msg("N = %d: ring %d has %d cells, neither one nor even", sizes[t], r, count);
        }
        for (int i = 0; i < 2 * d.n; i++) {
            int a = pp_dirs_antipode(&d, i);
            assert_in_range(a, 0, 2 * d.n - 1);
            assert_int_not_equal(a < d.n, i < d.n);
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
        cmocka_unit_test(test_cell_areas_from_membership),
        cmocka_unit_test(test_polar_partition),
        cmocka_unit_test(test_graded_partition),
        cmocka_unit_test(test_cells_by_monte_carlo),
        cmocka_unit_test(test_mean_cosines_exact),
        cmocka_unit_test(test_mirror_symmetries),
        cmocka_unit_test(test_partition_is_antipodal),
        cmocka_unit_test(test_nodes_lie_in_their_cell),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
