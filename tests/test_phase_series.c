/* test_phase_series.c: the cell integrals of a truncated Legendre series phase function
 * (src/physics/phase.h, pp_phase_fn with nmom > 0; delta-M's retained function, reference:
 * Methods, `rte2d`). Expected values from the addition theorem, not from the code's product
 * Gauss: over whole rings (azimuth bands) only the m = 0 harmonics survive, so the sum of S over
 * ring r times ring r' is sum_l (2l + 1) chi_l / (4 pi) (2 pi)^2 I_l(r) I_l(r') and the sum of a
 * row F over ring r is sum_l (2l + 1) chi_l / (4 pi) 2 pi P_l(mu_w) I_l(r), with I_l the
 * closed-form integral of P_l over the ring's mu range, (P_{l+1} - P_{l-1}) / (2l + 1). Also:
 * the Legendre moments of the series (a fine Simpson rule in cos against chi_l), and at g = 0.9
 * with L = 16, where the series dips below 0, that no entry is negative while rows still sum
 * to 1 and S stays symmetric. */
#include "testutil.h"

#include "legendre_rings.h"

#include <math.h>

#include "physics/phase.h"

#define PI 3.14159265358979323846

/* delta-M's retained moments (chi_l - f) / (1 - f), chi_l = g^l, f = g^L, l < L. */
static pp_phase_fn deltam_series(double g, int L)
{
    pp_phase_fn ph = {0.0, L, {0}};
    double f = pow(g, L);
    for (int l = 0; l < L; l++)
        ph.chi[l] = (pow(g, l) - f) / (1.0 - f);
    return ph;
}

/* The mu range of ring r, up (sign 1) or down (-1). */
static void ring_range(const pp_dirs *d, int r, int sign, double *a, double *b)
{
    double lo = d->mu_edge[r + 1], hi = d->mu_edge[r];
    *a = sign > 0 ? lo : -hi, *b = sign > 0 ? hi : -lo;
}

/* The series' moments 2 pi integral p P_l d cos = chi_l, by composite Simpson with 2e4 panels
 * (a polynomial of degree 2L - 2 <= 62: the rule's error is far below the tolerance). */
static void test_series_moments(void **state)
{
    (void)state;
    pp_phase_fn ph = deltam_series(0.9, 16);
    int n = 20000;
    double h = 2.0 / n, mom[16] = {0}, P[17];
    for (int i = 0; i <= n; i++) {
        double c = -1.0 + i * h, wt = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
        double p = pp_phase_eval(&ph, c);
        lr_legendre(c, 15, P);
        for (int l = 0; l < 16; l++)
            mom[l] += wt * 2 * PI * p * P[l] * h / 3;
    }
    for (int l = 0; l < 16; l++)
        assert_close(mom[l], ph.chi[l], 1e-10);
    /* delta-M keeps the transport coefficient: (1 - f)(1 - chi_1) = 1 - g */
    assert_close((1.0 - pow(0.9, 16)) * (1.0 - mom[1]), 1.0 - 0.9, 1e-10);
}

/* The 2n x 2n cell matrix of the phase function ph on the default partition of n cells per
 * hemisphere (d is built; the caller frees both), with the share its clipping moved in
 * *clipped. */
static double *series_matrix(const pp_phase_fn *ph, int n, pp_dirs *d, double *clipped)
{
    ppb_err err;
    int m = 2 * n;
    assert_int_equal(pp_dirs_make(n, d, &err), 0);
    double *P = malloc(sizeof(double) * m * m);
    assert_non_null(P);
    *clipped = -1.0;
    assert_int_equal(pp_phase_matrix_fn(d, ph, P, clipped, &err), 0);
    return P;
}

/* Ring-pair sums of S against the addition theorem, every pair of rings, up-up and up-down
 * blocks; series non-negative (g = 0.8, L = 11 and 16: the least value of p 8e-4 / sr), so
 * nothing is clipped and the sums are the series' own. */
static void test_ring_sums_match_addition_theorem(void **state)
{
    (void)state;
    const int ns[] = {41, 128};
    const int Ls[] = {11, 16};
    for (int t = 0; t < 2; t++) {
        int n = ns[t], m = 2 * n, L = Ls[t];
        pp_phase_fn ph = deltam_series(0.8, L);
        pp_dirs d;
        double clipped;
        double *P = series_matrix(&ph, n, &d, &clipped);
        assert_close(clipped, 0.0, 0.0);
        double Ir[64][PP_SERIES_MAX], Is[64][PP_SERIES_MAX], a, b;
        assert_true(d.nrings <= 64);
        for (int r = 0; r < d.nrings; r++) {
            ring_range(&d, r, 1, &a, &b);
            assert_int_equal(lr_ring_integrals(a, b, L, Ir[r]), 0);
            ring_range(&d, r, -1, &a, &b);
            assert_int_equal(lr_ring_integrals(a, b, L, Is[r]), 0);
        }
        double worst = 0.0;
        for (int r = 0; r < d.nrings; r++)
            for (int s = 0; s < d.nrings; s++)
                for (int down = 0; down < 2; down++) {
                    double got = 0.0, want = 0.0;
                    for (int i = d.ring_first[r]; i < d.ring_first[r + 1]; i++)
                        for (int j = d.ring_first[s]; j < d.ring_first[s + 1]; j++)
                            got += P[i * m + (down ? n : 0) + j] * d.solid;
                    for (int l = 0; l < L; l++)
                        want += (2.0 * l + 1.0) * ph.chi[l] / (4 * PI) * 4 * PI * PI * Ir[r][l] *
                                (down ? Is[s][l] : Ir[s][l]);
                    worst = fmax(worst, fabs(got - want));
                    /* against the ring pair's solid angles (2 pi / N times its counts) */
                    assert_close(got, want, 1e-10 * d.solid);
                }
        print_message("N = %d, L = %d: largest ring-pair difference %.3g sr^2\n", n, L, worst);
        free(P);
        pp_dirs_free(&d);
    }
}

/* Ring sums of a row F(w) against the addition theorem, for directions inside cells, on a cell
 * edge and at the pole. */
static void test_row_ring_sums(void **state)
{
    (void)state;
    int n = 128, m = 2 * n, L = 16;
    pp_phase_fn ph = deltam_series(0.8, L);
    pp_dirs d;
    ppb_err err;
    assert_int_equal(pp_dirs_make(n, &d, &err), 0);
    double *F = malloc(sizeof(double) * m);
    assert_non_null(F);
    const double ws[][3] = {{0.0, 1.0, 0.0}, {0.6, 0.8, 0.0}, {0.3, -0.5, 0.8124038404635961}};
    for (int k = 0; k < 3; k++) {
        double clipped = -1.0, Pw[PP_SERIES_MAX + 1], I[PP_SERIES_MAX], a, b;
        assert_int_equal(pp_phase_row_fn(&d, &ph, ws[k], F, &clipped, &err), 0);
        assert_close(clipped, 0.0, 0.0);
        lr_legendre(ws[k][1], L, Pw);
        for (int r = 0; r < d.nrings; r++)
            for (int sign = 1; sign >= -1; sign -= 2) {
                ring_range(&d, r, sign, &a, &b);
                assert_int_equal(lr_ring_integrals(a, b, L, I), 0);
                double got = 0.0, want = 0.0;
                for (int i = d.ring_first[r]; i < d.ring_first[r + 1]; i++)
                    got += F[(sign > 0 ? 0 : n) + i];
                for (int l = 0; l < L; l++)
                    want += (2.0 * l + 1.0) * ph.chi[l] / (4 * PI) * 2 * PI * Pw[l] * I[l];
                assert_close(got, want, 1e-10);
            }
    }
    free(F);
    pp_dirs_free(&d);
}

/* g = 0.9, L = 16 (the realistic case's default truncation on 128 cells): the series is
 * negative near the backward direction, so some cell integrals are; they are set to 0 and the
 * share reported. Checked: no negative entry, S symmetric, rows sum to 1 (conservation,
 * phase.h), the share moved small (the series' negative mass, 9.2e-4 of 1 by a fine rule in
 * cos, bounds what a row can lose) and positive. */
static void test_negative_lobes_clipped(void **state)
{
    (void)state;
    int n = 128, m = 2 * n;
    pp_phase_fn ph = deltam_series(0.9, 16);
    pp_dirs d;
    ppb_err err;
    double clipped;
    double *P = series_matrix(&ph, n, &d, &clipped);
    assert_true(clipped > 0.0 && clipped < 9.3e-4);
    for (int i = 0; i < m; i++) {
        double row = 0.0;
        for (int j = 0; j < m; j++) {
            assert_true(P[i * m + j] >= 0.0);
            assert_close(P[i * m + j], P[j * m + i], 1e-15);
            row += P[i * m + j];
        }
        assert_close(row, 1.0, 1e-12);
    }
    double *F = malloc(sizeof(double) * m), w[3] = {0.0, 1.0, 0.0}, row = 0.0;
    assert_non_null(F);
    assert_int_equal(pp_phase_row_fn(&d, &ph, w, F, &clipped, &err), 0);
    assert_true(clipped > 0.0 && clipped < 9.3e-4);
    for (int j = 0; j < m; j++)
        assert_true(F[j] >= 0.0), row += F[j];
    assert_close(row, 1.0, 1e-12);
    free(F);
    free(P);
    pp_dirs_free(&d);
}

/* Bad series refused with a message: chi_0 must be 1, |chi_l| <= 1, 1 .. PP_SERIES_MAX moments. */
static void test_bad_series_refused(void **state)
{
    (void)state;
    pp_dirs d;
    ppb_err err;
    assert_int_equal(pp_dirs_make(4, &d, &err), 0);
    double F[8], w[3] = {0.0, 1.0, 0.0};
    pp_phase_fn ph = deltam_series(0.5, 4);
    ph.chi[0] = 0.9;
    assert_int_equal(pp_phase_row_fn(&d, &ph, w, F, NULL, &err), -1);
    ph = deltam_series(0.5, 4);
    ph.chi[2] = 1.5;
    assert_int_equal(pp_phase_row_fn(&d, &ph, w, F, NULL, &err), -1);
    ph.nmom = PP_SERIES_MAX + 1;
    assert_int_equal(pp_phase_row_fn(&d, &ph, w, F, NULL, &err), -1);
    pp_dirs_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_series_moments),
        cmocka_unit_test(test_ring_sums_match_addition_theorem),
        cmocka_unit_test(test_row_ring_sums),
        cmocka_unit_test(test_negative_lobes_clipped),
        cmocka_unit_test(test_bad_series_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
