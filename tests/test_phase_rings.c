/* test_phase_rings.c: the HG cell-pair integrals of the polar-ring partition (src/physics/
 * phase_rings.h, pp_dirs_make_collars with collars > 0). Expected values from the addition
 * theorem, not from the code's azimuthal convolution: over whole rings only the m = 0 harmonics
 * survive, so the sum of S over ring r times ring r' is
 *   sum_l (2l + 1) g^l / (4 pi) (2 pi)^2 I_l(r) I_l(r'),
 * I_l the closed-form integral of P_l over the ring's mu range, (P_{l+1} - P_{l-1}) / (2l + 1);
 * HG's Legendre moments are g^l exactly, and the series is summed until g^l < 1e-18. The
 * partitions are the ones the slab solver's totals need (334 cells, 55 and 79 collars, snapped
 * at n = 1.5's critical cosine): thin rings whose cells reach a radian in azimuth. */
#include "testutil.h"

#include "legendre_rings.h"

#include <math.h>
#include <stdlib.h>

#include "physics/directions.h"
#include "physics/phase.h"

#define PI 3.14159265358979323846

/* Largest ring-pair difference of the blocks against the addition theorem, relative (HG is
 * positive everywhere). */
static double ring_sum_error(int n, int collars, double mu_snap, double g, int antipodal)
{
    ppb_err err;
    pp_dirs d;
    assert_int_equal(pp_dirs_make_collars(n, antipodal, mu_snap, collars, &d, &err), 0);
    assert_true(d.polar);
    double *Sa = malloc(sizeof(double) * n * n), *Sb = malloc(sizeof(double) * n * n);
    assert_true(Sa && Sb);
    assert_int_equal(pp_phase_blocks(&d, g, Sa, Sb, &err), 0);
    int L = (int)ceil(log(1e-18) / log(fabs(g))), R = d.nrings;
    double *Iu = malloc(sizeof(double) * R * L), *Id = malloc(sizeof(double) * R * L);
    assert_true(Iu && Id);
    for (int r = 0; r < R; r++) {
        assert_int_equal(lr_ring_integrals(d.mu_edge[r + 1], d.mu_edge[r], L, Iu + (size_t)r * L),
                         0);
        assert_int_equal(lr_ring_integrals(-d.mu_edge[r], -d.mu_edge[r + 1], L, Id + (size_t)r * L),
                         0);
    }
    double worst = 0.0;
    for (int r = 0; r < R; r++)
        for (int s = 0; s < R; s++)
            for (int down = 0; down < 2; down++) {
                double got = 0.0, want = 0.0, gl = 1.0;
                for (int i = d.ring_first[r]; i < d.ring_first[r + 1]; i++)
                    for (int j = d.ring_first[s]; j < d.ring_first[s + 1]; j++)
                        got += (down ? Sb : Sa)[(size_t)i * n + j];
                const double *Ir = Iu + (size_t)r * L, *Is = (down ? Id : Iu) + (size_t)s * L;
                for (int l = 0; l < L; l++, gl *= g)
                    want += (2.0 * l + 1.0) * gl * PI * Ir[l] * Is[l];
                if (fabs(got - want) / want > worst && getenv("RINGS_DEBUG"))
                    print_message("r %d s %d down %d: got %.12e want %.12e rel %.2e\n", r, s, down,
                                  got, want, (got - want) / want);
                worst = fmax(worst, fabs(got - want) / want);
            }
    free(Sa), free(Sb), free(Iu), free(Id);
    pp_dirs_free(&d);
    return worst;
}

/* g 0.95 and 0.7 on both partitions, against 1e-8, the relative error phase.c's product rule
 * aims at (PHASE_TOL); measured 1.5e-9 at g 0.95. */
static void test_ring_sums_match_addition_theorem(void **state)
{
    (void)state;
    double mu_c = sqrt(1.0 - 1.0 / (1.5 * 1.5));
    const int collars[] = {55, 79};
    const double gs[] = {0.95, 0.7};
    for (int c = 0; c < 2; c++)
        for (int k = 0; k < 2; k++) {
            double e = ring_sum_error(334, collars[c], mu_c, gs[k], 0);
            print_message("334 cells, %d collars, g %.2f: largest relative ring-pair error %.2e\n",
                          collars[c], gs[k], e);
            assert_true(e < 1e-8);
        }
}

/* A backward peak (g -0.9) on the antipodal polar partition (phase.h: a column permutation of
 * the |g| blocks) and integrated directly on the partition without antipodes (N even, so the
 * first collar is odd), and no snap, odd N. */
static void test_ring_sums_backward_and_odd(void **state)
{
    (void)state;
    double e1 = ring_sum_error(334, 40, 0.0, -0.9, 1), e2 = ring_sum_error(334, 40, 0.0, -0.7, 0);
    double e3 = ring_sum_error(201, 30, 0.5, 0.9, 0);
    print_message("g -0.9 antipodal: %.2e; g -0.7 direct: %.2e; 201 cells, 30 collars, g 0.9: "
                  "%.2e\n",
                  e1, e2, e3);
    assert_true(e1 < 1e-8);
    assert_true(e2 < 1e-8);
    assert_true(e3 < 1e-8);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ring_sums_match_addition_theorem),
        cmocka_unit_test(test_ring_sums_backward_and_odd),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
