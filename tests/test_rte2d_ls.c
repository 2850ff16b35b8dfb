/* test_rte2d_ls.c: rte2d's linear source (`[rte2d] source = linear`, rte2d_ls.h; reference:
 * Methods, `rte2d`, the linear source), each check with its source:
 * - one segment's transport through a source linear along it (the radiance out and the two
 *   integrals the fit needs) against the transport equation dpsi/dl = b + c l - sigma psi
 *   integrated by classical Runge-Kutta with the integrals by Simpson's rule on the same steps
 *   (an independent solution, fourth order, 4000 steps: 1e-12 of the values), on both sides of
 *   the switch to the Taylor series at tau = 0.1 and from tau 1e-7 to 30;
 * - the fit of a region's gradient from its tracks' sums against a field linear in x and y:
 *   the least-squares fit over the tracks reproduces it to rounding whatever the track layout
 *   (an arbitrary direction, offset and spacing), as its header claims;
 * - the solve: the energy balance R + T + sides + absorbed + ballistic + specular = 1 to the
 *   solve's residual (1e-6, as test_rte2d holds the flat source to; the linear source keeps the
 *   balance form) on the reduced tube at n = 1 and at n = 1.4 with 45 degree light and a
 *   density step, and the linear source at spacing 0.2 at least as close as the flat one to the
 *   flat source at spacing 0.05 (the grid's limit both converge to) in R, T and the sides. */
#include "testutil.h"
#include "deviceutil.h"

#include "methods/rte2d/method_rte2d.h"
#include "methods/rte2d/rte2d_ls.h"
#include "model/config.h"
#include "physics/totals.h"

/* psi' = b + c l - sigma psi by RK4 over [0, L] in n steps; the integrals of psi and l psi by
 * Simpson's rule on pairs of steps (n even). */
static double rk4_segment(double a, double b, double c, double st, double L, int n, double *i0,
                          double *i1)
{
    double h = L / n, psi = a, s0 = 0.0, s1 = 0.0;
    for (int k = 0; k < n; k++) {
        double l = k * h;
        double k1 = b + c * l - st * psi;
        double k2 = b + c * (l + 0.5 * h) - st * (psi + 0.5 * h * k1);
        double k3 = b + c * (l + 0.5 * h) - st * (psi + 0.5 * h * k2);
        double k4 = b + c * (l + h) - st * (psi + h * k3);
        double w = (k == 0) ? 1.0 : (k % 2 ? 4.0 : 2.0);
        s0 += w * psi;
        s1 += w * l * psi;
        psi += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    s0 += psi;
    s1 += L * psi;
    *i0 = s0 * h / 3.0;
    *i1 = s1 * h / 3.0;
    return psi;
}

static void test_segment_vs_ode(void **state)
{
    (void)state;
    double taus[] = {1e-7, 1e-3, 0.02, 0.0999, 0.1001, 0.3, 2.0, 30.0};
    double srcs[][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}, {0.7, 0.4, -0.3}};
    for (size_t t = 0; t < sizeof taus / sizeof taus[0]; t++)
        for (size_t k = 0; k < sizeof srcs / sizeof srcs[0]; k++) {
            double st = 0.8, L = taus[t] / st, a = srcs[k][0], b = srcs[k][1], c = srcs[k][2];
            double j0, j1, e0, e1;
            double out = ppb_ls_segment(a, b, c, st, taus[t], L, &j0, &j1);
            double ref = rk4_segment(a, b, c, st, L, 4000, &e0, &e1);
            /* Scales: what each term can reach over the segment. */
            double sp = fabs(a) + fabs(b) * L + fabs(c) * L * L;
            assert_close(out, ref, 1e-11 * sp);
            assert_close(j0, e0, 1e-11 * sp * L);
            assert_close(j1, e1, 1e-11 * sp * L * L);
        }
}

/* The sums of tracks along (ux, uy) (unit, planar), spacing delta from offset v0, across the
 * rectangle [x0, x1] x [y0, y1] centred at (xc, yc), through psi = p0 + gx (x - xc) + gy (y - yc)
 * constant in z; s is the direction's planar length (a 3-D length l3 runs l3 s in the plane). */
static void linear_sums(double *acc, double x0, double x1, double y0, double y1, double ux,
                        double uy, double s, double delta, double v0, double p0, double gx,
                        double gy)
{
    double xc = 0.5 * (x0 + x1), yc = 0.5 * (y0 + y1);
    for (int k = 0; k < PPB_MOC_LS_ACC; k++)
        acc[k] = 0.0;
    /* Offsets v along the normal (-uy, ux) covering the rectangle's corners. */
    double vs[4] = {-uy * x0 + ux * y0, -uy * x1 + ux * y0, -uy * x0 + ux * y1, -uy * x1 + ux * y1};
    double vmin = fmin(fmin(vs[0], vs[1]), fmin(vs[2], vs[3]));
    double vmax = fmax(fmax(vs[0], vs[1]), fmax(vs[2], vs[3]));
    for (double v = vmin + v0; v < vmax; v += delta) {
        /* The line p = v (-uy, ux) + t (ux, uy) clipped to the rectangle. */
        double px = -uy * v, py = ux * v, ta = -INFINITY, tb = INFINITY;
        double lo[2] = {x0, y0}, hi[2] = {x1, y1}, p[2] = {px, py}, u[2] = {ux, uy};
        int inside = 1;
        for (int d = 0; d < 2; d++) {
            if (fabs(u[d]) < 1e-15) {
                inside &= p[d] > lo[d] && p[d] < hi[d];
                continue;
            }
            double t1 = (lo[d] - p[d]) / u[d], t2 = (hi[d] - p[d]) / u[d];
            ta = fmax(ta, fmin(t1, t2));
            tb = fmin(tb, fmax(t1, t2));
        }
        if (!inside || !(tb > ta))
            continue;
        double l = tb - ta, dx = px + ta * ux - xc, dy = py + ta * uy - yc, L = l / s;
        double pa = p0 + gx * dx + gy * dy, k = (gx * ux + gy * uy) * s;
        /* psi linear along the segment: its integrals in closed form. */
        double i0 = pa * L + 0.5 * k * L * L, i1 = 0.5 * pa * L * L + k * L * L * L / 3.0;
        ppb_ls_add(acc, s * delta, delta, dx, dy, ux, uy, s, l, i0, i1);
    }
}

static void test_fit_reproduces_linear(void **state)
{
    (void)state;
    struct {
        double phi, s, delta, v0;
    } lay[] = {{0.3, 0.9, 0.013, 0.004},
               {1.2, 0.4, 0.031, 0.017},
               {2.9, 0.99, 0.007, 0.001},
               {0.0, 0.6, 0.02, 0.011},
               {M_PI / 2, 0.7, 0.05, 0.02}};
    for (size_t k = 0; k < sizeof lay / sizeof lay[0]; k++) {
        double acc[PPB_MOC_LS_ACC], gx, gy;
        linear_sums(acc, -0.3, -0.2, -0.55, -0.5, cos(lay[k].phi), sin(lay[k].phi), lay[k].s,
                    lay[k].delta, lay[k].v0, 0.8, 1.7, -2.3);
        ppb_ls_fit(acc, &gx, &gy);
        assert_close(gx, 1.7, 1e-9);
        assert_close(gy, -2.3, 1e-9);
    }
}

static double balance(const ppb_totals *t)
{
    return t->R + t->T + t->sides + t->absorbed + t->ballistic + t->specular - 1.0;
}

static ppb_config reduced_tube(double n, double theta, int step)
{
    ppb_config cfg;
    ppb_err err;
    if (ppb_config_defaults(&cfg, &err))
        fail_msg("%s", err.msg);
    cfg.memory_limit = 0;
    cfg.scene.geometry = PPB_GEOM_TUBE;
    cfg.scene.width = 4.0;
    cfg.scene.height = 2.0;
    cfg.scene.segments_top = 16;
    cfg.scene.segments_side = 6;
    cfg.scene.n = n;
    cfg.scene.theta_deg = theta;
    cfg.scene.step = step;
    cfg.scene.step_x = 0.0;
    cfg.scene.sigma_t_right = 0.5;
    cfg.scene.g = -0.5; /* where the flat source's grid error is largest (reference: Methods) */
    cfg.samples_dir = cfg.samples_seg = 1;
    cfg.rte2d.directions = 32;
    return cfg;
}

static ppb_totals solve(ppb_config *cfg, int source, double spacing)
{
    cfg->rte2d.source = source;
    cfg->rte2d.spacing = spacing;
    cfg->rte2d.step = 0.5 * spacing;
    ppb_err err;
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    ppb_result r;
    if (ppb_result_init(&r, "rte2d", &lo, &err))
        fail_msg("%s", err.msg);
    ppb_run_ctx ctx = {.cfg = cfg, .ocl = *tu_ocl(), .ocl_open = 1, .quiet = 1};
    ppb_rte2d_stats st;
    if (ppb_rte2d_run(&ctx, &r, &st, &err))
        fail_msg("rte2d: %s", err.msg);
    assert_true(st.converged);
    ppb_totals t = r.totals;
    ppb_result_free(&r);
    return t;
}

static void test_balance_and_limit(void **state)
{
    (void)state;
    struct {
        double n, theta;
        int step;
        const char *name;
    } cs[] = {{1.0, 0.0, PPB_STEP_NONE, "n = 1, normal"},
              {1.4, 45.0, PPB_STEP_DENSITY, "n = 1.4, 45 deg, density step"}};
    for (size_t c = 0; c < sizeof cs / sizeof cs[0]; c++) {
        ppb_config cfg = reduced_tube(cs[c].n, cs[c].theta, cs[c].step);
        ppb_totals ref = solve(&cfg, PPB_RTE_SOURCE_FLAT, 0.05);
        ppb_totals fl = solve(&cfg, PPB_RTE_SOURCE_FLAT, 0.2);
        ppb_totals ls = solve(&cfg, PPB_RTE_SOURCE_LINEAR, 0.2);
        double e_fl = fabs(fl.R - ref.R) + fabs(fl.T - ref.T) + fabs(fl.sides - ref.sides);
        double e_ls = fabs(ls.R - ref.R) + fabs(ls.T - ref.T) + fabs(ls.sides - ref.sides);
        printf("%s: spacing 0.05 flat R %.6f T %.6f sides %.6f; at 0.2 flat off by %.3g, linear "
               "by %.3g (R %.6f T %.6f sides %.6f), balance %.3g\n",
               cs[c].name, ref.R, ref.T, ref.sides, e_fl, e_ls, ls.R, ls.T, ls.sides, balance(&ls));
        assert_le(fabs(balance(&ls)), 1e-6);
        assert_le(e_ls, e_fl);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_segment_vs_ode),
        cmocka_unit_test(test_fit_reproduces_linear),
        cmocka_unit_test(test_balance_and_limit),
    };
    return cmocka_run_group_tests(tests, tu_open_device, tu_close_device);
}
