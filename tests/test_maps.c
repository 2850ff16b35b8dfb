/* test_maps.c: the light maps (src/physics/maps.h) against closed forms (reference: Medium,
 * Geometry, Light) for the uniform tube, the three step cases and oblique light, the exact
 * ballistic fraction and the midpoint rule over the lit part of S1. */
#include "testutil.h"

#include <math.h>

#include "physics/maps.h"
#include "physics/totals.h"

/* The map at 16 cells per mfp: every study case's jumps lie on cell edges, so the bilinear
 * lookup must reproduce the closed forms to rounding wherever it is read. */
#define RES 16

static ppb_maps build(const ppb_scene *sc)
{
    ppb_maps m;
    ppb_err err;
    if (ppb_maps_build(sc, RES, &m, &err))
        fail_msg("%s", err.msg);
    return m;
}

/* A grid of probe points over the cross-section, off the cell edges and on them. */
#define NPX 41
#define NPY 13
static void probe(int i, int j, double *x, double *y)
{
    *x = -5.0 + 10.0 * i / (NPX - 1) * 0.9999 + 1e-4 * (i == 0);
    *y = -3.0 * j / (NPY - 1) * 0.9999;
}

static void test_uniform_normal(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    ppb_maps m = build(&sc);
    for (int i = 0; i < NPX; i++)
        for (int j = 0; j < NPY; j++) {
            double x, y, D, abar, lit;
            probe(i, j, &x, &y);
            ppb_maps_lookup(&m, x, y, &D, &abar, &lit);
            assert_close(D, -y, 1e-9);       /* D = sigma_t depth (vertical light) */
            assert_close(abar, 0.95, 1e-12); /* one albedo */
            assert_close(lit, 1.0, 1e-12);   /* all of S1 lit */
        }
    ppb_maps_free(&m);
}

static void test_density_step(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    sc.step = PPB_STEP_DENSITY;
    ppb_maps m = build(&sc);
    /* Closed form: the vertical light path stays in its column, D = sigma_t(x) |y|, with
     * sigma_t = 1 for x < 0 and 0.5 for x >= 0 (reference: Cases, density_step). Probes right
     * beside the step test that the jump is kept sharp. */
    double xs[] = {-4.9, -1.0, -0.01, -1e-6, 0.0, 1e-6, 0.01, 2.5, 4.99};
    for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++)
        for (int j = 0; j < NPY; j++) {
            double y = -3.0 * j / (NPY - 1), D, abar, lit;
            ppb_maps_lookup(&m, xs[i], y, &D, &abar, &lit);
            assert_close(D, (xs[i] < 0 ? 1.0 : 0.5) * -y, 1e-8);
            assert_close(abar, 0.95, 1e-12);
        }
    ppb_maps_free(&m);
}

static void test_albedo_step(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    sc.step = PPB_STEP_ALBEDO;
    ppb_maps m = build(&sc);
    /* Closed form: the average along a vertical path is the column's own albedo, 0.95 left of
     * x = 0 and 0.475 right of it; D is unchanged, |y|. */
    double xs[] = {-4.9, -0.01, -1e-6, 1e-6, 0.01, 4.9};
    for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++)
        for (int j = 0; j < NPY; j++) {
            double y = -3.0 * j / (NPY - 1), D, abar, lit;
            ppb_maps_lookup(&m, xs[i], y, &D, &abar, &lit);
            assert_close(abar, xs[i] < 0 ? 0.95 : 0.475, 1e-8);
            assert_close(D, -y, 1e-8);
        }
    ppb_maps_free(&m);
}

static void test_shadow_step(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    sc.step = PPB_STEP_SHADOW;
    ppb_maps m = build(&sc);
    /* Shadow step (reference: Light): S1 lit for x < 0 only; with vertical light D = |y| there and
     * infinite (ppb_maps_depth) under the dark half, right up to the edge. */
    double xs[] = {-4.9, -0.5, -1e-6, 1e-6, 0.5, 4.9};
    for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++)
        for (int j = 0; j < NPY; j++) {
            double y = -3.0 * j / (NPY - 1);
            double D = ppb_maps_depth(&m, xs[i], y);
            if (xs[i] < 0)
                assert_close(D, -y, 1e-8);
            else
                assert_true(isinf(D));
        }
    ppb_maps_free(&m);
}

static void test_oblique_shadow_triangle(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    sc.theta_deg = 45;
    ppb_maps m = build(&sc);
    /* Shadow step at 45 deg (reference: Light): D = sqrt(2) |y| along the slanted path, and the
     * triangle x < -W/2 + |y| next to S3 is in shadow. The map's columns follow the light, so the
     * edge is a column edge: exact on both sides. */
    for (int i = 0; i < NPX; i++)
        for (int j = 0; j < NPY; j++) {
            double x, y;
            probe(i, j, &x, &y);
            double edge = -5.0 - y;
            if (fabs(x - edge) < 1e-7)
                continue;
            double D = ppb_maps_depth(&m, x, y);
            if (x > edge)
                assert_close(D, sqrt(2.0) * -y, 1e-8);
            else
                assert_true(isinf(D));
        }
    /* S3 itself is dark below its top corner. */
    assert_true(isinf(ppb_maps_depth(&m, -5.0, -0.5)));
    ppb_maps_free(&m);
}

static void test_oblique_density_exact(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    sc.theta_deg = 45;
    sc.step = PPB_STEP_DENSITY;
    /* Closed form at (x, y) = (1, -2): the path to S1 runs up-left to x' = -1; it spends
     * |dx| = 1 right of x = 0 and 1 left, each sqrt(2) long: D = sqrt(2)(0.5 + 1). */
    double D, abar;
    int lit;
    ppb_light_path_exact(&sc, 1.0, -2.0, &D, &abar, &lit);
    assert_close(D, sqrt(2.0) * 1.5, 1e-12);
    assert_int_equal(lit, 1);
    /* The map is exact away from the kink lines (the step and the light line through its foot)
     * and converges to the exact value next to them as map_res grows. */
    ppb_maps m = build(&sc);
    ppb_maps_lookup(&m, 1.0 + 0.5 / RES, -2.0 + 0.25 / RES, &D, &abar, &(double){0});
    double Dx;
    ppb_light_path_exact(&sc, 1.0 + 0.5 / RES, -2.0 + 0.25 / RES, &Dx, &abar, &lit);
    assert_close(D, Dx, 1e-8);
    ppb_maps_free(&m);
    double errs[2];
    int res[2] = {8, 64};
    for (int r = 0; r < 2; r++) {
        ppb_err err;
        assert_int_equal(ppb_maps_build(&sc, res[r], &m, &err), 0);
        double worst = 0.0, lt;
        for (int k = 0; k < 200; k++) { /* points straddling the step line x = 0 */
            double x = -0.05 + 0.1 * k / 199.0, y = -1.7, Dm, Dx2, ab;
            ppb_maps_lookup(&m, x, y, &Dm, &ab, &lt);
            ppb_light_path_exact(&sc, x, y, &Dx2, &ab, &lit);
            worst = fmax(worst, fabs(Dm - Dx2));
        }
        errs[r] = worst;
        ppb_maps_free(&m);
    }
    /* Linear interpolation across a kink: error ~ h x slope jump, so 8x finer cells cut it ~8x. */
    assert_lt(errs[1], errs[0] / 4.0);
}

static void test_average_albedo_oblique(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    sc.theta_deg = 45;
    sc.step = PPB_STEP_ALBEDO;
    /* Paper Sec. 3.3: length average along the path. From (1, -2) the path has half its length
     * on each side of x = 0: (0.95 + 0.475) / 2. */
    double D, abar;
    int lit;
    ppb_light_path_exact(&sc, 1.0, -2.0, &D, &abar, &lit);
    assert_close(abar, 0.7125, 1e-12);
    ppb_maps m = build(&sc);
    double Dm, am, lt;
    ppb_maps_lookup(&m, 1.0, -2.0, &Dm, &am, &lt);
    assert_close(am, 0.7125, 1e-8); /* (1, -2) lies in a cell no kink line cuts */
    ppb_maps_free(&m);
}

static void test_slab(void **state)
{
    (void)state;
    ppb_scene sc = tu_slab(2.0, 0.9, 0.0, 30.0);
    ppb_maps m = build(&sc);
    /* Slab mode: D = depth / cos(theta_L) at any x (reference: Geometry). */
    for (int j = 0; j <= 20; j++) {
        double y = -2.0 * j / 20.0;
        for (double x = -100; x <= 100; x += 37.5)
            assert_close(ppb_maps_depth(&m, x, y), -y / cos(PPB_PI / 6), 1e-9);
    }
    ppb_maps_free(&m);
}

static void test_ballistic(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    assert_close(ppb_ballistic_fraction(&sc), exp(-3.0), 1e-12); /* e^-tau0 */
    sc.step = PPB_STEP_DENSITY; /* half the width at tau = 3, half at 1.5 */
    assert_close(ppb_ballistic_fraction(&sc), 0.5 * (exp(-3.0) + exp(-1.5)), 1e-12);
    sc.step = PPB_STEP_SHADOW; /* normalised by the lit width: e^-3 again */
    assert_close(ppb_ballistic_fraction(&sc), exp(-3.0), 1e-12);
    sc.step = PPB_STEP_NONE;
    sc.theta_deg = 45;
    /* Entry x_e in [-5, 2] crosses to S2 (path 3 sqrt 2); x_e in (2, 5] leaves through S4
     * after (5 - x_e) sqrt 2: [7 e^{-3 sqrt 2} + (1 - e^{-3 sqrt 2}) / sqrt 2] / 10. */
    double r2 = sqrt(2.0), e = exp(-3.0 * r2);
    assert_close(ppb_ballistic_fraction(&sc), (7.0 * e + (1.0 - e) / r2) / 10.0, 1e-10);
    ppb_scene slab = tu_slab(2.0, 0.9, 0.0, 60.0);
    assert_close(ppb_ballistic_fraction(&slab), exp(-4.0), 1e-12); /* tau0 / mu0 */
    assert_close(ppb_beam_depth(&slab, 0.0), 4.0, 1e-14);
}

/* The ballistic fraction split by exit face (delta-M's totals in rte2d move the scaled beam's
 * excess through these faces). n = 1, 45 deg: test_ballistic's two parts, S2 and S4. n = 1.5
 * slab and n = 1.4 tube at normal light, Fresnel F = ((n - 1) / (n + 1))^2 at both faces and at
 * entry: the beam's series, (1 - F)^2 e^-tau / (1 - F^2 e^-2tau) at S2 and F e^-tau times that at
 * S1. n = 1.4, 45 deg (the walk off all four faces): the faces sum to ppb_bin_totals' ballistic
 * and the sides, where the beam is totally reflected, get none. */
static void test_ballistic_faces(void **state)
{
    (void)state;
    double b[PPB_NSURF];
    ppb_scene sc = tu_tube();
    sc.theta_deg = 45;
    double r2 = sqrt(2.0), e = exp(-3.0 * r2);
    ppb_ballistic_faces(&sc, b);
    assert_close(b[PPB_S2], 7.0 * e / 10.0, 1e-10);
    assert_close(b[PPB_S4], (1.0 - e) / r2 / 10.0, 1e-10);
    assert_close(b[PPB_S1] + b[PPB_S3], 0.0, 0.0);
    struct {
        ppb_scene sc;
        double n, tau;
    } cs[] = {{tu_slab(2.0, 0.9, 0.0, 0.0), 1.5, 2.0}, {tu_tube(), 1.4, 3.0}};
    for (int c = 0; c < 2; c++) {
        cs[c].sc.n = cs[c].n;
        double F = pow((cs[c].n - 1.0) / (cs[c].n + 1.0), 2.0), t = exp(-cs[c].tau);
        double s2 = (1.0 - F) * (1.0 - F) * t / (1.0 - F * F * t * t);
        ppb_ballistic_faces(&cs[c].sc, b);
        assert_close(b[PPB_S2], s2, 1e-12);
        assert_close(b[PPB_S1], s2 * F * t, 1e-12);
        assert_close(b[PPB_S3] + b[PPB_S4], 0.0, 0.0);
    }
    sc.n = 1.4;
    ppb_layout lo = ppb_scene_layout(&sc);
    double *zero = calloc(lo.ncells, sizeof *zero);
    assert_non_null(zero);
    ppb_totals t;
    ppb_bin_totals(&sc, &lo, zero, &t);
    ppb_ballistic_faces(&sc, b);
    /* the walk's 2e4 midpoints summed per face, then added: rounding only */
    assert_close(b[PPB_S1] + b[PPB_S2] + b[PPB_S3] + b[PPB_S4], t.ballistic, 1e-12);
    /* the refracted beam (30.3 deg) meets S4 at 59.7 deg from its normal, beyond the critical
     * 45.6 deg: it leaves through S2 and, reflected, S1 alone */
    assert_true(b[PPB_S1] > 0.0 && b[PPB_S2] > 0.0);
    assert_close(b[PPB_S3] + b[PPB_S4], 0.0, 0.0);
    free(zero);
}

/* Oblique light across the density step (theta_L = 30 deg, sigma_t 1 -> 0.5 at x = 0), the case
 * where mp's own copy of the beam depth and its 3-point rule were off by 8e-8. The beam's
 * path has length L = H / cos = 2 sqrt 3 and crosses x over H tan = sqrt 3 (sin = 1/2). */
static void test_ballistic_oblique_density(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    sc.step = PPB_STEP_DENSITY;
    sc.theta_deg = 30;
    double L = 2.0 * sqrt(3.0), shift = sqrt(3.0), s = 0.5;
    /* Beam depth by path lengths on each side: entry at -1 runs 1 / sin = 2 left of the step and
     * L - 2 right of it; entry at 4 leaves through S4 after (5 - 4) / sin = 2, all right. */
    assert_close(ppb_beam_depth(&sc, -4.0), L, 1e-13);
    assert_close(ppb_beam_depth(&sc, -1.0), 2.0 + 0.5 * (L - 2.0), 1e-13);
    assert_close(ppb_beam_depth(&sc, 1.0), 0.5 * L, 1e-13);
    assert_close(ppb_beam_depth(&sc, 4.0), 0.5 * 2.0, 1e-13);
    /* Closed form of the average of exp(-depth) over x_e in [-5, 5], piece by piece:
     *   [-5, -shift]: all left, e^{-L};  [-shift, 0]: depth = L/2 - x_e / (2 s), integral
     *   2 s e^{-L/2} (1 - e^{-L/2});  [0, 5 - shift]: all right, e^{-L/2};  [5 - shift, 5]: out
     *   through S4 after (5 - x_e) / s at sigma_t 1/2, integral 2 s (1 - e^{-L/2}). */
    double eh = exp(-0.5 * L);
    double sum = (5.0 - shift) * exp(-L) + 2.0 * s * eh * (1.0 - eh) + (5.0 - shift) * eh +
                 2.0 * s * (1.0 - eh);
    assert_close(ppb_ballistic_fraction(&sc), sum / 10.0, 1e-13);
}

/* The midpoint sum over the lit part of S1 (maps.h, the Fresnel walks' rule): for a linear
 * integrand the midpoint rule is exact, so sum * width / np is the integral to rounding, over
 * [-5, 5] and, with a shadow step at 0, over [-5, 0]; for exp(-x / 3) its error is within the
 * rule's bound (b - a) h^2 max |f''| / 24, h = (b - a) / np. */
static double linear(const ppb_scene *sc, double x, void *arg)
{
    (void)sc, (void)arg;
    return 2.0 + x;
}
static double decaying(const ppb_scene *sc, double x, void *arg)
{
    (void)sc, (void)arg;
    return exp(-x / 3.0);
}

static void test_lit_midpoint_sum(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    const int np = PPB_LIT_MIDPOINTS;
    double width, sum = ppb_lit_midpoint_sum(&sc, linear, NULL, np, &width);
    assert_close(width, 10.0, 0.0);
    assert_close(sum * width / np, 20.0, 1e-10); /* integral of 2 + x over [-5, 5] */
    sum = ppb_lit_midpoint_sum(&sc, decaying, NULL, np, &width);
    double exact = 3.0 * (exp(5.0 / 3.0) - exp(-5.0 / 3.0)), h = width / np;
    double bound = width * h * h * exp(5.0 / 3.0) / 9.0 / 24.0;
    assert_true(fabs(sum * width / np - exact) <= bound);
    sc.step = PPB_STEP_SHADOW;
    sum = ppb_lit_midpoint_sum(&sc, linear, NULL, np, &width);
    assert_close(width, 5.0, 0.0);
    assert_close(sum * width / np, -2.5, 1e-10); /* 10 - 12.5 over [-5, 0] */
    sc.step_x = -5.0;                            /* nothing lit */
    assert_close(ppb_lit_midpoint_sum(&sc, linear, NULL, np, &width), 0.0, 0.0);
    assert_close(width, 0.0, 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_uniform_normal),
        cmocka_unit_test(test_density_step),
        cmocka_unit_test(test_albedo_step),
        cmocka_unit_test(test_shadow_step),
        cmocka_unit_test(test_oblique_shadow_triangle),
        cmocka_unit_test(test_oblique_density_exact),
        cmocka_unit_test(test_average_albedo_oblique),
        cmocka_unit_test(test_slab),
        cmocka_unit_test(test_ballistic),
        cmocka_unit_test(test_ballistic_faces),
        cmocka_unit_test(test_ballistic_oblique_density),
        cmocka_unit_test(test_lit_midpoint_sum),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
