/* test_rte2d_beam.c: the exact beam integral over a rectangle (physics/rte2d_beam.h), each check
 * with its source:
 * - analytic: exp(affine) over polygons against closed forms (a triangle, a vanishing gradient),
 *   and the normal-incidence beam over a rectangle, the 1-D exponential's integral;
 * - independent quadrature: rectangles crossed by the light lines against nested adaptive
 *   Simpson of a point evaluator written here, which traces each class's beam backwards through
 *   the real tube's reflections (no images, no polygons);
 * - conservation: over a tiling of the cross-section, sum (1 - alpha) out = the power the beam
 *   loses to absorption, from two sources independent of the region integrals and of each other:
 *   ppb_rte_absorbed_beam (rte2d_grid.h: the beam walked forward along its path, 2e4 midpoints
 *   over the entry points where it reflects off the side walls), and a brute-force integral
 *   written here of (1 - alpha) sigma_t E over the cross-section, E from the backward point
 *   evaluator above, by nested adaptive Simpson (to 1e-10 absolute).
 * A searchlight's strip (reference: Light) joins both: its two light lines cut the rectangles,
 * and the point evaluator lights its own strip. */
#include "testutil.h"

#include "kernels/ppb_fresnel.h"
#include "model/config.h"
#include "methods/rte2d/rte2d_beam.h"
#include "methods/rte2d/rte2d_grid.h"

static ppb_scene base_scene(ppb_geometry geom)
{
    ppb_config cfg;
    ppb_err err;
    if (ppb_config_defaults(&cfg, &err))
        fail_msg("%s", err.msg);
    cfg.scene.geometry = geom;
    return cfg.scene;
}

/* The launch parameters of a scene, as rte2d builds them (coarse: only P matters here). */
static ppb_rte_params scene_params(const ppb_scene *sc)
{
    ppb_rte_grid G;
    ppb_err err;
    if (ppb_rte_grid_make(sc, 0.5, 4, 0.5, 0, NULL, &G, &err))
        fail_msg("%s", err.msg);
    ppb_rte_params P = G.P;
    ppb_rte_grid_free(&G);
    return P;
}

static double out_sum(const double out[4])
{
    return out[0] + out[1] + out[2] + out[3];
}

/* ---- analytic ---- */

/* exp(b x) over the triangle (0,0), (1,0), (0,1): int_0^1 e^{bx} (1 - x) dx = (e^b - 1 - b) / b^2;
 * b = 1e-9 and b = 0: the area 1/2 (to 1e-9 b); a rotated unit square with gradient along a
 * diagonal direction against the product of 1-D integrals. */
static void test_poly_exp_closed_forms(void **state)
{
    (void)state;
    double tx[3] = {0, 1, 0}, ty[3] = {0, 0, 1};
    double bs[4] = {3.0, -40.0, 1e-9, 0.0};
    for (int i = 0; i < 4; i++) {
        double b = bs[i];
        double ref = fabs(b) > 1e-4 ? (expm1(b) - b) / (b * b) : 0.5 + b / 6.0;
        double got = ppb_rte_poly_exp(tx, ty, 3, 0.0, b, 0.0);
        printf("triangle b = %g: %.17g vs %.17g (rel %.2g)\n", b, got, ref, fabs(got - ref) / ref);
        assert_rel(got, ref, 1e-14);
    }
    /* Square [0,1]^2 (clockwise), exp(-1 + 2x - 3y): (e^2 - 1)/2 (1 - e^-3)/3 e^-1. */
    double sx[4] = {0, 0, 1, 1}, sy[4] = {0, 1, 1, 0};
    double ref = exp(-1.0) * expm1(2.0) / 2.0 * -expm1(-3.0) / 3.0;
    double got = ppb_rte_poly_exp(sx, sy, 4, -1.0, 2.0, -3.0);
    printf("square: rel %.2g\n", fabs(got - ref) / ref);
    assert_rel(got, ref, 1e-14);
}

/* n = 1 at normal incidence, uniform: sigma E = sigma e^{sigma y}, so the rectangle's integral is
 * (x1 - x0)(e^{sigma y1} - e^{sigma y0}); in the slab at 45 degrees per unit width
 * cos (e^{sigma y1 / cos} - e^{sigma y0 / cos}). */
static void test_normal_incidence_analytic(void **state)
{
    (void)state;
    ppb_scene sc = base_scene(PPB_GEOM_TUBE);
    sc.width = 4.0;
    sc.height = 3.0;
    double sig[3] = {1.0, 7.5, 1e-3};
    for (int i = 0; i < 3; i++) {
        sc.sigma_t = sig[i];
        ppb_rte_params P = scene_params(&sc);
        double out[4], x0 = -1.3, x1 = 0.4, y0 = -2.1, y1 = -0.6;
        ppb_rte_beam_rect(&P, x0, x1, y0, y1, out);
        double ref = (x1 - x0) * exp(sig[i] * y0) * expm1(sig[i] * (y1 - y0));
        printf("normal sigma %g: %.17g vs %.17g (rel %.2g)\n", sig[i], out[0], ref,
               fabs(out[0] - ref) / ref);
        assert_rel(out[0], ref, 1e-13);
        assert_true(out[1] == 0.0 && out[2] == 0.0 && out[3] == 0.0);
    }
    ppb_scene sl = base_scene(PPB_GEOM_SLAB);
    sl.theta_deg = 45.0;
    sl.sigma_t = 2.0;
    ppb_rte_params P = scene_params(&sl);
    double out[4], c = cos(PPB_PI / 4.0), y0 = -0.9, y1 = -0.2;
    ppb_rte_beam_rect(&P, 5.0, 7.0, y0, y1, out);
    double ref = c * exp(2.0 * y0 / c) * expm1(2.0 * (y1 - y0) / c);
    printf("slab 45: rel %.2g\n", fabs(out[0] - ref) / ref);
    assert_rel(out[0], ref, 1e-13);
}

/* ---- independent quadrature ---- */

/* The refracted beam inside, from Snell's law and the Fresnel factors (ppb_fresnel.h). */
typedef struct trace_beam {
    double st, ct, in, fb, fs;
} trace_beam;

static trace_beam beam_inside(const ppb_scene *sc)
{
    double th = sc->theta_deg * PPB_PI / 180.0;
    trace_beam b = {sin(th), cos(th), 1.0, 0.0, 0.0};
    if (sc->n > 1.0) {
        b.st = sin(th) / sc->n;
        b.ct = sqrt(1.0 - b.st * b.st);
        b.in = (1.0 - ppb_fresnel(cos(th), sc->n)) * cos(th) / b.ct;
        b.fb = ppb_fresnel(b.ct, 1.0 / sc->n);
        b.fs = ppb_fresnel(b.st, 1.0 / sc->n);
    }
    return b;
}

static int is_tube(const ppb_scene *sc)
{
    return sc->geometry == PPB_GEOM_TUBE;
}

static double sigma_at(const ppb_scene *sc, double x)
{
    return is_tube(sc) && sc->step == PPB_STEP_DENSITY && x >= sc->step_x ? sc->sigma_t_right
                                                                          : sc->sigma_t;
}

/* Optical depth of the straight segment from x over length l along horizontal component rx:
 * the part of its horizontal span right of a density step has sigma_t_right. */
static double segment_depth(const ppb_scene *sc, double x, double rx, double l)
{
    double xa = fmin(x, x + l * rx), xb = fmax(x, x + l * rx);
    if (!is_tube(sc) || sc->step != PPB_STEP_DENSITY || xb - xa <= 0.0)
        return sigma_at(sc, x) * l;
    double right = fmax(0.0, xb - fmax(xa, sc->step_x)) / (xb - xa);
    return l * (sc->sigma_t * (1.0 - right) + sc->sigma_t_right * right);
}

static int s1_lit(const ppb_scene *sc, double x)
{
    if (!is_tube(sc))
        return 1;
    if (sc->searchlight) /* reference: Light: the strip [x0 - width/2, x0 + width/2) */
        return x >= sc->light_x0 - 0.5 * sc->light_width &&
               x < sc->light_x0 + 0.5 * sc->light_width;
    double hi = sc->step == PPB_STEP_SHADOW ? fmin(0.5 * sc->width, sc->step_x) : 0.5 * sc->width;
    return x >= -0.5 * sc->width && x < hi;
}

/* E of class cls at (x, y), traced backwards from the point against the beam's direction
 * (cls: 2 = -sin, 1 = up): a wall met backwards is a reflection (F_b at S1, S2; F_s at S3, S4);
 * S1 met going up backwards is also where the beam may have entered (lit part: beam_in times the
 * product of the F's times e^{-tau}). At n = 1 nothing reflects: the first wall ends the trace. */
static double trace_E(const ppb_scene *sc, const trace_beam *b, int cls, double x, double y)
{
    double W = sc->width, H = sc->height, rx = (cls & 2) ? b->st : -b->st;
    double ry = (cls & 1) ? -b->ct : b->ct, w = 1.0, tau = 0.0, E = 0.0;
    int refl = sc->n > 1.0;
    /* Only the oblique tube at n > 1 has the -sin classes, only n > 1 the up ones. */
    if (((cls & 2) && !(is_tube(sc) && refl && b->st > 0.0)) || ((cls & 1) && !refl))
        return 0.0;
    for (int hit = 0; hit < 100000 && w * exp(-tau) > 1e-19; hit++) {
        double ly = ry > 0.0 ? -y / ry : (-H - y) / ry, lx = INFINITY;
        if (is_tube(sc) && rx != 0.0)
            lx = rx > 0.0 ? (0.5 * W - x) / rx : (-0.5 * W - x) / rx;
        double l = fmin(lx, ly);
        tau += segment_depth(sc, x, rx, l);
        x += l * rx;
        y += l * ry;
        if (ly <= lx) {
            if (ry > 0.0 && rx <= 0.0 && s1_lit(sc, x)) /* entering: along (+sin, down) */
                E += b->in * w * exp(-tau);
            if (!refl)
                return E;
            w *= b->fb;
            ry = -ry;
            y = ry > 0.0 ? -H : 0.0;
        } else {
            if (!refl)
                return E;
            w *= b->fs;
            rx = -rx;
            x = rx > 0.0 ? -0.5 * W : 0.5 * W;
        }
    }
    return E;
}

/* Adaptive Simpson of f on [a, b]: split until the halves agree to 15 tol (tol halved per
 * level) or the depth runs out (a jump: its interval shrinks to 2^-depth). */
typedef double (*fn1)(double t, void *ctx);
static double simpson(fn1 f, void *c, double a, double b, double fa, double fm, double fb,
                      double whole, double tol, int depth)
{
    double m = 0.5 * (a + b), flm = f(0.5 * (a + m), c), frm = f(0.5 * (m + b), c);
    double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm),
           right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    double diff = left + right - whole;
    if (depth <= 0 || fabs(diff) <= 15.0 * tol)
        return left + right + diff / 15.0;
    return simpson(f, c, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1) +
           simpson(f, c, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1);
}

/* 16 panels first, so no lit strip hides between the first samples. */
static double integrate(fn1 f, void *c, double a, double b, double tol, int depth)
{
    double sum = 0.0, h = (b - a) / 16.0;
    for (int i = 0; i < 16; i++) {
        double u = a + i * h, v = u + h, fu = f(u, c), fv = f(v, c), fm = f(u + 0.5 * h, c);
        sum += simpson(f, c, u, v, fu, fm, fv, h / 6.0 * (fu + 4.0 * fm + fv), tol / 16.0, depth);
    }
    return sum;
}

typedef struct quad_ctx {
    const ppb_scene *sc;
    trace_beam b;
    int cls;
    double x, y0, y1, tol;
} quad_ctx;

static double inner_y(double y, void *c)
{
    quad_ctx *q = c;
    return sigma_at(q->sc, q->x) * trace_E(q->sc, &q->b, q->cls, q->x, y);
}

static double outer_x(double x, void *c)
{
    quad_ctx *q = c;
    q->x = x;
    return integrate(inner_y, q, q->y0, q->y1, 1e-3 * q->tol, 44);
}

/* The rectangle's integral of sigma_t E_cls by nested adaptive Simpson; tol absolute. */
static double brute_rect(const ppb_scene *sc, int cls, const double r[4], double tol)
{
    quad_ctx q = {sc, beam_inside(sc), cls, 0.0, r[2], r[3], tol};
    return integrate(outer_x, &q, r[0], r[1], tol, 24);
}

static void quad_case(const char *name, const ppb_scene *sc, const double r[4])
{
    ppb_rte_params P = scene_params(sc);
    double out[4];
    ppb_rte_beam_rect(&P, r[0], r[1], r[2], r[3], out);
    double tot = out_sum(out);
    assert_true(tot > 0.0);
    for (int k = 0; k < 4; k++) {
        double ref = brute_rect(sc, k, r, 1e-10 * tot);
        double rel = fabs(out[k] - ref) / tot;
        printf("%s class %d: exact %.12g quadrature %.12g (difference / total %.2g)\n", name, k,
               out[k], ref, rel);
        assert_true(rel < 1e-8);
    }
}

/* Rectangles that the light lines x_e = -W/2 and x_e = step_x (shadow, density step) cross. */
static void test_against_quadrature(void **state)
{
    (void)state;
    ppb_scene sc = base_scene(PPB_GEOM_TUBE);
    sc.width = 2.0;
    sc.height = 1.5;
    sc.sigma_t = 1.3;
    sc.theta_deg = 45.0;
    sc.step = PPB_STEP_SHADOW;
    sc.step_x = 0.3;
    double r1[4] = {-0.9, 0.6, -1.4, -0.2};
    quad_case("n = 1, 45 deg, shadow step", &sc, r1);

    sc.step = PPB_STEP_DENSITY;
    sc.step_x = 0.2;
    sc.sigma_t = 1.0;
    sc.sigma_t_right = 2.5;
    double r2[4] = {0.2, 0.9, -1.3, -0.1};
    quad_case("n = 1, 45 deg, density step (right)", &sc, r2);

    sc.n = 1.4;
    sc.width = 1.0;
    sc.height = 2.0;
    sc.step = PPB_STEP_NONE;
    sc.sigma_t = 0.4;
    double r3[4] = {-0.3, 0.35, -1.7, -0.4};
    quad_case("n = 1.4, 45 deg, tube", &sc, r3);

    sc.step = PPB_STEP_DENSITY;
    sc.step_x = 0.1;
    sc.sigma_t_right = 1.1;
    double r4[4] = {0.1, 0.45, -1.9, -0.3};
    quad_case("n = 1.4, 45 deg, tube, density step (right)", &sc, r4);
    double r5[4] = {-0.5, 0.1, -1.2, 0.0};
    quad_case("n = 1.4, 45 deg, tube, density step (left)", &sc, r5);

    /* A searchlight's strip [-0.6, 0.2]: both its light lines cross the rectangles. */
    sc = base_scene(PPB_GEOM_TUBE);
    sc.width = 2.0;
    sc.height = 1.5;
    sc.sigma_t = 1.3;
    sc.theta_deg = 45.0;
    sc.searchlight = 1;
    sc.light_x0 = -0.2;
    sc.light_width = 0.8;
    double r6[4] = {-0.9, 0.9, -1.4, -0.1};
    quad_case("n = 1, 45 deg, strip", &sc, r6);
    sc.step = PPB_STEP_DENSITY;
    sc.step_x = 0.0;
    sc.sigma_t_right = 2.5;
    double r7[4] = {0.0, 0.9, -1.3, -0.1};
    quad_case("n = 1, 45 deg, strip, density step (right)", &sc, r7);
    sc.n = 1.4;
    sc.width = 1.0;
    sc.height = 2.0;
    sc.step = PPB_STEP_NONE;
    sc.sigma_t = 0.4;
    sc.light_x0 = 0.05;
    sc.light_width = 0.5;
    double r8[4] = {-0.3, 0.35, -1.7, -0.4};
    quad_case("n = 1.4, 45 deg, tube, strip", &sc, r8);
}

/* ---- conservation ---- */

/* sum over a tiling (x split at the step, uneven rows; the slab: one column of width 1) of (1 -
 * alpha) sum_k out[k]. */
static double tiled_absorbed(const ppb_scene *sc, const ppb_rte_params *P)
{
    double W = is_tube(sc) ? sc->width : 1.0, xs[16];
    int nx = 0;
    xs[nx++] = -0.5 * W;
    int split = is_tube(sc) && sc->step != PPB_STEP_NONE && fabs(sc->step_x) < 0.5 * W;
    for (int i = 1; i < 7 && is_tube(sc); i++) {
        double x = -0.5 * W + W * (i + 0.13 * sin(i)) / 7.0;
        if (split && xs[nx - 1] < sc->step_x && x > sc->step_x)
            xs[nx++] = sc->step_x;
        xs[nx++] = x;
    }
    if (split && xs[nx - 1] < sc->step_x)
        xs[nx++] = sc->step_x;
    xs[nx++] = 0.5 * W;
    const int ny = 9;
    double sum = 0.0;
    for (int i = 0; i + 1 < nx; i++)
        for (int j = 0; j < ny; j++) {
            double t0 = (double)j / ny, t1 = (double)(j + 1) / ny;
            double y1 = -sc->height * t0 * t0, y0 = -sc->height * t1 * t1, out[4];
            ppb_rte_beam_rect(P, xs[i], xs[i + 1], y0, y1, out);
            double xm = 0.5 * (xs[i] + xs[i + 1]);
            double al = is_tube(sc)
                            ? ppb_albedo_at(xm, sc->step, sc->step_x, sc->albedo, sc->albedo_right)
                            : sc->albedo;
            sum += (1.0 - al) * out_sum(out);
        }
    return sum;
}

/* The absorbed beam power by brute force, from the geometry alone (docs/reference.md, Methods,
 * rte2d: the absorbed beam is the beam's collisions times 1 - alpha; per unit z, E_perp = 1):
 * the integral over the cross-section of (1 - alpha) sigma_t sum_k E_k, E_k from trace_E above
 * (each point traced backwards through the walls, no image, no polygon, no walk along the beam),
 * by nested adaptive Simpson (integrate() above): in x to tol absolute, split at
 * step_x (where alpha or sigma_t jumps), and in y down each column to 1e-13 (E jumps across the
 * light lines, which the bisection isolates). Against the exact tiling it agrees within 3e-11
 * at tol 1e-10 on every case below (4e-7 at tol 1e-8): the test allows 1e-9. */
typedef struct column_ctx {
    const ppb_scene *sc;
    trace_beam b;
    double x;
} column_ctx;

static double column_y(double y, void *c)
{
    column_ctx *q = c;
    double e = 0.0;
    for (int k = 0; k < PPB_BEAM_CLASSES; k++)
        e += trace_E(q->sc, &q->b, k, q->x, y);
    return sigma_at(q->sc, q->x) * e;
}

static double column(double x, void *c)
{
    column_ctx *q = c;
    q->x = x;
    const ppb_scene *sc = q->sc;
    double al = is_tube(sc) ? ppb_albedo_at(x, sc->step, sc->step_x, sc->albedo, sc->albedo_right)
                            : sc->albedo;
    return (1.0 - al) * integrate(column_y, q, -sc->height, 0.0, 1e-13, 40);
}

static double witness_absorbed(const ppb_scene *sc, double tol)
{
    double W = is_tube(sc) ? sc->width : 1.0, cut[3] = {-0.5 * W, 0.5 * W, 0.5 * W};
    int nparts = 1;
    if (is_tube(sc) && sc->step != PPB_STEP_NONE && fabs(sc->step_x) < 0.5 * W)
        cut[1] = sc->step_x, nparts = 2;
    column_ctx q = {sc, beam_inside(sc), 0.0};
    double sum = 0.0;
    for (int p = 0; p < nparts; p++)
        sum += integrate(column, &q, cut[p], cut[p + 1], tol, 30);
    return sum;
}

typedef struct cons_case {
    const char *name;
    ppb_geometry geom;
    double n, theta;
    int step;
    double sigma_t; /* 0: 0.8 */
    int strip;      /* 1: a searchlight's strip [-0.75, 0.15] (reference: Light) */
} cons_case;

static void test_conservation(void **state)
{
    (void)state;
    const cons_case cs[] = {
        {"slab n = 1 normal", PPB_GEOM_SLAB, 1.0, 0.0, PPB_STEP_NONE, 0.0, 0},
        {"slab n = 1 45", PPB_GEOM_SLAB, 1.0, 45.0, PPB_STEP_NONE, 0.0, 0},
        {"slab n = 1.4 normal", PPB_GEOM_SLAB, 1.4, 0.0, PPB_STEP_NONE, 0.0, 0},
        {"slab n = 1.4 45", PPB_GEOM_SLAB, 1.4, 45.0, PPB_STEP_NONE, 0.0, 0},
        {"tube n = 1 normal", PPB_GEOM_TUBE, 1.0, 0.0, PPB_STEP_NONE, 0.0, 0},
        {"tube n = 1 normal density", PPB_GEOM_TUBE, 1.0, 0.0, PPB_STEP_DENSITY, 0.0, 0},
        {"tube n = 1 45", PPB_GEOM_TUBE, 1.0, 45.0, PPB_STEP_NONE, 0.0, 0},
        {"tube n = 1 45 shadow", PPB_GEOM_TUBE, 1.0, 45.0, PPB_STEP_SHADOW, 0.0, 0},
        {"tube n = 1 45 density", PPB_GEOM_TUBE, 1.0, 45.0, PPB_STEP_DENSITY, 0.0, 0},
        {"tube n = 1 45 albedo", PPB_GEOM_TUBE, 1.0, 45.0, PPB_STEP_ALBEDO, 0.0, 0},
        {"tube n = 1.4 normal", PPB_GEOM_TUBE, 1.4, 0.0, PPB_STEP_NONE, 0.0, 0},
        {"tube n = 1.4 normal density", PPB_GEOM_TUBE, 1.4, 0.0, PPB_STEP_DENSITY, 0.0, 0},
        {"tube n = 1.4 45", PPB_GEOM_TUBE, 1.4, 45.0, PPB_STEP_NONE, 0.0, 0},
        {"tube n = 1.4 45 shadow", PPB_GEOM_TUBE, 1.4, 45.0, PPB_STEP_SHADOW, 0.0, 0},
        {"tube n = 1.4 45 density", PPB_GEOM_TUBE, 1.4, 45.0, PPB_STEP_DENSITY, 0.0, 0},
        {"tube n = 1.4 45 albedo", PPB_GEOM_TUBE, 1.4, 45.0, PPB_STEP_ALBEDO, 0.0, 0},
        {"tube n = 1 80 density, thick", PPB_GEOM_TUBE, 1.0, 80.0, PPB_STEP_DENSITY, 12.0, 0},
        {"tube n = 1.4 80 shadow, thin", PPB_GEOM_TUBE, 1.4, 80.0, PPB_STEP_SHADOW, 0.05, 0},
        {"tube n = 1.4 80 density, thick", PPB_GEOM_TUBE, 1.4, 80.0, PPB_STEP_DENSITY, 12.0, 0},
        {"tube n = 1 normal strip", PPB_GEOM_TUBE, 1.0, 0.0, PPB_STEP_NONE, 0.0, 1},
        {"tube n = 1 45 strip albedo", PPB_GEOM_TUBE, 1.0, 45.0, PPB_STEP_ALBEDO, 0.0, 1},
        {"tube n = 1 45 strip density", PPB_GEOM_TUBE, 1.0, 45.0, PPB_STEP_DENSITY, 0.0, 1},
        {"tube n = 1.4 45 strip", PPB_GEOM_TUBE, 1.4, 45.0, PPB_STEP_NONE, 0.0, 1},
        {"tube n = 1.4 45 strip density", PPB_GEOM_TUBE, 1.4, 45.0, PPB_STEP_DENSITY, 0.0, 1},
    };
    for (size_t c = 0; c < sizeof cs / sizeof cs[0]; c++) {
        ppb_scene sc = base_scene(cs[c].geom);
        sc.width = 2.0;
        sc.height = 1.5;
        sc.sigma_t = cs[c].sigma_t > 0.0 ? cs[c].sigma_t : 0.8;
        sc.albedo = 0.3;
        sc.n = cs[c].n;
        sc.theta_deg = cs[c].theta;
        sc.step = cs[c].step;
        sc.step_x = 0.25;
        sc.sigma_t_right = 2.2;
        sc.albedo_right = 0.75;
        sc.searchlight = cs[c].strip;
        sc.light_x0 = -0.3;
        sc.light_width = 0.9;
        ppb_rte_params P = scene_params(&sc);
        double got = tiled_absorbed(&sc, &P), ref = ppb_rte_absorbed_beam(&sc);
        double wit = witness_absorbed(&sc, 1e-10);
        printf("%s: tiled %.15g, ppb_rte_absorbed_beam %.15g (rel %.2g), brute force %.15g "
               "(tiled - it %.2g, walk - it %.2g)\n",
               cs[c].name, got, ref, fabs(got - ref) / ref, wit, got - wit, ref - wit);
        assert_true(fabs(got - ref) / ref < 1e-9);
        assert_true(fabs(got - wit) < 1e-9);
        assert_true(fabs(ref - wit) < 1e-9);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_poly_exp_closed_forms),
        cmocka_unit_test(test_normal_incidence_analytic),
        cmocka_unit_test(test_against_quadrature),
        cmocka_unit_test(test_conservation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
