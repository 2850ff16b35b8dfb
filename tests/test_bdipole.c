/* test_bdipole.c: the `bdipole` method (src/methods/bdipole/; reference: Methods, `bdipole`):
 * d'Eon's better dipole. The exact Fresnel moments against mpmath's; the closed-form total
 * diffuse reflectance against Jensen et al. 2001's R_d in the classical dipole's limit and
 * against energy conservation at alpha' = 1; the profile's plane integrals against their closed
 * forms; the line kernel (K0, K1) against direct quadrature of the 3-D profile along z; the
 * strip quadrature against the plane integrals and its convergence in [bdipole] samples; the
 * method on every study config (finite, non-negative, totals within the profile's bounds), at
 * the robustness grid's corners and in slab mode; bdipole+ss = bdipole + ss cell by cell. */
#include "testutil.h"
#include "study_cases.h"
#include "profileutil.h"

#include <math.h>

#include "kernels/ppb_fresnel.h"
#include "methods/bdipole/bdipole_profile.h"
#include "methods/registry.h"
#include "model/config.h"
#include "physics/diffuse_exit.h"

static void test_fresnel_moments(void **state)
{
    (void)state;
    /* C_i = int_0^1 F(mu, 1/n) mu^i dmu against mpmath's tanh-sinh quadrature at 40 digits
     * directly in the inside cosine, split at the critical cosine
     * (tests/data/gen_bdipole_moments.py); C1 also against 2 C1 = the internal diffuse Fresnel
     * reflectance of physics/diffuse_exit.h (Prahl's identity from F_dr,e); 0 at n = 1. */
    static const double ref[][3] = {{1.1, 0.0971724617160648975, 0.0293065807490385511},
                                    {1.2, 0.168152870220622862, 0.0661653927065029583},
                                    {1.33, 0.235974574396349544, 0.109412841202367106},
                                    {1.4, 0.264492741218610438, 0.129594274758454833},
                                    {1.5, 0.298172879853855825, 0.154810174026563636},
                                    {2.5, 0.43774932588175703, 0.273546735438323362}};
    double worst = 0;
    for (size_t i = 0; i < sizeof ref / sizeof ref[0]; i++) {
        double c1 = ppb_bdipole_fresnel_moment(1, ref[i][0]);
        double c2 = ppb_bdipole_fresnel_moment(2, ref[i][0]);
        worst = fmax(worst, fmax(fabs(c1 / ref[i][1] - 1), fabs(c2 / ref[i][2] - 1)));
        assert_rel(2 * c1, ppb_diffuse_fresnel(1 / ref[i][0]), 1e-13);
    }
    print_message("Fresnel moments: largest relative error against mpmath %.2e\n", worst);
    assert_lt(worst, 1e-13);
    assert_close(ppb_bdipole_fresnel_moment(1, 1.0), 0.0, 0.0);
    assert_close(ppb_bdipole_fresnel_moment(2, 1.0), 0.0, 0.0);
}

static void test_rd_closed_form(void **state)
{
    (void)state;
    /* The classical dipole is this model with Jensen et al. 2001's choices: D = 1 / (3
     * sigma_t'), sigma_tr = sqrt(3 sigma_a sigma_t'), z_v = -(z_r + 4 A D) with A = (1 + F_dr) /
     * (1 - F_dr), and the exitance the flux alone (C_phi = 0, C_E = 1). The closed-form plane
     * integral at h = 0 must then be their Eq. (R_d) = (alpha' / 2) (1 + e^(-(4/3) A
     * sqrt(3 (1 - alpha')))) e^(-sqrt(3 (1 - alpha'))), in units sigma_t' = 1. */
    const double alpha[] = {0.01, 0.3, 0.8, 0.95, 0.999}, A[] = {1.0, 2.948};
    for (int i = 0; i < 5; i++)
        for (int k = 0; k < 2; k++) {
            double a = alpha[i], D = 1.0 / 3.0, s = sqrt(3.0 * (1 - a));
            ppb_bdipole j = {.alpha = a,
                             .D = D,
                             .sigma_tr = s,
                             .zr = 1.0,
                             .zv = -(1.0 + 4 * A[k] * D),
                             .c_phi = 0.0,
                             .c_e = 1.0};
            double jensen = 0.5 * a * (1 + exp(-4.0 / 3.0 * A[k] * s)) * exp(-s);
            assert_rel(ppb_bdipole_plane(&j, 0.0), jensen, 1e-14);
        }
    /* Energy: at albedo 1 (alpha' = 1, sigma_tr = 0) all that enters returns through a
     * semi-infinite medium: C_phi 4 A + C_E = (1 + 3 C2) / 2 + (1 - 3 C2) / 2 = 1, for any n
     * and g. Just below, 1 - R_d vanishes like sigma_tr, i.e. like sqrt(1 - albedo): a hundred
     * times closer to 1 in albedo, ten times closer in R_d (to 1 %). */
    const double n[] = {1.0, 1.33, 2.5}, g[] = {-0.5, 0.0, 0.9};
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            ppb_bdipole b = ppb_bdipole_make(2.0, 1.0, g[k], n[i]);
            assert_close(b.sigma_tr, 0.0, 0.0);
            assert_rel(ppb_bdipole_plane(&b, 0.0), 1.0, 1e-14);
            ppb_bdipole c8 = ppb_bdipole_make(2.0, 1.0 - 1e-8, g[k], n[i]);
            ppb_bdipole c10 = ppb_bdipole_make(2.0, 1.0 - 1e-10, g[k], n[i]);
            double d8 = 1 - ppb_bdipole_plane(&c8, 0.0), d10 = 1 - ppb_bdipole_plane(&c10, 0.0);
            assert_lt(0, d10);
            assert_between(d8 / d10, 9.9, 10.1);
        }
    /* Nothing scatters, nothing returns. */
    ppb_bdipole z = ppb_bdipole_make(1.0, 0.0, 0.0, 1.4);
    assert_close(ppb_bdipole_plane(&z, 0.0), 0.0, 0.0);
}

typedef struct prof_arg {
    const ppb_bdipole *b;
    double h; /* plane distance or in-plane distance, by use */
} prof_arg;

/* The ring at in-plane radius t of the plane at distance h. */
static double ring(double t, const void *arg)
{
    const prof_arg *p = arg;
    return 2 * PPB_PI * t * ppb_bdipole_R(p->b, sqrt(t * t + p->h * p->h));
}

/* Both halves of the z axis at in-plane distance rho = h. */
static double along_z(double z, const void *arg)
{
    const prof_arg *p = arg;
    return 2 * ppb_bdipole_R(p->b, sqrt(p->h * p->h + z * z));
}

/* int_0^inf f by pu_graded (test_burley.c's independent quadrature): [0, T] directly (panels of
 * h beyond the grading toward 0), [T, inf) as
 * int_0^(1/T) f(1 / w) / w^2 dw (the algebraic tail at sigma_tr = 0 becomes smooth, and w is
 * exact near 0 where t is large). T = 200 / sigma_tr (the profile below e^-200 beyond) and
 * h = 0.25 / sigma_tr; at sigma_tr = 0, T = 1 and h = 0.25. */
typedef struct inv_arg {
    pu_fn1 f;
    const void *arg;
} inv_arg;

static double inverted(double w, const void *arg)
{
    const inv_arg *q = arg;
    return q->f(1 / w, q->arg) / (w * w);
}

static double to_infinity(pu_fn1 f, const prof_arg *p)
{
    double s = p->b->sigma_tr, T = s > 0 ? 200 / s : 1, h = s > 0 ? 0.25 / s : 0.25;
    inv_arg q = {f, p};
    return pu_graded(f, p, 0, T, h) + pu_graded(inverted, &q, 0, 1 / T, 1e-3 / T);
}

/* Media in units of 1/sigma_t: (sigma_t, albedo, g, n), from strongly absorbing to albedo 1
 * (sigma_tr = 0). */
static const double media[][4] = {{1.0, 0.3, 0.0, 1.0},   {1.0, 0.95, 0.0, 1.0},
                                  {2.0, 0.8, 0.5, 1.4},   {0.5, 0.99, -0.5, 1.33},
                                  {1.0, 0.999, 0.9, 2.5}, {1.0, 1.0, 0.0, 1.4}};
#define NMEDIA (sizeof media / sizeof media[0])

static ppb_bdipole medium(size_t i)
{
    return ppb_bdipole_make(media[i][0], media[i][1], media[i][2], media[i][3]);
}

static void test_plane_integral(void **state)
{
    (void)state;
    /* 2 pi int R(sqrt(t^2 + h^2)) t dt over the plane at distance h, by quadrature of the 3-D
     * profile (graded Gauss-Legendre in t up to 1, in 1 / t beyond), against the closed form P(h)
     * (bdipole_profile.h); h = 0 is R_d. */
    const double h[] = {0.0, 0.3, 1.0, 3.0};
    double worst = 0;
    for (size_t i = 0; i < NMEDIA; i++) {
        ppb_bdipole b = medium(i);
        for (int k = 0; k < 4; k++) {
            prof_arg p = {&b, h[k]};
            double num = to_infinity(ring, &p);
            worst = fmax(worst, fabs(num / ppb_bdipole_plane(&b, h[k]) - 1));
        }
        print_message("medium %zu: alpha' %.4f sigma_tr %.4f R_d %.6f\n", i, b.alpha, b.sigma_tr,
                      ppb_bdipole_plane(&b, 0.0));
    }
    print_message("plane integrals: largest relative error %.2e\n", worst);
    assert_lt(worst, 1e-13);
}

static void test_line_kernel(void **state)
{
    (void)state;
    /* The line kernel (2 K0 for the fluence pair, 2 z s K1(s q) / q for the flux terms, their
     * s -> 0 limits at albedo 1) against the 3-D profile integrated along z directly. */
    const double rho[] = {0.0, 1e-3, 0.05, 0.3, 1.0, 3.0, 10.0};
    double worst = 0;
    for (size_t i = 0; i < NMEDIA; i++) {
        ppb_bdipole b = medium(i);
        for (int k = 0; k < 7; k++) {
            prof_arg p = {&b, rho[k]};
            double direct = to_infinity(along_z, &p);
            worst = fmax(worst, fabs(ppb_bdipole_line(&b, rho[k]) / direct - 1));
        }
    }
    print_message("line kernel: largest relative error %.2e\n", worst);
    assert_lt(worst, 1e-13);
}

/* At sigma_tr = 0 the line kernel at rho^2 = u^2 + v^2 is alpha' / (2 pi) (C_phi / (2 D)
 * ln((u^2 + b^2) / (u^2 + a^2)) + C_E (z_r / (u^2 + a^2) + |z_v| / (u^2 + b^2))), a^2 = v^2 +
 * z_r^2, b^2 = v^2 + z_v^2; its integral over |u| > L, from int_L^inf du / (u^2 + a^2) =
 * atan(a / L) / a and int_L^inf ln((u^2 + b^2) / (u^2 + a^2)) du = 2 b atan(b / L) -
 * 2 a atan(a / L) - L ln((L^2 + b^2) / (L^2 + a^2)) (by parts). */
static double strip_tail(const ppb_bdipole *p, double L, double v)
{
    double zr = p->zr, zv = -p->zv, a = sqrt(v * v + zr * zr), b = sqrt(v * v + zv * zv);
    double logs =
        2 * b * atan(b / L) - 2 * a * atan(a / L) - L * log1p((b * b - a * a) / (L * L + a * a));
    double flux = zr * atan(a / L) / a + zv * atan(b / L) / b;
    return 2 * p->alpha * (p->c_phi * logs / (2 * p->D) + p->c_e * flux) / (2 * PPB_PI);
}

static void test_strip_quadrature(void **state)
{
    (void)state;
    /* The whole line of entry points (u over [-L, L]) against the plane integral P(|v|): at
     * v = 0 the exit point on S1 (R_d), at depth v a plane at distance |v|. For sigma_tr > 0,
     * L = 400 / sigma_tr (the profile below e^-100 beyond); at sigma_tr = 0 (albedo 1) the line
     * kernel falls like 1 / u^2 and the strip to L = 1e4 misses its tail beyond L, which the
     * expected value takes off in closed form (strip_tail). Halves add up at any cut.
     * Convergence in nodes per 1 / sigma_tr ([bdipole] samples) printed; at the default 16
     * within 1e-13. */
    const double v[] = {0.0, -1e-6, -0.01, -0.5, -3.0};
    const int nodes[] = {1, 2, 4, 16};
    for (int k = 0; k < 4; k++) {
        double worst = 0;
        for (size_t i = 0; i < NMEDIA; i++) {
            ppb_bdipole b = medium(i);
            double L = b.sigma_tr > 0 ? 400 / b.sigma_tr : 1e4;
            for (int j = 0; j < 5; j++) {
                double tail = b.sigma_tr > 0 ? 0 : strip_tail(&b, L, v[j]);
                double exact = ppb_bdipole_plane(&b, fabs(v[j])) - tail;
                double got = ppb_bdipole_strip(&b, -L, L, v[j], nodes[k]);
                worst = fmax(worst, fabs(got / exact - 1));
                double left = ppb_bdipole_strip(&b, -L, 0.37, v[j], nodes[k]);
                double right = ppb_bdipole_strip(&b, 0.37, L, v[j], nodes[k]);
                worst = fmax(worst, fabs((left + right) / exact - 1));
            }
        }
        print_message("strip quadrature: %2d nodes per 1/sigma_tr: largest relative error %.2e\n",
                      nodes[k], worst);
        if (nodes[k] == 16)
            assert_lt(worst, 1e-13);
    }
}

/* A study config's totals against the bounds of test_study_configs. */
static void study_bounds(const char *name, ppb_run_ctx *ctx, const ppb_result *out)
{
    const ppb_scene *sc = &ctx->cfg->scene;
    double Rd = 0, PH = 0, entry = pu_entry(sc);
    for (int side = 0; side < 2; side++) {
        double st, al;
        pu_side_medium(sc, side, &st, &al);
        ppb_bdipole b = ppb_bdipole_make(st, al, sc->g, sc->n);
        Rd = fmax(Rd, ppb_bdipole_plane(&b, 0.0));
        PH = fmax(PH, ppb_bdipole_plane(&b, sc->height));
    }
    double sum = out->totals.R + out->totals.T + out->totals.sides;
    print_message("%-24s R_d %.4f  R %.4f T %.4f sides %.4f  sum %.4f  ballistic %.4f\n", name, Rd,
                  out->totals.R, out->totals.T, out->totals.sides, sum, out->totals.ballistic);
    assert_le(out->totals.R, entry * Rd * (1 + 1e-12));
    assert_le(out->totals.T, entry * PH * (1 + 1e-12));
    assert_le(out->totals.sides, entry * Rd * (1 + 1e-12));
    assert_lt(0, out->totals.T);               /* light does reach the far face */
    assert_le(sum + out->totals.ballistic, 1); /* the result check's energy bound holds */
}

static void test_study_configs(void **state)
{
    (void)state;
    /* bdipole on every study config (configs/study.list): every radiance finite and >= 0, and
     * the totals within the profile's bounds. R(r) falls with r, so its integral over a plane at
     * distance h, P(h), falls with h: for an entry point, S1 lies in the profile's plane (at
     * most R_d), S2 in the plane at distance H (at most P(H)), each side in a half plane at some
     * distance (at most R_d / 2); times the entering 1 - F(theta_L), with the larger of the
     * tube's two media. */
    pu_study_configs("bdipole", NULL, study_bounds);
}

/* R at a corner of the robustness grid within (1 - F) R_d (test_extremes). */
static void corner_bounds(const pu_corner *c, ppb_run_ctx *ctx, const ppb_result *out)
{
    ppb_bdipole b = ppb_bdipole_make(ctx->cfg->scene.sigma_t, c->albedo, c->g, c->n);
    double Rd = ppb_bdipole_plane(&b, 0.0);
    assert_between(Rd, 0, 1 + 1e-14);
    assert_le(out->totals.R, Rd * (1 + 1e-12));
}

static void test_extremes(void **state)
{
    (void)state;
    /* The corners of the robustness grid (tests/test_robust.c's values): albedo 0 to 1, g
     * +-0.95, H from 1e-3 to 1e3, theta_L 0 and 89 deg, n 1 and 2.5, tube and slab: every cell
     * finite and >= 0, R within (1 - F) R_d, and the method's result checks passed. */
    const double albedo[] = {0, 0.01, 0.5, 0.999, 1}, g[] = {-0.95, 0, 0.95},
                 height[] = {1e-3, 1, 1e3}, theta[] = {0, 89}, n[] = {1, 2.5};
    pu_grid grid = {1, PU_AXIS(albedo), PU_AXIS(g), PU_AXIS(height), PU_AXIS(theta), PU_AXIS(n)};
    pu_extremes("bdipole", &grid, NULL, corner_bounds);
}

static void set_samples(ppb_config *cfg, int samples)
{
    cfg->bdipole.samples = samples;
}

static void test_quadrature_converges_on_tube(void **state)
{
    (void)state;
    /* The method's quadrature error on the tube (uniform_g0_normal, density_step, and albedo 1
     * where sigma_tr = 0): every cell at [bdipole] samples = 16 (default) and 8 against 64. */
    pu_samples_converge("bdipole", "uniform_g0_normal", NAN, set_samples);
    pu_samples_converge("bdipole", "density_step", NAN, set_samples);
    pu_samples_converge("bdipole", "uniform_g0_normal_n14", 1.0, set_samples);
}

/* A slab's totals and S1's lobe (test_slab_mode). */
static void slab_totals(ppb_run_ctx *ctx, const ppb_result *out, double mu, double entry)
{
    const ppb_scene *sc = &ctx->cfg->scene;
    ppb_bdipole b = ppb_bdipole_make(sc->sigma_t, 0.95, 0.0, sc->n);
    assert_rel(out->totals.R, entry * ppb_bdipole_plane(&b, 0.0), 1e-14);
    assert_rel(out->totals.T, entry * ppb_bdipole_plane(&b, 3.0), 1e-14);
    pu_assert_lobe_mean(out, mu);
}

static void test_slab_mode(void **state)
{
    (void)state;
    /* Slab mode: R = (1 - F) P(0) and T = (1 - F) P(H) (the closed-form plane integrals),
     * radiance R cos(theta_L) / pi on S1 at n = 1; at n = 1.4 the exit lobe distributes the
     * same flux (its bins' mean is 1). */
    pu_slab_mode("bdipole", slab_totals);
}

static void test_sum_with_ss(void **state)
{
    (void)state;
    study_check_sum_with_ss("bdipole");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fresnel_moments),
        cmocka_unit_test(test_rd_closed_form),
        cmocka_unit_test(test_plane_integral),
        cmocka_unit_test(test_line_kernel),
        cmocka_unit_test(test_strip_quadrature),
        cmocka_unit_test(test_study_configs),
        cmocka_unit_test(test_extremes),
        cmocka_unit_test(test_quadrature_converges_on_tube),
        cmocka_unit_test(test_slab_mode),
        cmocka_unit_test(test_sum_with_ss),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
