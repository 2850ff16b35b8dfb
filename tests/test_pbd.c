/* test_pbd.c: the `pbd` method (src/methods/pbd/; reference: Methods, `pbd`): photon beam
 * diffusion as pbrt-v4 ships it. pbrt's Fresnel moment fits against the exact moments, the beam
 * integrals (BeamDiffusionMS, BeamDiffusionSS) against an independent implementation and the
 * unsampled integrals they estimate (tests/data/gen_pbd_ref.py, scipy quad), the table's rhoEff
 * against the radial integral of the same, the Catmull-Rom spline's order and exactness, Sr at
 * the table's nodes and its scaling in sigma_t, the plane integral against the mixed rhoEff, the
 * strip quadrature against an independent polar-coordinate integral, and the method on every
 * study config, in slab mode and at the extremes. */
#include "testutil.h"
#include "study_cases.h"
#include "profileutil.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "kernels/ppb_fresnel.h"
#include "methods/pbd/method_pbd.h"
#include "methods/pbd/pbd_profile.h"
#include "methods/pbd/pbd_table.h"
#include "methods/registry.h"
#include "model/config.h"

/* int_0^1 F(mu, 1 / eta) mu^k dmu of the exact Fresnel reflectance, composite 16-point
 * Gauss-Legendre split at the critical cosine (F is 1 below it and smooth above). */
static double exact_moment(double eta, int k)
{
    double mu_c = eta > 1 ? sqrt(1 - 1 / (eta * eta)) : 0, x[16], w[16], sum = mu_c > 0 ? 0 : 0;
    if (mu_c > 0)
        sum += pow(mu_c, k + 1) / (k + 1); /* total internal reflection */
    const int panels = 64;
    for (int p = 0; p < panels; p++) {
        double a = mu_c + (1 - mu_c) * p / panels, b = mu_c + (1 - mu_c) * (p + 1) / panels;
        tu_gauss_legendre(16, a, b, x, w);
        for (int j = 0; j < 16; j++)
            sum += w[j] * ppb_fresnel(x[j], 1 / eta) * pow(x[j], k);
    }
    return sum;
}

static void test_fresnel_moments(void **state)
{
    (void)state;
    /* pbrt's fits FresnelMoment_k(eta) are int_0^1 F(mu, 1 / eta) mu^k dmu (the reflectance met
     * from inside at relative index eta), to within 2 % over eta 1.2 to 1.5 (the fits' own
     * accuracy, measured here against the exact moments: C2 at eta = 1.2 is the worst, 1.7 %);
     * at eta = 1 they are 0.00217 and
     * -0.00221, not 0 (pbrt uses them as they are). */
    const double eta[] = {1.2, 1.33, 1.4, 1.5};
    double worst = 0;
    for (int i = 0; i < 4; i++) {
        double e1 = exact_moment(eta[i], 1), e2 = exact_moment(eta[i], 2);
        double f1 = ppb_pbd_fresnel_moment1(eta[i]), f2 = ppb_pbd_fresnel_moment2(eta[i]);
        worst = fmax(worst, fmax(fabs(f1 / e1 - 1), fabs(f2 / e2 - 1)));
        print_message("eta %.2f: C1 fit %.5f exact %.5f, C2 fit %.5f exact %.5f\n", eta[i], f1, e1,
                      f2, e2);
    }
    assert_lt(worst, 0.02);
    assert_rel(ppb_pbd_fresnel_moment1(1.0), 0.00217, 1e-9);
    assert_rel(ppb_pbd_fresnel_moment2(1.0), -0.00221, 1e-6);
    /* The exit lobe's normaliser c = 1 - 2 FresnelMoment1(1 / eta) is 1 - F_dr,e, the mean of
     * 1 - F over the hemisphere from air: the same fit at 1 / eta (0.03 % at n = 1.4). */
    assert_rel(ppb_pbd_fresnel_moment1(1 / 1.4), exact_moment(1 / 1.4, 1), 1e-3);
}

typedef struct ref_row {
    char kind[8];
    double a, g, eta, r, sampled, unsampled;
} ref_row;

static int load_ref(ref_row *rows, int max)
{
    FILE *f = fopen(PPB_SOURCE_DIR "/tests/data/pbd_ref.csv", "r");
    assert_non_null(f);
    char line[512];
    int n = 0;
    assert_non_null(fgets(line, sizeof line, f)); /* header */
    while (n < max && fgets(line, sizeof line, f)) {
        ref_row *r = &rows[n];
        char *comma = strchr(line, ',');
        assert_non_null(comma);
        size_t len = (size_t)(comma - line);
        assert_true(len < sizeof r->kind);
        memcpy(r->kind, line, len);
        r->kind[len] = 0;
        assert_int_equal(sscanf(comma + 1, "%lf,%lf,%lf,%lf,%lf,%lf", &r->a, &r->g, &r->eta, &r->r,
                                &r->sampled, &r->unsampled),
                         6);
        n++;
    }
    fclose(f);
    return n;
}

static double beam(const ref_row *r, int samples)
{
    double rho = r->a;
    return strcmp(r->kind, "ms") == 0 ? ppb_pbd_ms(rho, 1 - rho, r->g, r->eta, r->r, samples)
                                      : ppb_pbd_ss(rho, 1 - rho, r->g, r->eta, r->r, samples);
}

static void test_beam_integrals(void **state)
{
    (void)state;
    /* BeamDiffusionMS and BeamDiffusionSS at sigma_t = 1 (pbd_ref.csv, gen_pbd_ref.py):
     * - at pbrt's 100 samples, against the script's own transcription of the formulas (same
     *   estimator, independent code): to rounding;
     * - the estimator converges to the integral it samples (scipy quad of the unsampled
     *   formula): at 2e4 samples within 1e-4 (7.4e-5 and 2.9e-5 for single scattering at r = 0.01,
     *   n = 1.4, where 1 - F rises as a square root from the critical depth t_c, the beam's
     *   first, which slows the midpoint quantiles; 4e-6 or less elsewhere), its error at 100
     * samples (pbrt's) below 7 % near the source (r = 0.01: single scattering peaks at depth t ~ r
     * there, which pbrt's first quantile, t = 0.005 / sigma_t, resolves coarsely; measured 6.1 %)
     * and below 0.6 % at r >= 0.1, and at 2e4 samples below its error at 100 and 400 wherever that
     * is above 1e-6 (near the source the error is not monotone in the count: the quantiles can land
     * well by chance, 3.2e-3 at 100 against 8.6e-3 at 400 for that same row). */
    ref_row rows[64];
    int n = load_ref(rows, 64), beams = 0;
    for (int i = 0; i < n; i++) {
        const ref_row *r = &rows[i];
        if (strcmp(r->kind, "ms") && strcmp(r->kind, "ss"))
            continue;
        beams++;
        assert_rel(beam(r, 100), r->sampled, 1e-11);
        double e25 = fabs(beam(r, 25) / r->unsampled - 1);
        double e100 = fabs(beam(r, 100) / r->unsampled - 1);
        double e400 = fabs(beam(r, 400) / r->unsampled - 1);
        double efine = fabs(beam(r, 20000) / r->unsampled - 1);
        print_message("%s rho %.2f g %+.1f eta %.1f r %-5g: error at 25/100/400/2e4 samples "
                      "%.1e %.1e %.1e %.1e\n",
                      r->kind, r->a, r->g, r->eta, r->r, e25, e100, e400, efine);
        assert_lt(efine, 1e-4);
        assert_lt(e100, r->r < 0.05 ? 0.07 : 0.006);
        if (e100 > 1e-6) {
            assert_lt(efine, e100);
            assert_lt(efine, e400);
        }
    }
    assert_int_equal(beams, 24);
}

static void test_rho_eff(void **state)
{
    (void)state;
    /* The table's rhoEff (the spline integral of each row, pbrt's IntegrateCatmullRom) against
     * scipy's adaptive integral of the same 100-sample profile over r to the table's last
     * radius: the spline's integration error on pbrt's geometric radii (ratio 1.2), below 1e-3
     * (measured 8.4e-4 at row 50, g = -0.5, where back-scattering makes single scattering's
     * r log(1 / r) rise at the entry point largest; 1.1e-4 and 3.9e-5 at the others); against
     * the unsampled profile's integral the beam sampling's error is added (3.6e-4 at most
     * between the script's two integrals): below 1.5e-3 (pbd_ref.csv, rows 70, 90, 50). */
    ref_row rows[64];
    int n = load_ref(rows, 64), found = 0;
    static ppb_pbd_table t;
    for (int i = 0; i < n; i++) {
        const ref_row *r = &rows[i];
        if (strcmp(r->kind, "rhoeff"))
            continue;
        found++;
        ppb_pbd_table_build(&t, r->g, r->eta, PPB_PBD_SAMPLES);
        int row = (int)r->a;
        double e = t.rho_eff[row];
        print_message("row %d (albedo %.5f) g %+.1f eta %.1f: rhoEff %.6f, quad %.6f, unsampled "
                      "%.6f\n",
                      row, t.rho[row], r->g, r->eta, e, r->sampled, r->unsampled);
        assert_rel(e, r->sampled, 1e-3);
        assert_rel(e, r->unsampled, 1.5e-3);
    }
    assert_int_equal(found, 3);
    /* pbrt's grids: albedo 0 and 1 at the ends, radii 0, 2.5e-3, ..., 2.5e-3 1.2^62. */
    assert_close(t.rho[0], 0, 0);
    assert_close(t.rho[PPB_PBD_NRHO - 1], 1, 1e-15);
    assert_rel(t.radius[PPB_PBD_NR - 1], 2.5e-3 * pow(1.2, 62), 1e-13);
}

/* The spline through f at nodes x[0..n-1], at s. */
static double cr_eval(const double *x, const double *f, int n, double s)
{
    int off;
    double w[4], sum = 0;
    assert_true(ppb_pbd_cr_weights(x, n, s, &off, w));
    for (int k = 0; k < 4; k++)
        if (w[k] != 0)
            sum += w[k] * f[off + k];
    return sum;
}

/* Largest error of the spline of sin on [0, 3] with n uniform nodes, over the interior
 * intervals (the end ones use one-sided slopes). */
static double cr_error(int n)
{
    double x[512], f[512], worst = 0;
    for (int i = 0; i < n; i++) {
        x[i] = 3.0 * i / (n - 1);
        f[i] = sin(x[i]);
    }
    for (int i = 1; i < n - 2; i++)
        for (int j = 1; j < 10; j++) {
            double s = x[i] + (x[i + 1] - x[i]) * j / 10.0;
            worst = fmax(worst, fabs(cr_eval(x, f, n, s) - sin(s)));
        }
    return worst;
}

static void test_catmull_rom(void **state)
{
    (void)state;
    /* On uniform nodes the central-difference slopes are exact for a quadratic, so the cubic
     * Hermite spline reproduces it (interior intervals) and its integral; for a smooth
     * function the error falls as h^3 (the slopes' O(h^2) error times h): ratio near 8 per
     * halving. The weights sum to 1 (constants reproduced) and interpolate at the nodes. */
    double x[11], f[11];
    for (int i = 0; i < 11; i++) {
        x[i] = 0.5 * i;
        f[i] = 1 - 2 * x[i] + 0.75 * x[i] * x[i];
    }
    for (double s = 0.5; s <= 4.5; s += 0.13)
        assert_close(cr_eval(x, f, 11, s), 1 - 2 * s + 0.75 * s * s, 1e-13);
    for (int i = 0; i < 11; i++)
        assert_close(cr_eval(x, f, 11, x[i]), f[i], 1e-15);
    double e[4];
    for (int k = 0; k < 4; k++)
        e[k] = cr_error(16 << k);
    print_message("Catmull-Rom of sin, interior: error %.2e %.2e %.2e %.2e (ratios %.2f %.2f "
                  "%.2f)\n",
                  e[0], e[1], e[2], e[3], e[0] / e[1], e[1] / e[2], e[2] / e[3]);
    for (int k = 0; k < 3; k++)
        assert_between(e[k] / e[k + 1], 7.0, 9.0);
    /* Outside the nodes: no weights (pbrt's Sr is then 0). */
    int off;
    double w[4];
    assert_false(ppb_pbd_cr_weights(x, 11, -1e-9, &off, w));
    assert_false(ppb_pbd_cr_weights(x, 11, 5 + 1e-9, &off, w));
    /* The integral (IntegrateCatmullRom) is the spline's own: against 4-point Gauss-Legendre
     * per interval of the spline (exact for a cubic), on pbrt's geometric radii. */
    double r[PPB_PBD_NR], g[PPB_PBD_NR], xg[4], wg[4], sum = 0;
    r[0] = 0;
    r[1] = 2.5e-3;
    for (int i = 2; i < PPB_PBD_NR; i++)
        r[i] = 1.2 * r[i - 1];
    for (int i = 0; i < PPB_PBD_NR; i++)
        g[i] = r[i] * exp(-r[i]);
    for (int i = 0; i + 1 < PPB_PBD_NR; i++) {
        tu_gauss_legendre(4, r[i], r[i + 1], xg, wg);
        for (int j = 0; j < 4; j++)
            sum += wg[j] * cr_eval(r, g, PPB_PBD_NR, xg[j]);
    }
    assert_rel(ppb_pbd_cr_integral(r, g, PPB_PBD_NR), sum, 1e-13);
    assert_rel(sum, 1.0, 2e-3); /* int_0^inf r e^-r dr = 1: the spline is close */
}

static const ppb_pbd_table *table(double g, double eta)
{
    static ppb_pbd_table t;
    if (t.radius[1] == 0 || t.g != g || t.eta != eta)
        ppb_pbd_table_build(&t, g, eta, PPB_PBD_SAMPLES);
    return &t;
}

static void test_sr_nodes_and_scaling(void **state)
{
    (void)state;
    /* At a table albedo and radius Sr is the table's entry / (2 pi r) sigma_t^2 (the spline
     * interpolates); Sr(r; sigma_t) = sigma_t^2 Sr(sigma_t r; 1) (optical radius); 0 past the
     * last radius. */
    const ppb_pbd_table *t = table(0.0, 1.4);
    ppb_pbd_profile p, p1;
    ppb_pbd_profile_init(&p, t, 2.0, t->rho[80]);
    ppb_pbd_profile_init(&p1, t, 1.0, t->rho[80]);
    for (int k = 1; k < PPB_PBD_NR; k++) {
        double r = t->radius[k] / 2.0;
        double want = t->profile[80 * PPB_PBD_NR + k] / (2 * PPB_PI * t->radius[k]) * 4.0;
        assert_rel(ppb_pbd_sr(&p, r), fmax(want, 0), 1e-12);
    }
    for (double r = 1e-3; r < 50; r *= 1.7)
        assert_rel(ppb_pbd_sr(&p, r), 4.0 * ppb_pbd_sr(&p1, 2 * r), 1e-12);
    assert_close(ppb_pbd_sr(&p, t->radius[PPB_PBD_NR - 1] / 2.0 * 1.001), 0, 0);
}

/* The spline's negative part, int min(P, 0) over the optical radius: where it dips below 0 far
 * out (the geometric intervals are wide against the profile's exponential decay there), Sr is
 * clamped to 0 (pbrt's ClampZero) and the plane integral loses it. 16 sub-panels of 8-point
 * Gauss-Legendre per table interval. */
static double negative_mass(const ppb_pbd_profile *p)
{
    double sum = 0, x[8], w[8];
    for (int k = 0; k + 1 < PPB_PBD_NR; k++)
        for (int s = 0; s < 16; s++) {
            double a = p->radius[k] + (p->radius[k + 1] - p->radius[k]) * s / 16.0;
            double b = p->radius[k] + (p->radius[k + 1] - p->radius[k]) * (s + 1) / 16.0;
            tu_gauss_legendre(8, a, b, x, w);
            for (int j = 0; j < 8; j++)
                sum += w[j] * fmin(0, cr_eval(p->radius, p->p, PPB_PBD_NR, x[j]));
        }
    return sum;
}

static void test_plane_integral(void **state)
{
    (void)state;
    /* The plane integral of Sr is rhoEff mixed by the albedo weights (the spline's integral is
     * linear in its values) less the spline's negative part, which the clamp removes (a few
     * 1e-10 here: the nodes far out, optical radius > 13, are below 1e-9), and 2 pi int Sr r dr
     * of ppb_pbd_sr by 8-point Gauss-Legendre on 16 sub-panels of each table interval (a route
     * through Sr, not the spline) agrees; beyond h the same with the lower limit h. */
    const double albedo[] = {0.3, 0.8, 0.95, 0.999};
    const ppb_pbd_table *t = table(0.5, 1.4);
    for (int i = 0; i < 4; i++) {
        ppb_pbd_profile p;
        ppb_pbd_profile_init(&p, t, 1.5, albedo[i]);
        double R = ppb_pbd_plane(&p, 0.0), x[8], w[8];
        double neg = negative_mass(&p);
        assert_true(neg <= 0);
        assert_close(R, p.rho_eff - neg, 1e-2 * fabs(neg) + 1e-14);
        for (int hi = 0; hi < 2; hi++) {
            double h = hi ? 0.7 : 0.0, sum = 0;
            for (int k = 0; k + 1 < PPB_PBD_NR; k++) {
                double a = fmax(h, t->radius[k] / 1.5), b = t->radius[k + 1] / 1.5;
                for (int m = 0; m < 16 && b > a; m++) {
                    tu_gauss_legendre(8, a + (b - a) * m / 16, a + (b - a) * (m + 1) / 16, x, w);
                    for (int j = 0; j < 8; j++)
                        sum += w[j] * 2 * PPB_PI * x[j] * ppb_pbd_sr(&p, x[j]);
                }
            }
            assert_rel(ppb_pbd_plane(&p, h), sum, 1e-9);
        }
        print_message("albedo %.3f: R %.6f (rhoEff %.6f, negative part %.1e), beyond 0.7: %.6f\n",
                      albedo[i], R, p.rho_eff, neg, ppb_pbd_plane(&p, 0.7));
    }
}

/* The angle of the circle of radius s about the exit point's foot inside the strip u in [ua,
 * ub] of the (u, z) plane: 2 (acos(ua / s) - acos(ub / s)), cosines clamped to [-1, 1]. */
static double strip_angle(double s, double ua, double ub)
{
    double ca = fmax(-1, fmin(1, ua / s)), cb = fmax(-1, fmin(1, ub / s));
    return 2 * (acos(ca) - acos(cb));
}

static int add_edge(double *e, int n, double v)
{
    if (v > 0)
        e[n++] = v;
    return n;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Independent reference of the strip integral: in polar coordinates (s, phi) of the (u, z)
 * plane about the exit point's foot, int_0^inf s Sr(sqrt(s^2 + v^2)) angle(s) ds, one
 * dimension: panels at the table radii (s_k = sqrt(R_k^2 - v^2)) and at |ua|, |ub| (the angle's
 * square-root kinks), each graded geometrically toward every edge from both sides down to 1e-13
 * of it, 16-point Gauss-Legendre on each sub-panel. */
static double strip_polar(const ppb_pbd_profile *p, double ua, double ub, double v)
{
    double e[256];
    int n = 0;
    e[n++] = 0;
    for (int k = 1; k < PPB_PBD_NR; k++) {
        double R = p->radius[k] / p->sigma_t;
        if (R > v)
            n = add_edge(e, n, sqrt(R * R - v * v));
    }
    n = add_edge(e, n, fabs(ua));
    n = add_edge(e, n, fabs(ub));
    qsort(e, (size_t)n, sizeof e[0], cmp_double);
    double sum = 0, x[16], w[16];
    for (int i = 0; i + 1 < n; i++) {
        double a = e[i], b = e[i + 1];
        if (!(b > a * (1 + 1e-15)))
            continue;
        double mid = 0.5 * (a + b);
        /* geometric sub-panels toward a and toward b */
        for (int side = 0; side < 2; side++) {
            double lo = side ? mid : a, hi = side ? b : mid;
            for (int m = 0; m < 44; m++) {
                double f0 = pow(0.5, m + 1), f1 = pow(0.5, m);
                double pa = side ? hi - (hi - lo) * f1 : lo + (hi - lo) * f0;
                double pb = side ? hi - (hi - lo) * f0 : lo + (hi - lo) * f1;
                if (m == 43) {
                    if (side)
                        pb = hi;
                    else
                        pa = lo;
                }
                tu_gauss_legendre(16, pa, pb, x, w);
                for (int j = 0; j < 16; j++)
                    sum += w[j] * x[j] * ppb_pbd_sr(p, sqrt(x[j] * x[j] + v * v)) *
                           strip_angle(x[j], ua, ub);
            }
        }
    }
    return sum;
}

static void test_strip_quadrature(void **state)
{
    (void)state;
    /* ppb_pbd_strip (Gauss-Legendre panels in x and z, [pbd] nodes = 6: the default) against
     * the polar-coordinate reference: exit points on the strip (v = 0, inside and outside it),
     * below it (v = 0.5, 3: S2 at the study's H) and beside it (a side wall), two media. Within
     * 1e-6 of the value at the default nodes, 1e-9 at 12, or 1e-11 and 1e-12 absolute per unit
     * irradiance: far out (optical radius > 13) the spline dips below 0 and pbrt's clamp puts
     * kinks in Sr that no panel edge follows (where Sr is below 1e-9 of the plane integral). */
    const struct {
        double ua, ub, v;
    } cases[] = {{-0.3, 0.7, 0}, {0.2, 1.2, 0},   {-2.0, -0.5, 0},   {-0.5, 0.5, 0.5},
                 {-0.5, 0.5, 3}, {4.5, 5.5, 1.0}, {-5.5, -4.5, 2.0}, {-1e-3, 2.0, 1e-4}};
    const struct {
        double g, eta, sigma_t, albedo;
    } media[] = {{0.0, 1.0, 1.0, 0.95}, {0.5, 1.4, 2.0, 0.6}};
    double worst6 = 0, worst12 = 0;
    for (int m = 0; m < 2; m++) {
        ppb_pbd_profile p;
        ppb_pbd_profile_init(&p, table(media[m].g, media[m].eta), media[m].sigma_t,
                             media[m].albedo);
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
            double ref = strip_polar(&p, cases[c].ua, cases[c].ub, cases[c].v);
            double s6 = ppb_pbd_strip(&p, cases[c].ua, cases[c].ub, cases[c].v, 6);
            double s12 = ppb_pbd_strip(&p, cases[c].ua, cases[c].ub, cases[c].v, 12);
            print_message("medium %d [%g, %g] v %g: polar %.10e, nodes 6 %.1e, 12 %.1e\n", m,
                          cases[c].ua, cases[c].ub, cases[c].v, ref, s6 / ref - 1, s12 / ref - 1);
            worst6 = fmax(worst6, fabs(s6 - ref) / fmax(1e-6 * ref, 1e-11));
            worst12 = fmax(worst12, fabs(s12 - ref) / fmax(1e-9 * ref, 1e-12));
        }
    }
    print_message("strip: largest error over its bound %.2f at 6 nodes, %.2f at 12\n", worst6,
                  worst12);
    assert_lt(worst6, 1);
    assert_lt(worst12, 1);
}

/* The study's tube at 32 top and 12 side segments: the suite stays short. */
static void coarse_segments(ppb_config *cfg)
{
    cfg->scene.segments_top = 32;
    cfg->scene.segments_side = 12;
}

/* A study config's kept table and its totals against the bounds of test_study_configs. */
static void study_bounds(const char *name, ppb_run_ctx *ctx, const ppb_result *out)
{
    const ppb_scene *sc = &ctx->cfg->scene;
    assert_non_null(ppb_ctx_state(ctx, "pbd"));
    double entry = pu_entry(sc);
    double rmax = 0, tmax = 0;
    for (int side = 0; side < 2; side++) {
        double st, al;
        pu_side_medium(sc, side, &st, &al);
        ppb_pbd_profile p;
        ppb_pbd_profile_init(&p, table(sc->g, sc->n), st, al);
        rmax = fmax(rmax, ppb_pbd_plane(&p, 0));
        tmax = fmax(tmax, ppb_pbd_plane(&p, sc->height));
    }
    double sum = out->totals.R + out->totals.T + out->totals.sides;
    print_message("%-24s rhoEff %.4f  R %.4f T %.4f sides %.4f  sum %.4f\n", name, rmax,
                  out->totals.R, out->totals.T, out->totals.sides, sum);
    assert_le(out->totals.R, entry * rmax * (1 + 1e-9));
    assert_le(out->totals.T, entry * tmax * (1 + 1e-9));
    assert_le(out->totals.sides, entry * rmax * (1 + 1e-9));
    assert_lt(0.1 * entry * rmax, out->totals.R); /* most of it within the lit strip's reach */
    assert_le(sum, 1 + 1e-3);
}

static void test_study_configs(void **state)
{
    (void)state;
    /* pbd on every study config (configs/study.list), at a coarser segment grid (32 and 12)
     * that keeps the suite short: every radiance finite and >= 0, and the totals within the
     * profile's bounds: for one entry point S1 lies in the profile's plane (at most rhoEff),
     * S2 in the plane at distance H (at most the plane integral beyond H), the two sides in
     * half planes (at most rhoEff together); times the entering 1 - F(theta_L), with the
     * largest over the tube's media. The table is built once per (g, n) and kept. */
    pu_study_configs("pbd", coarse_segments, study_bounds);
}

/* A slab's totals, and a second run in the same context (test_slab_mode). */
static void slab_totals(ppb_run_ctx *ctx, const ppb_result *out, double mu, double entry)
{
    (void)mu;
    ppb_result again;
    study_run_id(ctx, "pbd", &again);
    ppb_pbd_profile p;
    ppb_pbd_profile_init(&p, table(0.0, ctx->cfg->scene.n), ctx->cfg->scene.sigma_t, 0.95);
    assert_close(out->totals.R, entry * (p.rho_eff - negative_mass(&p)),
                 entry * (1e-2 * fabs(negative_mass(&p)) + 1e-14));
    assert_rel(out->totals.T, entry * ppb_pbd_plane(&p, 3.0), 1e-14);
    assert_close(again.totals.R, out->totals.R, 0);
    assert_close(again.totals.T, out->totals.T, 0);
    ppb_result_free(&again);
}

static void test_slab_mode(void **state)
{
    (void)state;
    /* Slab mode: R = (1 - F) (the mixed rhoEff less the clamped negative part), T = (1 - F) the
     * plane integral beyond H, and a second run in the same context reuses the kept table
     * (identical totals). */
    pu_slab_mode("pbd", slab_totals);
}

/* Albedo 0 reflects nothing (test_extremes). */
static void corner_dark(const pu_corner *c, ppb_run_ctx *ctx, const ppb_result *out)
{
    (void)ctx;
    if (c->albedo == 0)
        assert_close(out->totals.R, 0, 0);
}

static void test_extremes(void **state)
{
    (void)state;
    /* Albedo 0 to 1, g +-0.95, H 1e-3 and 1e3, n 1 and 1.4 on a coarse tube: every cell finite
     * and >= 0 and the method's result checks passed; albedo 0 reflects nothing. */
    const double albedo[] = {0, 0.01, 0.5, 0.999, 1}, g[] = {-0.95, 0, 0.95},
                 height[] = {1e-3, 1e3}, n[] = {1, 1.4};
    pu_grid grid = {0, PU_AXIS(albedo), PU_AXIS(g), PU_AXIS(height), {NULL, 0}, PU_AXIS(n)};
    pu_extremes("pbd", &grid, NULL, corner_dark);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fresnel_moments),
        cmocka_unit_test(test_beam_integrals),
        cmocka_unit_test(test_rho_eff),
        cmocka_unit_test(test_catmull_rom),
        cmocka_unit_test(test_sr_nodes_and_scaling),
        cmocka_unit_test(test_plane_integral),
        cmocka_unit_test(test_strip_quadrature),
        cmocka_unit_test(test_study_configs),
        cmocka_unit_test(test_slab_mode),
        cmocka_unit_test(test_extremes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
