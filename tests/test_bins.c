/* test_bins.c: the deterministic methods' bin samples and weights (kernels/ppb_bin_samples.h,
 * ppb_bin_sample_u and ppb_bin_sample_dir; docs/reference.md, Bins) as a quadrature of a bin's
 * average, against analytic integrals and a composite Simpson rule computed here: the weights
 * integrate the bin's projected solid angle and its solid angle, and the last theta row (next to
 * the tangent plane) integrates the grazing factors of the exit radiance, mu^k and the Fresnel
 * transmittance 1 - F(mu), far better than the midpoints, as the first row (next to the normal)
 * does sin(theta) and the forward peak of the once-scattered light at normal light. */
#include "testutil.h"

#include "kernels/ppb_bin_samples.h"
#include "kernels/ppb_fresnel.h"

/* The n x n samples of bin (it, ip) of an ntheta x nphi grid on surface surf: the sum of
 * weight x f(mu) / n^2, the bin's average of f under the samples (the methods' bin value). */
static double sample_average(int surf, int it, int ip, int n, int ntheta, int nphi,
                             double (*f)(double mu, const void *arg), const void *arg)
{
    double sum = 0.0;
    int bin = ppb_bin_index(it, ip, nphi);
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++) {
            double w[3];
            double wk = ppb_bin_sample_dir(surf, bin, a, b, n, ntheta, nphi, &w[0], &w[1], &w[2]);
            double mu = w[0] * ppb_normal_x(surf) + w[1] * ppb_normal_y(surf);
            sum += wk * f(mu, arg);
        }
    return sum / (n * n);
}

/* The same average on the midpoints of the n x n grid in (sin^2 theta, phi), weight 1 (the
 * sampling every method used before the last row was graded). Only mu matters here, so phi
 * drops out. */
static double midpoint_average(int it, int n, int ntheta, double (*f)(double mu, const void *arg),
                               const void *arg)
{
    double sum = 0.0;
    for (int a = 0; a < n; a++)
        sum += f(sqrt(1.0 - (it + (a + 0.5) / n) / ntheta), arg);
    return sum / n;
}

/* The last row's exact average of f(mu) over its projected solid angle, uniform in
 * s = sin^2 theta over [s0, 1], s0 = (ntheta - 1) / ntheta: with s = 1 - (1 - s0) (1 - t)^2,
 * mu = (1 - t) sqrt(1 - s0), the average is the integral over t in [0, 1] of f(mu) 2 (1 - t),
 * smooth in t; composite Simpson on 20000 panels gives it to rounding (error h^4 f'''' / 180).
 */
static double simpson_last_row(int ntheta, double (*f)(double mu, const void *arg), const void *arg)
{
    const int m = 20000; /* panels, even */
    double s0 = (ntheta - 1.0) / ntheta, c = sqrt(1.0 - s0), h = 1.0 / m, sum = 0.0;
    for (int i = 0; i <= m; i++) {
        double t = i * h, wgt = (i == 0 || i == m) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += wgt * f((1.0 - t) * c, arg) * 2.0 * (1.0 - t);
    }
    return sum * h / 3.0;
}

static double mu_power(double mu, const void *arg)
{
    return pow(mu, *(const double *)arg);
}

/* The air-side exit's Fresnel transmittance at relative index n (ppb_fresnel, the n^2 law's
 * 1 - F, reference: Medium): falls to 0 linearly in mu at grazing. */
static double transmittance(double mu, const void *arg)
{
    return 1.0 - ppb_fresnel(mu, *(const double *)arg);
}

/* The exit radiance's shape near grazing at n = 1.4: (1 - F(mu)) (a + b mu), a + b mu the inside
 * radiance's rise (the half-space's H-function is near linear there). */
static double exit_shape(double mu, const void *arg)
{
    return transmittance(mu, arg) * (1.0 + 2.0 * mu);
}

/* Every row's weights sum to n (so a bin's n x n weights to n^2: the bin's projected solid angle
 * pi / (ntheta nphi) exactly, reference: Bins), every sample lies in its own bin (ppb_dir_bin, the
 * Monte Carlo's binning), and every row but the first and the last keeps the midpoints with
 * weight 1. */
static void test_weights_and_bins(void **state)
{
    (void)state;
    const int ns[] = {1, 2, 3, 4, 5, 8, 16, 64}, nts[] = {1, 3, 8};
    for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++)
        for (size_t j = 0; j < sizeof nts / sizeof nts[0]; j++) {
            int n = ns[i], ntheta = nts[j], nphi = 5;
            for (int it = 0; it < ntheta; it++) {
                double sum = 0.0;
                for (int a = 0; a < n; a++) {
                    double u, wk = ppb_bin_sample_u(it, a, n, ntheta, &u);
                    assert_true(u > 0.0 && u < 1.0 && wk > 0.0);
                    if (it > 0 && it < ntheta - 1) {
                        assert_true(u == (a + 0.5) / n && wk == 1.0);
                    }
                    sum += wk;
                }
                assert_close(sum, n, 1e-12 * n);
            }
            for (int surf = 0; surf < 4; surf++)
                for (int bin = 0; bin < ntheta * nphi; bin++)
                    for (int a = 0; a < n; a++)
                        for (int b = 0; b < n; b++) {
                            double w[3];
                            ppb_bin_sample_dir(surf, bin, a, b, n, ntheta, nphi, &w[0], &w[1],
                                               &w[2]);
                            assert_close(w[0] * w[0] + w[1] * w[1] + w[2] * w[2], 1.0, 1e-14);
                            assert_int_equal(ppb_dir_bin(surf, w[0], w[1], w[2], ntheta, nphi),
                                             bin);
                        }
        }
}

static double inv_mu(double mu, const void *arg)
{
    (void)arg;
    return 1.0 / mu;
}

/* The bin's solid angle: a sample stands for weight x pi / (ntheta nphi n^2) of projected solid
 * angle, i.e. that / mu of solid angle, so sum of weight / mu x pi / (ntheta nphi n^2) must be
 * the bin's solid angle, analytically 2 (pi / nphi) (mu_lo - mu_hi) (both phi halves of the
 * folded bin; mu at the bin's sin^2 edges). In the last row 1 / mu is infinite at the tangent
 * plane, but (1 - t) in the graded rule's Jacobian cancels it: the rule is exact (to rounding),
 * where the midpoints are 15 % off at n = 4. The other rows keep the midpoints: within the
 * midpoint rule's bound (s1 - s0) h^2 max|f''| / 24 for f = (1 - s)^(-1/2) in s, h = (s1 - s0) /
 * n, max|f''| = (3/4) (1 - s1)^(-5/2) (scaled to the row's average). */
static void test_solid_angle(void **state)
{
    (void)state;
    const int ns[] = {1, 2, 4, 8, 64}, nts[] = {1, 4, 8};
    for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++)
        for (size_t j = 0; j < sizeof nts / sizeof nts[0]; j++) {
            int n = ns[i], ntheta = nts[j], nphi = 4;
            for (int it = 0; it < ntheta; it++) {
                double s0 = (double)it / ntheta, s1 = (it + 1.0) / ntheta;
                double omega = 2.0 * (PPB_PI / nphi) * (sqrt(1.0 - s0) - sqrt(1.0 - s1));
                double proj = ppb_bin_proj_solid_angle(ntheta, nphi);
                double got = proj * sample_average(PPB_S2, it, 1, n, ntheta, nphi, inv_mu, NULL);
                if (it == 0 && ntheta > 1) {
                    /* graded toward the normal, where 1 / mu is smooth: a Gauss rule in t, whose
                     * error falls faster than the midpoints' bound (measured, 4 rows: 1.06e-3
                     * against the bound 1.00e-3 at n = 2, 7.3e-7 against 2.5e-4 at n = 4) */
                    double h = (s1 - s0) / n, f2 = 0.75 * pow(1.0 - s1, -2.5);
                    double e = fabs(got / proj - omega / proj);
                    if (n == 2 || n == 4)
                        printf("1/mu over the first of %d rows, n = %d: graded %.2e, midpoint "
                               "bound %.2e\n",
                               ntheta, n, e, h * h * f2 / 24.0);
                    if (n >= 4)
                        assert_true(e <= h * h * f2 / 24.0);
                } else if (it == ntheta - 1) {
                    assert_rel(got, omega, 1e-12);
                    double mid = proj * midpoint_average(it, n, ntheta, inv_mu, NULL);
                    if (n == 4)
                        assert_true(fabs(mid / omega - 1.0) > 0.1);
                } else {
                    double h = (s1 - s0) / n, f2 = 0.75 * pow(1.0 - s1, -2.5);
                    double bound = h * h * f2 / 24.0; /* on the row's average of f */
                    assert_close(got / proj, omega / proj, bound * (1.0 + 1e-12));
                }
            }
        }
}

/* mu^k over the last row, analytic: the average over s in [s0, 1] of (1 - s)^(k/2) is
 * (1 - s0)^(k/2) / (k/2 + 1). In t the integrand is (1 - t)^(k+1) times constants, a polynomial
 * of degree k + 1, which the n-point Gauss-Legendre rule integrates exactly for k + 1 <= 2n - 1;
 * k = 1 is the Fresnel transmittance's and the half-space radiance's grazing slope, where the
 * midpoints' error goes as n^-1.5 (the 1.1-1.4 % of docs/reference.md, Bins, at 4 x 4). Also
 * k = 1/2 (not a polynomial in t: the graded rule is not exact, but must still beat the
 * midpoints). */
static void test_mu_powers(void **state)
{
    (void)state;
    const int ns[] = {1, 2, 3, 4, 8}, ntheta = 8;
    double s0 = (ntheta - 1.0) / ntheta;
    for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++) {
        int n = ns[i];
        for (int k2 = 1; k2 <= 2 * (2 * n - 2); k2++) { /* k = k2 / 2 */
            double k = 0.5 * k2;
            double exact = pow(1.0 - s0, 0.5 * k) / (0.5 * k + 1.0);
            double got = sample_average(PPB_S1, ntheta - 1, 0, n, ntheta, 4, mu_power, &k);
            double mid = midpoint_average(ntheta - 1, n, ntheta, mu_power, &k);
            double eg = fabs(got / exact - 1.0), em = fabs(mid / exact - 1.0);
            if (k2 % 2 == 0) /* integer k <= 2n - 2: exact */
                assert_rel(got, exact, 1e-13);
            else
                assert_true(eg < em);
            if (k2 == 2)
                printf("mu^1 over the last of 8 rows, n = %d: graded %.2e, midpoints %.2e\n", n, eg,
                       em);
            if (k2 == 2 && n == 4)
                assert_true(em > 5e-3); /* the error this is for */
        }
    }
}

/* The Fresnel transmittance 1 - F(mu) at n = 1.4 and the exit shape (1 - F)(1 + 2 mu) over the
 * last row (8 rows; the study's default), against composite Simpson in t (above). Measured, the
 * graded samples' and the midpoints' relative errors: 1 - F 6.8e-3 and 3.5e-2 at 2 x 2, 3.4e-6
 * and 1.5e-2 at 4 x 4 (the 1.1-1.4 % the methods' last row was high by), 3e-13 and 6.0e-3 at
 * 8 x 8; the exit shape 2.0e-3 and 3.0e-2, 1.7e-7 and 1.2e-2, 1e-14 and 4.5e-3. The graded
 * samples must be 4 times closer at 2 x 2, 1000 times from 4 x 4 on, and within 1e-4 at 4 x 4
 * (a tenth of the 1e-3 the slab tests hold ppslab and rte2d to). */
static void test_fresnel_grazing(void **state)
{
    (void)state;
    const int ntheta = 8;
    double nrel = 1.4;
    double (*fs[])(double, const void *) = {transmittance, exit_shape};
    double one = 1.0; /* the Simpson rule itself, on mu^1 against its closed form (above) */
    assert_rel(simpson_last_row(ntheta, mu_power, &one), sqrt(1.0 / ntheta) / 1.5, 1e-13);
    for (int fi = 0; fi < 2; fi++) {
        double exact = simpson_last_row(ntheta, fs[fi], &nrel);
        for (int n = 2; n <= 8; n *= 2) {
            double got = sample_average(PPB_S1, ntheta - 1, 2, n, ntheta, 4, fs[fi], &nrel);
            double mid = midpoint_average(ntheta - 1, n, ntheta, fs[fi], &nrel);
            double eg = fabs(got / exact - 1.0), em = fabs(mid / exact - 1.0);
            printf("%s over the last of 8 rows at n = 1.4, %d x %d: graded %.2e, midpoints "
                   "%.2e\n",
                   fi ? "(1 - F)(1 + 2 mu)" : "1 - F", n, n, eg, em);
            assert_true(eg * (n == 2 ? 4.0 : 1000.0) < em);
            if (n == 4)
                assert_le(eg, 1e-4);
        }
    }
}

/* The first row's exact average of f(mu) over its projected solid angle, uniform in
 * s = sin^2 theta over [0, S], S = 1 / ntheta: with s = S t^4 (ds = 4 S t^3 dt, which spreads a
 * peak at s = 0 over t), composite Simpson on 20000 panels in t. */
static double simpson_first_row(int ntheta, double (*f)(double mu, const void *arg),
                                const void *arg)
{
    const int m = 20000; /* panels, even */
    double S = 1.0 / ntheta, h = 1.0 / m, sum = 0.0;
    for (int i = 0; i <= m; i++) {
        double t = i * h, wgt = (i == 0 || i == m) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += wgt * f(sqrt(1.0 - S * t * t * t * t), arg) * 4.0 * t * t * t;
    }
    return sum * h / 3.0;
}

static double sin_theta(double mu, const void *arg)
{
    (void)arg;
    return sqrt(1.0 - mu * mu);
}

/* HG's forward peak as the transmitted once-scattered light leaves at normal light (the
 * scattering angle is the exit angle): p(mu) per steradian. */
static double hg_peak(double mu, const void *arg)
{
    return ppb_hg_phase(*(const double *)arg, mu);
}

/* The first row, next to the normal (8 rows): sin(theta), the part of a smooth field that turns
 * with phi, is linear in t under the grading, so its average (2/3) sqrt(S) is exact from n = 2
 * on (analytic); and HG's peak at normal light, against composite Simpson (above). Measured,
 * graded and midpoints at 4 x 4: g = 0.8 4e-4 and 2.3e-2, 0.9 1.0e-2 and 1.7e-1, 0.95 2.9e-2 and
 * 4.7e-1; at 8 x 8, 0.95: 8e-4 and 2.8e-1 (the same numbers as an independent Python check of
 * the rule). Bounds: 1.5 x the measured error, and the midpoints at least 10 x worse. */
static void test_first_row_peak(void **state)
{
    (void)state;
    const int ntheta = 8;
    double S = 1.0 / ntheta;
    for (int n = 2; n <= 8; n *= 2) {
        double got = sample_average(PPB_S2, 0, 1, n, ntheta, 4, sin_theta, NULL);
        assert_rel(got, 2.0 / 3.0 * sqrt(S), 1e-13);
    }
    assert_rel(simpson_first_row(ntheta, sin_theta, NULL), 2.0 / 3.0 * sqrt(S), 1e-12);
    const struct {
        double g;
        int n;
        double bound;
    } cases[] = {{0.8, 4, 6e-4}, {0.9, 4, 1.5e-2}, {0.95, 4, 4.4e-2}, {0.95, 8, 1.2e-3}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double g = cases[i].g;
        int n = cases[i].n;
        double exact = simpson_first_row(ntheta, hg_peak, &g);
        double got = sample_average(PPB_S2, 0, 3, n, ntheta, 4, hg_peak, &g);
        double mid = midpoint_average(0, n, ntheta, hg_peak, &g);
        double eg = fabs(got / exact - 1.0), em = fabs(mid / exact - 1.0);
        printf("HG peak (g %.2f) over the first of 8 rows, %d x %d: graded %.2e, midpoints %.2e\n",
               g, n, n, eg, em);
        assert_le(eg, cases[i].bound);
        assert_true(10.0 * eg < em);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_weights_and_bins), cmocka_unit_test(test_solid_angle),
        cmocka_unit_test(test_mu_powers),        cmocka_unit_test(test_fresnel_grazing),
        cmocka_unit_test(test_first_row_peak),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
