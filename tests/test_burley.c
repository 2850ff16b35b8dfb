/* test_burley.c: the `burley` method (src/methods/burley/; reference: Methods, `burley`):
 * Christensen & Burley 2015's normalized diffusion profile. K0 against Abramowitz & Stegun's
 * tables, the profile's plane integral against its closed form, the line kernel (2 K0) against
 * direct quadrature of the 3-D profile along z, the strip quadrature against the closed-form
 * plane integrals and its convergence in [burley] samples, the scaling factor s(A) of Eq. 5 and
 * 6, A against Chandrasekhar's H-function, slab mode's closed forms, the method on every study
 * config (finite, non-negative, energy within the profile's bounds) and burley+ss = burley + ss
 * cell by cell. */
#include "testutil.h"
#include "study_cases.h"
#include "profileutil.h"

#include <math.h>

#include "base/quadrature.h"
#include "kernels/ppb_fresnel.h"
#include "methods/burley/burley_profile.h"
#include "methods/burley/method_burley.h"
#include "methods/registry.h"
#include "model/config.h"

static void test_k0_tables(void **state)
{
    (void)state;
    /* Abramowitz & Stegun Table 9.8 tabulates e^x K0(x) to 10 digits (x = 1: 1.1444630798,
     * x = 2: 0.8415682151, x = 5: 0.5478075643, x = 10: 0.3916319344, x = 20: 0.2785448767);
     * the values here are K0 itself to 17 digits, from the ascending series A&S 9.6.13 summed in
     * 140-digit decimal arithmetic (python decimal, separately), which reproduce the table's
     * digits. They cover each of the three branches and both switch points (2 and 20). */
    static const double table[][2] = {
        {1e-6, 1.39314420736264194e+1},   {0.1, 2.42706902470201661e+0},
        {0.5, 9.24419071227665862e-1},    {1.0, 4.21024438240708333e-1},
        {1.5, 2.13805562647525737e-1},    {1.999, 1.14033830589232924e-1},
        {2.0, 1.13893872749533436e-1},    {2.001, 1.13754098736684612e-1},
        {2.5, 6.23475532003661860e-2},    {3.0, 3.47395043862792481e-2},
        {5.0, 3.69109833404259427e-3},    {10.0, 1.77800623161676518e-5},
        {19.99, 5.80037120048621754e-10}, {20.0, 5.74123781533652429e-10},
        {20.01, 5.68270797457241064e-10}, {30.0, 2.13247749646305637e-14},
        {50.0, 3.41016774978949551e-23}};
    double worst = 0;
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
        double k = ppb_bessel_k0(table[i][0]);
        worst = fmax(worst, fabs(k / table[i][1] - 1));
        assert_rel(k, table[i][1], 1e-10);
    }
    print_message("K0: largest relative error over the table %.2e\n", worst);
    assert_lt(worst, 1e-14);
    /* The table's e^x K0(x) at its printed 10 digits. */
    assert_rel(exp(1.0) * ppb_bessel_k0(1.0), 1.1444630798, 1e-10);
    assert_rel(exp(2.0) * ppb_bessel_k0(2.0), 0.8415682151, 1e-10);
    assert_rel(exp(5.0) * ppb_bessel_k0(5.0), 0.5478075643, 1e-10);
    assert_rel(exp(10.0) * ppb_bessel_k0(10.0), 0.3916319344, 1e-10);
    assert_true(isinf(ppb_bessel_k0(0.0)));
    assert_close(ppb_bessel_k0(INFINITY), 0.0, 0.0);
    assert_close(ppb_bessel_k0(800.0), 0.0, 1e-300);
}

static void test_k1_tables(void **state)
{
    (void)state;
    /* K1 at the same points, 18 digits from mpmath's besselk(1, x) at 30 digits (pip install
     * mpmath; an independent arbitrary-precision implementation): each branch and both switch
     * points (2 and 20). */
    static const double table[][2] = {
        {1e-6, 999999.999992784324},      {0.1, 9.85384478087060557},
        {0.5, 1.65644112000330089},       {1.0, 0.601907230197234575},
        {1.5, 0.277387800456843816},      {1.999, 0.140049842077109663},
        {2.0, 0.139865881816522427},      {2.001, 0.139682188301767555},
        {2.5, 0.0738908163477470636},     {3.0, 0.0401564311281941844},
        {5.0, 0.00404461344545216421},    {10.0, 1.86487734538255846e-5},
        {19.99, 5.94372291903156996e-10}, {20.0, 5.88305796955703818e-10},
        {20.01, 5.82301297907223455e-10}, {30.0, 2.16773200189154942e-14},
        {50.0, 3.44410222671755561e-23}};
    double worst = 0;
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        worst = fmax(worst, fabs(ppb_bessel_k1(table[i][0]) / table[i][1] - 1));
    print_message("K1: largest relative error over the table %.2e\n", worst);
    assert_lt(worst, 1e-14);
    assert_true(isinf(ppb_bessel_k1(0.0)));
    assert_close(ppb_bessel_k1(INFINITY), 0.0, 0.0);
}

static double ring(double r, const void *arg)
{
    return 2 * PPB_PI * r * ppb_burley_R(arg, r);
}

static void test_profile_plane_integral(void **state)
{
    (void)state;
    /* Eq. 3 is normalized: 2 pi int_0^inf R(r) r dr = A s / 4 (1/s + 3/s) = A (analytic), and
     * the CDF's closed form is its partial integral. */
    const double As[][2] = {{0.5, 1.0}, {0.9, 0.3}, {0.2, 4.0}, {1.0, 0.906}};
    for (int i = 0; i < 4; i++) {
        ppb_burley b = {As[i][0], As[i][1]};
        double total = pu_graded(ring, &b, 0, 200 / b.s, 0.25 / b.s);
        assert_rel(total, b.A, 1e-12);
        for (double r = 0.1; r < 10; r *= 3)
            assert_rel(pu_graded(ring, &b, 0, r / b.s, 0.25 / b.s),
                       b.A * ppb_burley_cdf(&b, r / b.s), 1e-12);
    }
}

typedef struct line_arg {
    const ppb_burley *b;
    double rho;
} line_arg;

static double along_z(double z, const void *arg)
{
    const line_arg *l = arg;
    return 2 * ppb_burley_R(l->b, sqrt(l->rho * l->rho + z * z)); /* both halves of the line */
}

static void test_line_kernel(void **state)
{
    (void)state;
    /* The line kernel A s (K0(s rho) + K0(s rho / 3)) / (4 pi) against the 3-D profile
     * integrated along z directly (graded Gauss-Legendre to z = 400 / s). */
    ppb_burley b = {0.6, 1.2};
    const double rho[] = {1e-3, 0.05, 0.3, 1.0, 3.0, 10.0};
    for (int i = 0; i < 6; i++) {
        line_arg l = {&b, rho[i]};
        double direct = pu_graded(along_z, &l, 0, 400 / b.s, fmax(0.1, rho[i]) / b.s);
        assert_rel(ppb_burley_line(&b, rho[i]), direct, 1e-11);
    }
}

static void test_strip_quadrature(void **state)
{
    (void)state;
    /* The strip integral against its closed forms: the whole line of entry points (u over
     * [-L, L], L far beyond the profile) gives the profile's plane integral: A at v = 0 (the
     * exit point on S1 itself, K0's log singularity in the integrand) and A (1 - cdf(|v|)) at
     * depth v (a plane at distance |v|). Convergence in nodes_per_d ([burley] samples): the
     * error at 1, 2, 4 and 16 nodes per d printed (panels of 10 nodes up to 10 d / samples
     * long; the graded panels near the exit point do not depend on it); at the default 16
     * every case within 1e-12. */
    const double As[][2] = {{0.5, 1.05}, {0.95, 0.35}, {0.3, 3.0}};
    const double v[] = {0.0, -1e-6, -0.01, -0.5, -3.0};
    const int nodes[] = {1, 2, 4, 16};
    for (int k = 0; k < 4; k++) {
        double worst = 0;
        for (int i = 0; i < 3; i++) {
            ppb_burley b = {As[i][0], As[i][1]};
            double L = 400 / b.s;
            for (int j = 0; j < 5; j++) {
                double exact = b.A * (1 - ppb_burley_cdf(&b, fabs(v[j])));
                double got = ppb_burley_strip(&b, -L, L, v[j], nodes[k]);
                worst = fmax(worst, fabs(got / exact - 1));
                /* the halves: symmetric in u, and additive at any cut */
                double left = ppb_burley_strip(&b, -L, 0.37, v[j], nodes[k]);
                double right = ppb_burley_strip(&b, 0.37, L, v[j], nodes[k]);
                worst = fmax(worst, fabs((left + right) / exact - 1));
            }
        }
        print_message("strip quadrature: %2d nodes per d: largest relative error %.2e\n", nodes[k],
                      worst);
        if (nodes[k] == 16)
            assert_lt(worst, 1e-12);
    }
}

static void test_shape_factor(void **state)
{
    (void)state;
    /* Eq. 5, s = 1.85 - A + 7 |A - 0.8|^3 (searchlight, mfp), and Eq. 6,
     * s = 1.9 - A + 3.5 (A - 0.8)^2 (diffuse surface transmission, mfp), at a few A: the
     * formula evaluated by hand (the paper prints its curves, not values). */
    assert_close(ppb_burley_shape_searchlight(0.8), 1.05, 1e-15);
    assert_close(ppb_burley_shape_searchlight(1.0), 0.906, 1e-15);
    assert_close(ppb_burley_shape_searchlight(0.0), 5.434, 1e-14);
    assert_close(ppb_burley_shape_searchlight(0.5), 1.539, 1e-14);
    assert_close(ppb_burley_shape_diffuse(0.8), 1.1, 1e-15);
    assert_close(ppb_burley_shape_diffuse(0.0), 4.14, 1e-14);
    /* Positive and falling over [0, 1]: every A gives a profile. */
    for (double A = 0; A < 1; A += 0.01) {
        assert_lt(0, ppb_burley_shape_searchlight(A + 0.01));
        assert_lt(ppb_burley_shape_searchlight(A + 0.01), ppb_burley_shape_searchlight(A));
    }
}

/* Chandrasekhar's H-function of isotropic scattering by iterating
 * 1/H(mu) = sqrt(1 - w) + (w/2) int_0^1 mu' H(mu') / (mu + mu') dmu' (Chandrasekhar 1960,
 * Ch. V), on 32 panels x 10 Gauss-Legendre nodes graded toward mu' = 0; the plane albedo of a
 * semi-infinite isotropic medium is then 1 - H(mu0) sqrt(1 - w) (Chandrasekhar 1960, Ch. VI). */
static double plane_albedo_isotropic(double w, double mu0)
{
    enum { P = 32, Q = 10, N = P * Q };
    double gx[Q], gw[Q], mu[N + 1], wt[N], H[N + 1];
    ppb_gauss_legendre(Q, gx, gw);
    for (int p = 0; p < P; p++) {
        double lo = p ? pow(2.0, p - P) : 0.0, hi = pow(2.0, p + 1 - P); /* [2^-32, 1] graded */
        for (int j = 0; j < Q; j++) {
            mu[p * Q + j] = 0.5 * (lo + hi) + 0.5 * (hi - lo) * gx[j];
            wt[p * Q + j] = 0.5 * (hi - lo) * gw[j];
        }
    }
    mu[N] = mu0;
    for (int i = 0; i <= N; i++)
        H[i] = 1.0;
    for (int it = 0; it < 2000; it++) {
        double change = 0;
        for (int i = 0; i <= N; i++) {
            double sum = 0;
            for (int k = 0; k < N; k++)
                sum += wt[k] * mu[k] * H[k] / (mu[i] + mu[k]);
            double h = 1.0 / (sqrt(1 - w) + 0.5 * w * sum);
            change = fmax(change, fabs(h - H[i]));
            H[i] = h;
        }
        if (change < 1e-15)
            break;
    }
    return 1 - H[N] * sqrt(1 - w);
}

static void test_albedo_exact(void **state)
{
    (void)state;
    /* A from the slab solver (every scattering order, semi-infinite) against Chandrasekhar's
     * plane albedo at g = 0, n = 1, for normal and oblique beams, at the default 334 direction
     * cells (extrapolated from 334 and 668). The solver's R alone falls like 1/cells (at albedo
     * 0.5 and normal light 4.9e-3 off at 64 cells, 6.7e-4 at 334, 2.3e-4 at 1000, 1.1e-4 at
     * 2000; at mu0 = 0.5 1.4e-3 at 334: measured, not asserted); 1 at albedo 1, 0 at 0; rising
     * with the albedo; at n = 1.4 below the n = 1 value (the boundary returns light inside,
     * where more is absorbed) and still in (0, 1). */
    ppb_err err;
    const double w[] = {0.5, 0.95, 0.99};
    const double mu0[] = {1.0, 0.5};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 2; j++) {
            double A, ref = plane_albedo_isotropic(w[i], mu0[j]);
            assert_int_equal(ppb_burley_albedo(w[i], 0.0, 1.0, mu0[j], 334, &A, &err), 0);
            print_message("A(albedo %.2f, mu0 %.1f): solver %.8f  H-function %.8f  (%.1e)\n", w[i],
                          mu0[j], A, ref, A / ref - 1);
            assert_rel(A, ref, 1e-4);
        }
    double A, prev = -1;
    assert_int_equal(ppb_burley_albedo(1.0, 0.5, 1.4, 1.0, 334, &A, &err), 0);
    assert_close(A, 1.0, 0.0);
    assert_int_equal(ppb_burley_albedo(0.0, 0.5, 1.4, 1.0, 334, &A, &err), 0);
    assert_close(A, 0.0, 0.0);
    for (double al = 0.1; al < 1; al += 0.2) {
        double A14;
        assert_int_equal(ppb_burley_albedo(al, 0.0, 1.0, 1.0, 64, &A, &err), 0);
        assert_int_equal(ppb_burley_albedo(al, 0.0, 1.4, 1.0, 64, &A14, &err), 0);
        assert_lt(prev, A);
        assert_lt(0, A14);
        assert_lt(A14, A);
        prev = A;
    }
}

/* A study config's totals against the bounds of test_study_configs. */
static void study_bounds(const char *name, ppb_run_ctx *ctx, const ppb_result *out)
{
    const ppb_config *cfg = ctx->cfg;
    const ppb_scene *sc = &cfg->scene;
    ppb_err err;
    double Amax = 0, smin = INFINITY, entry = pu_entry(sc);
    for (int side = 0; side < 2; side++) {
        double st, al, A;
        pu_side_medium(sc, side, &st, &al);
        assert_int_equal(ppb_burley_albedo(al, sc->g, sc->n, cos(sc->theta_deg * PPB_PI / 180),
                                           cfg->burley.directions, &A, &err),
                         0);
        Amax = fmax(Amax, A);
        smin = fmin(smin, ppb_burley_shape_searchlight(A) * st * (1 - al * sc->g));
    }
    ppb_burley far = {Amax, smin};
    double sum = out->totals.R + out->totals.T + out->totals.sides;
    print_message("%-24s A %.4f  R %.4f T %.4f sides %.4f  sum %.4f  ballistic %.4f\n", name, Amax,
                  out->totals.R, out->totals.T, out->totals.sides, sum, out->totals.ballistic);
    assert_le(out->totals.R, entry * Amax * (1 + 1e-12));
    assert_le(out->totals.T, entry * Amax * (1 - ppb_burley_cdf(&far, sc->height)) * (1 + 1e-12));
    assert_le(out->totals.sides, entry * Amax * (1 + 1e-12));
    assert_le(sum, 1 + 1e-3); /* the result check's energy bound (reference: Methods) */
}

static void test_study_configs(void **state)
{
    (void)state;
    /* burley on every study config (configs/study.list): every radiance finite and >= 0, and
     * the totals within the profile's bounds. For an entry point, S1 lies in the profile's
     * plane (at most A), S2 in the plane at distance H (at most A (1 - cdf(H))), each side in a
     * half plane through the entry point's normal line (at most A / 2); times the entering
     * 1 - F(theta_L), with A the largest and s the smallest of the tube's media. */
    pu_study_configs("burley", NULL, study_bounds);
}

/* 32 direction cells for A at the corners, in the method and in corner_bounds alike. */
static void coarse_directions(ppb_config *cfg)
{
    cfg->burley.directions = 32;
}

/* R at a corner of the robustness grid within (1 - F) A (test_extremes). */
static void corner_bounds(const pu_corner *c, ppb_run_ctx *ctx, const ppb_result *out)
{
    (void)ctx;
    ppb_err err;
    double A, mu = cos(c->theta * PPB_PI / 180);
    assert_int_equal(ppb_burley_albedo(c->albedo, c->g, c->n, mu, 32, &A, &err), 0);
    assert_between(A, 0, 1);
    assert_le(out->totals.R, A * (1 + 1e-12));
}

static void test_extremes(void **state)
{
    (void)state;
    /* The corners of the robustness grid (tests/test_robust.c's values): albedo 0 to 1, g
     * +-0.95, H from 1e-3 to 1e3, theta_L 0 and 89 deg, n 1 and 1.4, tube and slab: every cell
     * finite and >= 0, R within (1 - F) A, and the result checks of the method passed. */
    const double albedo[] = {0, 0.01, 0.5, 0.999, 1}, g[] = {-0.95, 0, 0.95},
                 height[] = {1e-3, 1, 1e3}, theta[] = {0, 89}, n[] = {1, 1.4};
    pu_grid grid = {1, PU_AXIS(albedo), PU_AXIS(g), PU_AXIS(height), PU_AXIS(theta), PU_AXIS(n)};
    pu_extremes("burley", &grid, coarse_directions, corner_bounds);
}

static void set_samples(ppb_config *cfg, int samples)
{
    cfg->burley.samples = samples;
}

static void test_quadrature_converges_on_tube(void **state)
{
    (void)state;
    /* The method's quadrature error on the tube (uniform_g0_normal and density_step): every
     * cell at [burley] samples = 16 (default) and 8 against 64 nodes per d. */
    pu_samples_converge("burley", "uniform_g0_normal", NAN, set_samples);
    pu_samples_converge("burley", "density_step", NAN, set_samples);
}

/* A slab's totals and S1's lobe (test_slab_mode). */
static void slab_totals(ppb_run_ctx *ctx, const ppb_result *out, double mu, double entry)
{
    ppb_err err;
    double A;
    assert_int_equal(
        ppb_burley_albedo(0.95, 0.0, ctx->cfg->scene.n, mu, ctx->cfg->burley.directions, &A, &err),
        0);
    ppb_burley b = {A, ppb_burley_shape_searchlight(A) * (1 - 0.95 * 0.0)};
    assert_rel(out->totals.R, entry * A, 1e-14);
    assert_rel(out->totals.T, entry * A * (1 - ppb_burley_cdf(&b, 3.0)), 1e-14);
    pu_assert_lobe_mean(out, mu);
}

static void test_slab_mode(void **state)
{
    (void)state;
    /* Slab mode: R = (1 - F) A and T = (1 - F) A (1 - cdf(H)) (the profile over the planes at
     * distance 0 and H), radiance R cos(theta_L) / pi on S1 at n = 1; at n = 1.4 the exit lobe
     * distributes the same flux (its bins' mean is 1). */
    pu_slab_mode("burley", slab_totals);
}

static void test_sum_with_ss(void **state)
{
    (void)state;
    study_check_sum_with_ss("burley");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_k0_tables),
        cmocka_unit_test(test_k1_tables),
        cmocka_unit_test(test_profile_plane_integral),
        cmocka_unit_test(test_line_kernel),
        cmocka_unit_test(test_strip_quadrature),
        cmocka_unit_test(test_shape_factor),
        cmocka_unit_test(test_albedo_exact),
        cmocka_unit_test(test_study_configs),
        cmocka_unit_test(test_extremes),
        cmocka_unit_test(test_quadrature_converges_on_tube),
        cmocka_unit_test(test_slab_mode),
        cmocka_unit_test(test_sum_with_ss),
        /* one per line */
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
