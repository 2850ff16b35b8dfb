/* test_dirpole.c: the `dirpole` method (src/methods/dirpole/; reference: Methods, `dirpole`):
 * Frisvad, Hachisuka & Kjeldsen 2014's directional dipole. The Fresnel moments' fits against
 * the moments integrated from the exact Fresnel equations; the profile's symmetries (radial at
 * normal incidence, mirror in the plane of incidence, forward-peaked at oblique incidence); the
 * z quadrature against a much finer plain one; the plane integrals of the strip quadrature
 * against a polar quadrature of the 3-D profile (normal and oblique incidence, at the face and
 * at depth); their convergence in [dirpole] samples; slab mode; the method on every study
 * config and at the robustness grid's extremes (finite, non-negative, within the plane's
 * bounds) and dirpole+ss = dirpole + ss cell by cell. */
#include "testutil.h"
#include "study_cases.h"
#include "profileutil.h"

#include <math.h>

#include "base/quadrature.h"
#include "kernels/ppb_fresnel.h"
#include "methods/dirpole/dirpole_profile.h"
#include "methods/registry.h"
#include "model/config.h"
#include "physics/diffuse_exit.h"

static const double UP[3] = {0, 1, 0}, DOWN[3] = {0, -1, 0};

/* int_0^1 F(mu, 1/eta) mu^k dmu for light inside a medium of relative index eta meeting its
 * boundary: composite 16-point Gauss-Legendre, 4000 panels each side of the critical cosine
 * (where F has a square-root kink). */
static double fresnel_moment(double eta, int k)
{
    double x[16], w[16], n_rel = 1.0 / eta;
    ppb_gauss_legendre(16, x, w);
    double mu_c = n_rel < 1.0 ? sqrt(1.0 - n_rel * n_rel) : 0.0, sum = 0.0;
    const double edges[3] = {0.0, mu_c, 1.0};
    for (int part = 0; part < 2; part++) {
        double a = edges[part], b = edges[part + 1], h = (b - a) / 4000;
        for (int p = 0; p < 4000 && h > 0; p++)
            for (int j = 0; j < 16; j++) {
                double mu = a + (p + 0.5 + 0.5 * x[j]) * h;
                sum += 0.5 * h * w[j] * ppb_fresnel(mu, n_rel) * pow(mu, k);
            }
    }
    return sum;
}

static void test_fresnel_moment_fits(void **state)
{
    (void)state;
    /* d'Eon & Irving 2011's polynomial fits of 2 C1 and 3 C2 (the paper's C_phi and C_E) against
     * the moments of the exact unpolarized Fresnel reflectance, inside (eta) and outside
     * (1/eta) over eta = 1.1..1.6; 2 C1 also against ppb_diffuse_fresnel (Prahl's identity
     * for the inside value: an independent route). The fits are fits: their error is what
     * is bounded here, measured 1e-3 at most for 2 C1 and 3e-3 for 3 C2 (printed). */
    double worst1 = 0, worst2 = 0;
    for (int i = 0; i <= 10; i++) {
        double eta = 1.1 + 0.05 * i;
        for (int side = 0; side < 2; side++) {
            double e = side ? 1.0 / eta : eta;
            double c1 = fresnel_moment(e, 1), c2 = fresnel_moment(e, 2);
            assert_close(2 * c1, ppb_diffuse_fresnel(1.0 / e), 1e-9);
            worst1 = fmax(worst1, fabs(2 * ppb_dirpole_c1(e) - 2 * c1));
            if (!side) /* the paper uses C2 at eta > 1 only (C_E(eta)): its fit is for that */
                worst2 = fmax(worst2, fabs(3 * ppb_dirpole_c2(e) - 3 * c2));
        }
    }
    print_message("fits: largest error of 2 C1 %.2e, of 3 C2 %.2e\n", worst1, worst2);
    assert_lt(worst1, 2e-3);
    assert_lt(worst2, 5e-3);
    /* eta = 1: no boundary, every moment 0 (exact, not the fits' value there). */
    assert_close(ppb_dirpole_c1(1.0), 0.0, 0.0);
    assert_close(ppb_dirpole_c2(1.0), 0.0, 0.0);
    /* A = (1 - C_E) / (2 C_phi) = (1 + 3 C2) / (1 - 2 C1): 1 at eta = 1. */
    ppb_dirpole p;
    const double w[3] = {0, -1, 0};
    ppb_dirpole_init(&p, 1.0, 0.95, 0.0, 1.0, w);
    assert_close(p.A, 1.0, 1e-15);
    ppb_dirpole_init(&p, 1.0, 0.95, 0.0, 1.4, w);
    double c1 = fresnel_moment(1.4, 1), c2 = fresnel_moment(1.4, 2);
    assert_rel(p.A, (1 + 3 * c2) / (1 - 2 * c1), 1e-2);
}

/* The beam refracted into a medium of index n at theta_L (deg): (sin / n, -cos_t, 0). */
static void beam(double theta_deg, double n, double w[3])
{
    double c = cos(theta_deg * PPB_PI / 180), s = sin(theta_deg * PPB_PI / 180);
    w[0] = s / n;
    w[1] = -ppb_refract_cos(c, n);
    w[2] = 0;
}

static void test_symmetries(void **state)
{
    (void)state;
    /* Normal incidence, exit points in the entry plane: the exitance depends on r only (the
     * modified tangent plane is the tangent plane; the real and virtual sources lie on the
     * normal through x_i), so it is the same in every direction of the plane, and swapping
     * x_i and x_o (the reciprocity the paper's Sec. 6.3 symmetrizes for in general) leaves it
     * unchanged here. Oblique incidence: mirror-symmetric across the plane of incidence
     * (z -> -z) and larger forward (x . w_12 > 0) than backward, the model's point. */
    ppb_dirpole p, q;
    double w[3];
    beam(0, 1.4, w);
    ppb_dirpole_init(&p, 1.0, 0.9, 0.3, 1.4, w);
    const double r[] = {0.01, 0.3, 1, 3, 10};
    for (int i = 0; i < 5; i++) {
        double x0[3] = {r[i], 0, 0}, ref = ppb_dirpole_exitance(&p, x0, UP, UP);
        assert_true(ref > 0);
        for (int k = 1; k < 12; k++) {
            double phi = 2 * PPB_PI * k / 12;
            double x[3] = {r[i] * cos(phi), 0, r[i] * sin(phi)};
            assert_rel(ppb_dirpole_exitance(&p, x, UP, UP), ref, 1e-13);
        }
    }
    beam(60, 1.0, w);
    ppb_dirpole_init(&q, 1.0, 0.95, 0.0, 1.0, w);
    for (int i = 0; i < 5; i++) {
        double a[3] = {0.3 * r[i], -0.2 * r[i], r[i]}, b[3] = {a[0], a[1], -a[2]};
        const double *normals[] = {UP, DOWN};
        for (int k = 0; k < 2; k++)
            assert_rel(ppb_dirpole_exitance(&q, a, UP, normals[k]),
                       ppb_dirpole_exitance(&q, b, UP, normals[k]), 1e-13);
        double fwd[3] = {r[i], 0, 0}, bwd[3] = {-r[i], 0, 0};
        assert_true(ppb_dirpole_exitance(&q, fwd, UP, UP) > ppb_dirpole_exitance(&q, bwd, UP, UP));
    }
}

static void test_line_quadrature(void **state)
{
    (void)state;
    /* The z integral (Gauss-Legendre on z = q sinh t) against composite Simpson in plain z
     * (2e6 intervals on [0, 40 / sigma_tr + 10]), at exit points each face of the tube can
     * hold (S1 on the entry plane, S2 at depth 3, S3 with the entry points to its right, S4 to
     * its left), near and far, at normal and 45 deg incidence, n = 1 and 1.4: within 1e-10.
     * The exception is S4 near S1's corner under the oblique beam (the beam leaves toward S4,
     * mu0 < 0, and the clamp of S_d at 0 puts a kink on the line): within 1e-3 at 16 nodes per
     * unit t, 3e-5 at 64 (printed). */
    const double theta[] = {0, 45}, n[] = {1.0, 1.4};
    const double pts[4][4][2] = {{{0, 0}, {0.05, 0}, {1, 0}, {-2, 0}},
                                 {{0.01, -3}, {0.3, -3}, {1, -3}, {-4, -3}},
                                 {{0, -0.05}, {-0.05, -0.05}, {-1, -0.3}, {-3, -2}},
                                 {{0, -0.05}, {0.05, -0.05}, {1, -0.3}, {3, -2}}};
    double worst = 0, corner = 0;
    for (int c = 0; c < 2; c++) {
        ppb_dirpole p;
        double w[3];
        beam(theta[c], n[c], w);
        ppb_dirpole_init(&p, 1.0, 0.95, 0.0, n[c], w);
        for (int f = 0; f < 4; f++)
            for (int i = 0; i < 4; i++) {
                const double no[3] = {ppb_normal_x(f), ppb_normal_y(f), 0};
                double u = pts[f][i][0], v = pts[f][i][1];
                double zmax = 40 / p.sigma_tr + 10, h = zmax / 2e6, sum = 0;
                for (int k = 0; k <= 2000000; k++) {
                    double x[3] = {u, v, k ? k * h : 1e-3 * h}; /* z -> 0+: n_i* is its limit */
                    double wt = (k == 0 || k == 2000000) ? 1 : (k % 2 ? 4 : 2);
                    sum += wt * ppb_dirpole_exitance(&p, x, UP, no);
                }
                double ref = 2 * sum * h / 3, got = ppb_dirpole_line(&p, u, v, no, 16);
                double e = fabs(got / ref - 1);
                if (c == 1 && f == PPB_S4 && v > -0.1) {
                    corner = fmax(corner, e);
                    continue;
                }
                worst = fmax(worst, e);
            }
    }
    print_message("line: largest relative difference from plain Simpson %.2e (S4 corner %.2e)\n",
                  worst, corner);
    assert_lt(worst, 1e-10);
    assert_lt(corner, 1e-3);
}

/* The plane integral of the exitance at an exit point at depth v below the entry plane (normal
 * no) by polar quadrature about the entry point under it: rho = e^s, s over [ln 1e-8, ln(50 /
 * sigma_tr)] in 800 16-point Gauss-Legendre panels, phi by the trapezoidal rule on 720 points
 * (the integrand is periodic in phi). Nothing shared with the strip's route but the exitance. */
static double plane_polar(const ppb_dirpole *p, double v, const double no[3])
{
    double x[16], w[16];
    ppb_gauss_legendre(16, x, w);
    double s0 = log(1e-8), s1 = log(50 / p->sigma_tr), h = (s1 - s0) / 800, sum = 0;
    for (int k = 0; k < 800; k++)
        for (int j = 0; j < 16; j++) {
            double rho = exp(s0 + (k + 0.5 + 0.5 * x[j]) * h), ring = 0;
            for (int m = 0; m < 720; m++) {
                double phi = 2 * PPB_PI * m / 720;
                double xo[3] = {rho * cos(phi), v, rho * sin(phi)};
                ring += ppb_dirpole_exitance(p, xo, UP, no);
            }
            sum += 0.5 * h * w[j] * rho * rho * ring * (2 * PPB_PI / 720);
        }
    return sum;
}

static void test_plane_integrals(void **state)
{
    (void)state;
    /* The strip quadrature over the whole plane of entry points (x over +-100 / sigma_tr, z over
     * the whole axis) against the polar quadrature above: at the face (R) and at depth 3 (T),
     * normal and 45 deg incidence, n = 1 and 1.4. At normal incidence, n = 1, alpha' = 0.95
     * the model's R is 0.849 (printed): the directional dipole's reflectance of a
     * semi-infinite medium, against the exact 0.536 (reference: Methods, `burley`). */
    const double theta[] = {0, 45, 0, 45}, n[] = {1.0, 1.0, 1.4, 1.4};
    for (int c = 0; c < 4; c++) {
        ppb_dirpole p;
        double w[3];
        beam(theta[c], n[c], w);
        ppb_dirpole_init(&p, 1.0, 0.95, 0.0, n[c], w);
        double wide = 100 / p.sigma_tr;
        double R = ppb_dirpole_strip(&p, -wide, wide, 0.0, UP, 16);
        double T = ppb_dirpole_strip(&p, -wide, wide, -3.0, DOWN, 16);
        double Rp = plane_polar(&p, 0.0, UP), Tp = plane_polar(&p, -3.0, DOWN);
        print_message("theta %2.0f n %.1f: R %.10f (polar %.10f)  T %.10f (polar %.10f)\n",
                      theta[c], n[c], R, Rp, T, Tp);
        assert_rel(R, Rp, 1e-10);
        assert_rel(T, Tp, 1e-10);
    }
}

static void test_strip_converges(void **state)
{
    (void)state;
    /* The strip integral at [dirpole] samples = 8 and 16 (default) against 64, at exit points
     * on every face of the study's tube (W 10, H 3, the strip [-5, 5]), oblique at n = 1.4:
     * within 1e-8 at 16; within 1e-5 at S4 near S1's corner, where S_d's clamp at 0 puts a
     * kink on the line (test_line_quadrature; printed). */
    ppb_dirpole p;
    double w[3];
    beam(45, 1.4, w);
    ppb_dirpole_init(&p, 1.0, 0.95, 0.0, 1.4, w);
    const double pts[][3] = {{-4.9, 0, 0}, {0, 0, 0},     {3, 0, 0},   {5, 0, 0},
                             {-4, -3, 1},  {0, -3, 1},    {4, -3, 1},  {-5, -0.01, 2},
                             {-5, -2, 2},  {5, -0.01, 3}, {5, -1.5, 3}};
    double worst[2] = {0, 0}, corner[2] = {0, 0};
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++) {
        int f = (int)pts[i][2];
        const double no[3] = {ppb_normal_x(f), ppb_normal_y(f), 0};
        double x = pts[i][0], y = pts[i][1];
        double ref = ppb_dirpole_strip(&p, x - 5, x + 5, y, no, 64);
        const int s[2] = {8, 16};
        for (int k = 0; k < 2; k++) {
            double e = fabs(ppb_dirpole_strip(&p, x - 5, x + 5, y, no, s[k]) / ref - 1);
            if (f == PPB_S4 && y > -0.1) /* the clamp's kink (test_line_quadrature) */
                corner[k] = fmax(corner[k], e);
            else
                worst[k] = fmax(worst[k], e);
        }
    }
    print_message("strip: samples 8 vs 64 %.2e, 16 vs 64 %.2e (S4 corner %.2e, %.2e)\n", worst[0],
                  worst[1], corner[0], corner[1]);
    assert_lt(worst[1], 1e-8);
    assert_lt(corner[1], 1e-5);
}

/* The plane integrals of the media of scene sc (both sides of a step): the largest R at the
 * face and T at depth H, per unit power entering. */
static void plane_bounds(const ppb_scene *sc, double *R, double *T)
{
    double w[3];
    beam(sc->theta_deg, sc->n > 1 ? sc->n : 1.0, w);
    *R = *T = 0;
    for (int side = 0; side < 2; side++) {
        double st, al;
        pu_side_medium(sc, side, &st, &al);
        ppb_dirpole p;
        ppb_dirpole_init(&p, st, al, sc->g, sc->n, w);
        double wide = 100 / p.sigma_tr;
        *R = fmax(*R, ppb_dirpole_strip(&p, -wide, wide, 0, UP, 16));
        *T = fmax(*T, ppb_dirpole_strip(&p, -wide, wide, -sc->height, DOWN, 16));
    }
}

/* S1's and S2's totals against the bounds of test_study_configs. */
static void study_bounds(const char *name, ppb_run_ctx *ctx, const ppb_result *out)
{
    const ppb_scene *sc = &ctx->cfg->scene;
    double entry = pu_entry(sc), Rp, Tp;
    double wide = sc->width / ppb_scene_lit_width(sc);
    plane_bounds(sc, &Rp, &Tp);
    print_message("%-24s R %.4f (plane %.4f) T %.4f (plane %.4f) sides %.4f\n", name, out->totals.R,
                  Rp, out->totals.T, Tp, out->totals.sides);
    assert_le(out->totals.R, entry * Rp * wide * (1 + 1e-9));
    assert_le(out->totals.T, entry * Tp * wide * (1 + 1e-9));
    assert_true(out->totals.sides >= 0 && out->totals.sides <= entry * Rp * wide);
}

static void test_study_configs(void **state)
{
    (void)state;
    /* dirpole on every study config (configs/study.list): every radiance finite and >= 0, and
     * S1's and S2's totals within the plane's: the exitance is >= 0 (clamped), so a lit strip
     * gives each exit point at most what the whole plane of entry points gives, R_plane at the
     * face and T_plane at depth H; over the face that is at most (1 - F) R_plane W / W_lit of
     * the entering power (W_lit the lit width), likewise T. */
    pu_study_configs("dirpole", NULL, study_bounds);
}

/* The corners at 4 [dirpole] samples: short runs (accuracy is test_strip_converges's). */
static void coarse_samples(ppb_config *cfg)
{
    cfg->dirpole.samples = 4;
}

/* Nothing at all leaves at albedo 0 (test_extremes). */
static void corner_dark(const pu_corner *c, ppb_run_ctx *ctx, const ppb_result *out)
{
    (void)ctx;
    double sum = 0;
    for (size_t i = 0; i < out->layout.ncells; i++)
        sum += out->radiance[i];
    if (c->albedo == 0)
        assert_close(sum, 0, 0);
}

static void test_extremes(void **state)
{
    (void)state;
    /* The corners of the robustness grid (tests/test_robust.c's values): albedo 0 to 1, g
     * +-0.95, H from 1e-3 to 1e3, theta_L 0 and 89 deg, n 1 and 1.4, tube and slab: every cell
     * finite and >= 0, and the method's result checks passed. Albedo 0 gives 0 (no scattering:
     * alpha' = 0, the extrapolation distance infinite). */
    const double albedo[] = {0, 0.5, 1}, g[] = {-0.95, 0.95}, height[] = {1e-3, 1e3},
                 theta[] = {0, 89}, n[] = {1, 1.4};
    pu_grid grid = {1, PU_AXIS(albedo), PU_AXIS(g), PU_AXIS(height), PU_AXIS(theta), PU_AXIS(n)};
    pu_extremes("dirpole", &grid, coarse_samples, corner_dark);
}

/* A slab's totals and S1's lobe (test_slab_mode). */
static void slab_totals(ppb_run_ctx *ctx, const ppb_result *out, double mu, double entry)
{
    double n = ctx->cfg->scene.n, w[3];
    ppb_dirpole p;
    beam(30, n, w);
    ppb_dirpole_init(&p, 1.0, 0.95, 0.0, n, w);
    assert_rel(out->totals.R, entry * plane_polar(&p, 0, UP), 1e-10);
    assert_rel(out->totals.T, entry * plane_polar(&p, -3, DOWN), 1e-10);
    pu_assert_lobe_mean(out, mu);
}

static void test_slab_mode(void **state)
{
    (void)state;
    /* Slab mode: R and T are (1 - F(theta_L)) times the plane integrals (the polar quadrature
     * of test_plane_integrals), radiance R cos(theta_L) / pi on S1 (the lobe's bins' mean 1 at
     * n = 1.4). */
    pu_slab_mode("dirpole", slab_totals);
}

static void test_sum_with_ss(void **state)
{
    (void)state;
    study_check_sum_with_ss("dirpole");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fresnel_moment_fits), cmocka_unit_test(test_symmetries),
        cmocka_unit_test(test_line_quadrature),     cmocka_unit_test(test_plane_integrals),
        cmocka_unit_test(test_strip_converges),     cmocka_unit_test(test_slab_mode),
        cmocka_unit_test(test_sum_with_ss),         cmocka_unit_test(test_extremes),
        cmocka_unit_test(test_study_configs),
        /* one per line */
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
