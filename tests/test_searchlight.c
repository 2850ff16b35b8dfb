/* test_searchlight.c: the searchlight light (reference: Light; `[light] lit = strip`, x0, width),
 * each check with its source:
 * - the keys and their refusals (a strip off S1, with a shadow step, in a slab; pp's strip, a
 *   line in ss, mp, the `+ss` sums and rte2d; a line taken by the profile models): the
 *   reference's rules;
 * - S1's lit part, the power entering, the diffusion models' pieces, the kernels' lit test and
 *   light-line breaks: the definitions of reference: Light, by hand;
 * - the ballistic fraction of a strip and of a line near S4 at oblique light: Beer-Lambert along
 *   each entry point's path (exits through S2 or S4), in closed form; the Monte Carlo's
 *   unscattered count against it within its binomial noise (so the photons enter on the strip);
 * - the Monte Carlo's energy: R + T + sides + absorbed + ballistic = 1 (a conservation law);
 * - rte2d against the Monte Carlo within its noise on a strip at 30 degrees: a chi-square over
 *   every bin of every surface and each surface's total within 4 standard errors (an
 *   independent solver of the same transfer), rte2d's own balance to 1e-6;
 * - ss against mc1 (the Monte Carlo's once-scattered part, an independent estimator of the same
 *   single scattering) on the same strip: S1's and S2's totals within 4 standard errors plus
 *   ss's discretisation allowance, and a chi-square over S1's bins;
 * - the semi-infinite medium (W 40, H 20): the fraction reflected from a line or a strip is the
 *   plane albedo 1 - H(1) sqrt(1 - alpha) (Chandrasekhar 1960) for mc, (alpha/2)(1 - ln 2) for
 *   mc1 and ss (single scattering's closed form);
 * - the line as the limit of narrow strips: mc's line and a strip of width 1e-3 (the same
 *   photons, moved by at most 5e-4) agree in every total within 4 standard errors. */
#include "testutil.h"
#include "deviceutil.h"

#include "kernels/ppb_light.h"
#include "methods/mc/mc_tally.h"
#include "methods/mc/method_mc.h"
#include "methods/pp/method_ss.h"
#include "methods/registry.h"
#include "methods/rte2d/method_rte2d.h"
#include "model/config.h"
#include "physics/maps.h"
#include "physics/medium.h"

/* ---- keys and refusals ---- */

static const char *strip_ini(const char *name)
{
    return tu_config(name, "[experiment]\nmethods = mc\n[tube]\nwidth = 10\nheight = 3\n[light]\n"
                           "lit = strip\nx0 = 1\nwidth = 2\n");
}

/* Loads the strip config with the overrides sets ("section.key=value", a NULL-ended list of at
 * most 4) and checks its methods; returns the error ("" when accepted). */
static const char *load_check(const char *name, const char *const *sets)
{
    static ppb_config cfg;
    static ppb_err err;
    memset(&err, 0, sizeof err);
    int n = 0;
    while (sets && sets[n])
        n++;
    if (ppb_config_load_sets(&cfg, NULL, strip_ini(name), sets, n, &err) == 0 &&
        ppb_methods_check(&cfg, &err) == 0)
        return "";
    return err.msg;
}

#define SETS(...) ((const char *const[]){__VA_ARGS__, NULL})

static void expect_refused(const char *name, const char *const *sets, const char *needle)
{
    const char *msg = load_check(name, sets);
    if (!strstr(msg, needle))
        fail_msg("%s: error '%s' lacks '%s'", name, msg, needle);
}

static void test_keys(void **state)
{
    (void)state;
    ppb_config cfg;
    ppb_err err = {{0}};
    assert_int_equal(ppb_config_load(&cfg, strip_ini("strip_ok"), &err), 0);
    assert_int_equal(cfg.scene.searchlight, 1);
    assert_true(cfg.scene.light_x0 == 1 && cfg.scene.light_width == 2);
    assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
    assert_int_equal(cfg.scene.searchlight, 0); /* the default: the whole face */

    expect_refused("strip_off", SETS("light.width=9"), "light.width: the lit strip");
    expect_refused("line_off", SETS("light.width=0", "light.x0=5"), "light.x0: the lit line");
    expect_refused("strip_shadow", SETS("medium.step=shadow"), "do not combine");
    expect_refused("strip_slab", SETS("experiment.geometry=slab"), "needs the tube");
    expect_refused("strip_pp", SETS("experiment.methods=mc, pp"), "pp: a searchlight");
    const char *line_refusers[] = {"ss", "mp", "rte2d", "mp+ss", "burley+ss"};
    for (int i = 0; i < 5; i++) {
        char methods[64], name[32];
        snprintf(methods, sizeof methods, "experiment.methods=mc, %s", line_refusers[i]);
        snprintf(name, sizeof name, "line_%d", i);
        expect_refused(name, SETS(methods, "light.width=0"),
                       "a line searchlight (width = 0) is refused");
    }
    /* A line takes mc and the profile models with a line hook (physics/bssrdf_tube.h); a strip
     * takes mc, ss, mp, burley, rte2d; a strip that is the whole face takes pp too. */
    assert_string_equal(load_check("line_mc", SETS("light.width=0")), "");
    assert_string_equal(
        load_check("line_models",
                   SETS("experiment.methods=mc, burley, bdipole, pbd, dirpole", "light.width=0")),
        "");
    assert_string_equal(
        load_check("strip_all",
                   SETS("experiment.methods=mc, ss, mp, mp+ss, burley, burley+ss, rte2d")),
        "");
    assert_string_equal(
        load_check("strip_face", SETS("experiment.methods=pp", "light.x0=0", "light.width=10")),
        "");
}

/* ---- the lit part ---- */

static ppb_scene strip_scene(double x0, double w, double theta)
{
    ppb_scene sc = tu_tube();
    sc.searchlight = 1;
    sc.light_x0 = x0;
    sc.light_width = w;
    sc.theta_deg = theta;
    return sc;
}

static void test_lit_part(void **state)
{
    (void)state;
    double lo, hi;
    ppb_scene face = tu_tube();
    ppb_scene_lit_range(&face, &lo, &hi);
    assert_true(lo == -5 && hi == 5);
    face.step = PPB_STEP_SHADOW, face.step_x = 1;
    ppb_scene_lit_range(&face, &lo, &hi);
    assert_true(lo == -5 && hi == 1);
    assert_close(ppb_scene_power_in(&face), 6, 1e-15);

    ppb_scene sc = strip_scene(1, 2, 60);
    ppb_scene_lit_range(&sc, &lo, &hi);
    assert_true(lo == 0 && hi == 2);
    assert_close(ppb_scene_power_in(&sc), 2 * 0.5, 1e-15); /* width x cos 60 */
    ppb_scene line = strip_scene(1, 0, 60);
    assert_true(ppb_scene_lit_line(&line));
    assert_close(ppb_scene_power_in(&line), 0.5, 1e-15); /* unit strength x cos 60 */

    /* The diffusion models' pieces: the strip cut at a density step inside it; a line is one
     * degenerate piece. */
    sc.step = PPB_STEP_DENSITY, sc.step_x = 0.5;
    ppb_lit_piece p[2];
    assert_int_equal(ppb_lit_pieces(&sc, p), 2);
    assert_true(p[0].xa == 0 && p[0].xb == 0.5 && p[0].sigma_t == 1);
    assert_true(p[1].xa == 0.5 && p[1].xb == 2 && p[1].sigma_t == 0.5);
    assert_int_equal(ppb_lit_pieces(&line, p), 1);
    assert_true(p[0].xa == 1 && p[0].xb == 1);

    /* The kernels' test: x' in [lo, hi) on S1; and a vertical ray down from (1.5, 0) to S2 at
     * normal light crosses no light line, one from (-2, -1) toward (3, -1) crosses both. */
    ppb_scene nsc = strip_scene(1, 2, 0);
    ppb_medium M = ppb_medium_of(&nsc);
    ppb_lit L = ppb_lit_of(&nsc);
    assert_true(ppb_lit_at(&M, &L, 0.0, 0.0) && ppb_lit_at(&M, &L, 1.99, 0.0));
    assert_false(ppb_lit_at(&M, &L, 2.0, 0.0) || ppb_lit_at(&M, &L, -0.01, 0.0));
    double brk[8];
    assert_int_equal(ppb_lit_breaks(&M, &L, 0.0, 1.5, 0.0, 0.0, -1.0, 3.0, brk, 0), 0);
    assert_int_equal(ppb_lit_breaks(&M, &L, 0.0, -2.0, -1.0, 1.0, 0.0, 5.0, brk, 0), 2);
    assert_close(brk[0], 2.0, 1e-15);
    assert_close(brk[1], 4.0, 1e-15);
    ppb_scene whole = tu_tube();
    ppb_medium F = ppb_medium_of(&whole);
    ppb_lit FL = ppb_lit_of(&whole);
    assert_int_equal(ppb_lit_breaks(&F, &FL, 0.0, -2.0, -1.0, 1.0, 0.0, 5.0, brk, 0), 0);
}

/* ---- against the Monte Carlo ---- */

/* The Monte Carlo of cfg: mc and mc1 radiance and both totals with their standard errors. */
typedef struct mc_run {
    ppb_result mc, mc1;
    ppb_mc_totals_stats all, once;
} mc_run;

static void run_mc(ppb_config *cfg, mc_run *r)
{
    ppb_err err;
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    ppb_run_ctx ctx = {.cfg = cfg, .ocl = *tu_ocl(), .ocl_open = 1, .quiet = 1};
    ppb_mc_tallies t;
    ppb_mc_trace_info info;
    if (ppb_mc_tallies_init(&t, &cfg->scene, (uint64_t)cfg->mc.seed, cfg->mc.batches, &err) ||
        ppb_mc_trace(&ctx, 0, cfg->mc.photons, &t, &info, &err) ||
        ppb_result_init(&r->mc, "mc", &lo, &err) || ppb_result_init(&r->mc1, "mc1", &lo, &err))
        fail_msg("%s", err.msg);
    ppb_mc_tallies_to_results(&t, &cfg->scene, &r->mc, &r->mc1);
    ppb_mc_tallies_totals(&t, &cfg->scene, 0, &r->all);
    ppb_mc_tallies_totals(&t, &cfg->scene, 1, &r->once);
    ppb_mc_tallies_free(&t);
}

static void mc_free(mc_run *r)
{
    ppb_result_free(&r->mc), ppb_result_free(&r->mc1);
}

/* A deterministic method of the slice under test: ss or rte2d. */
static void run(ppb_config *cfg, const char *id, ppb_result *r)
{
    ppb_err err;
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    if (ppb_result_init(r, id, &lo, &err))
        fail_msg("%s", err.msg);
    ppb_run_ctx ctx = {.cfg = cfg, .ocl = *tu_ocl(), .ocl_open = 1, .quiet = 1};
    int rc =
        strcmp(id, "ss") == 0 ? ppb_method_ss(&ctx, r, &err) : ppb_rte2d_run(&ctx, r, NULL, &err);
    if (rc)
        fail_msg("%s: %s", id, err.msg);
}

/* Beer-Lambert from entry point xe at angle theta (n = 1, sigma_t 1): the path leaves through S2
 * after H / cos, or through S4 after (W/2 - xe) / sin when that is shorter. */
static double beer(double xe, double W, double H, double th)
{
    double l = H / cos(th);
    if (th > 0)
        l = fmin(l, (0.5 * W - xe) / sin(th));
    return exp(-l);
}

static void test_ballistic(void **state)
{
    (void)state;
    double th = 60 * PPB_PI / 180;
    /* Strip [3, 5] at 60 deg: entry points beyond 5 - 3 tan 60 = -0.196 leave through S4. */
    ppb_scene sc = strip_scene(4, 2, 60);
    double x[64], w[64], exact = 0;
    tu_gauss_legendre(64, 3, 5, x, w);
    for (int i = 0; i < 64; i++)
        exact += w[i] * beer(x[i], 10, 3, th) / 2;
    assert_close(ppb_ballistic_fraction(&sc), exact, 1e-12);
    ppb_scene line = strip_scene(4.5, 0, 60);
    assert_close(ppb_ballistic_fraction(&line), beer(4.5, 10, 3, th), 1e-14);

    /* The Monte Carlo's unscattered fraction: binomial, p from Beer-Lambert. */
    ppb_config cfg;
    ppb_err err;
    assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
    cfg.mc.photons = 200000;
    for (int c = 0; c < 2; c++) {
        cfg.scene = c ? line : sc;
        mc_run r;
        run_mc(&cfg, &r);
        double p = ppb_ballistic_fraction(&cfg.scene), binom = sqrt(p * (1 - p) / 200000);
        const ppb_totals *t = &r.all.mean;
        double sum = t->R + t->T + t->sides + t->absorbed + t->ballistic + t->specular;
        print_message("%s: mc ballistic %.5f vs Beer-Lambert %.5f (binomial se %.5f); R %.5f T "
                      "%.5f sides %.5f absorbed %.5f, sum - 1 = %.2g\n",
                      c ? "line x0 = 4.5" : "strip [3, 5]", t->ballistic, p, binom, t->R, t->T,
                      t->sides, t->absorbed, sum - 1);
        assert_close(t->ballistic, p, 4 * binom);
        assert_close(sum, 1.0, 1e-6);
        mc_free(&r);
    }
}

/* The small tube (16 x 6 segments, 4 x 4 bins) lit on the strip [-0.5, 1.5] at 30 degrees. */
static ppb_config strip_cfg(void)
{
    ppb_config cfg;
    ppb_err err;
    if (ppb_config_defaults(&cfg, &err))
        fail_msg("%s", err.msg);
    cfg.scene = strip_scene(0.5, 2, 30);
    cfg.scene.albedo = 0.9;
    cfg.scene.segments_top = 16;
    cfg.scene.segments_side = 6;
    cfg.scene.ntheta = cfg.scene.nphi = 4;
    cfg.samples_dir = 4; /* the bins' averages resolve the strip's steep profile to ~1e-3 */
    cfg.samples_seg = 8;
    cfg.rte2d.directions = 128;
    cfg.rte2d.spacing = cfg.rte2d.step = 0.1;
    cfg.mc.photons = 1000000;
    cfg.memory_limit = 0;
    return cfg;
}

/* Sum over the bins of surfaces [s0, s1) of ((a - m) / se)^2 where se > 0; *dof the count. */
static double chi2_of(const ppb_result *a, const ppb_result *m, int s0, int s1, int *dof)
{
    double chi2 = 0;
    *dof = 0;
    for (int s = s0; s < s1; s++)
        for (int seg = 0; seg < a->layout.nseg[s]; seg++)
            for (int b = 0; b < a->layout.nbins; b++) {
                size_t i = ppb_cell(&a->layout, s, seg, b);
                if (!(m->se[i] > 0.0))
                    continue;
                double z = (a->radiance[i] - m->radiance[i]) / m->se[i];
                chi2 += z * z;
                ++*dof;
            }
    return chi2;
}

static void test_rte2d_matches_mc(void **state)
{
    (void)state;
    ppb_config cfg = strip_cfg();
    ppb_result a;
    mc_run r;
    run(&cfg, "rte2d", &a);
    run_mc(&cfg, &r);
    int dof;
    double chi2 = chi2_of(&a, &r.mc, 0, PPB_NSURF, &dof), p = tu_chi2_pvalue(chi2, dof);
    const ppb_totals *t = &a.totals, *m = &r.all.mean, *se = &r.all.se;
    double bal = t->R + t->T + t->sides + t->absorbed + t->ballistic + t->specular - 1;
    print_message("strip [-0.5, 1.5] at 30 deg: rte2d vs mc chi2 %.1f over %d bins, p = %.3g; "
                  "R %.5f vs %.5f +- %.5f, T %.5f vs %.5f +- %.5f, sides %.5f vs %.5f +- %.5f, "
                  "absorbed %.5f vs %.5f; rte2d balance %.2g\n",
                  chi2, dof, p, t->R, m->R, se->R, t->T, m->T, se->T, t->sides, m->sides, se->sides,
                  t->absorbed, m->absorbed, bal);
    assert_true(dof > 500);
    assert_lt(1e-4, p);
    assert_close(t->R, m->R, 4 * se->R);
    assert_close(t->T, m->T, 4 * se->T);
    assert_close(t->sides, m->sides, 4 * se->sides);
    assert_close(bal, 0.0, 1e-6);
    ppb_result_free(&a);
    mc_free(&r);
}

/* ss's own error (the march step, the maps' bilinear cells) is of order 1e-3 relative; the
 * allowance 3e-3 of the total covers it, far below a strip placed wrong (an edge moved by one
 * map cell, 1/64 mfp, changes R1 by ~1 %). */
static void test_ss_matches_mc1(void **state)
{
    (void)state;
    ppb_config cfg = strip_cfg();
    ppb_result s;
    mc_run r;
    run(&cfg, "ss", &s);
    run_mc(&cfg, &r);
    const ppb_totals *m = &r.once.mean, *se = &r.once.se;
    int dof;
    double chi2 = chi2_of(&s, &r.mc1, PPB_S1, PPB_S2 + 1, &dof), p = tu_chi2_pvalue(chi2, dof);
    print_message(
        "strip [-0.5, 1.5] at 30 deg: ss vs mc1 chi2 %.1f over %d S1 and S2 bins, p = %.3g; "
        "R %.5f vs %.5f +- %.5f, T %.5f vs %.5f +- %.5f, sides %.5f vs %.5f +- %.5f\n",
        chi2, dof, p, s.totals.R, m->R, se->R, s.totals.T, m->T, se->T, s.totals.sides, m->sides,
        se->sides);
    assert_true(dof > 200);
    assert_lt(1e-4, p);
    assert_close(s.totals.R, m->R, 4 * se->R + 3e-3 * m->R);
    assert_close(s.totals.T, m->T, 4 * se->T + 3e-3 * m->T);
    ppb_result_free(&s);
    mc_free(&r);
}

static void test_line_is_narrow_strip_limit(void **state)
{
    (void)state;
    ppb_config cfg = strip_cfg();
    cfg.mc.photons = 200000;
    cfg.scene.light_width = 0;
    mc_run l, n;
    run_mc(&cfg, &l);
    cfg.scene.light_width = 1e-3;
    run_mc(&cfg, &n);
    const double *a = &l.all.mean.R, *b = &n.all.mean.R, *se = &l.all.se.R; /* R, T, sides */
    for (int k = 0; k < 3; k++) {
        print_message("line vs strip 1e-3: total %d: %.5f vs %.5f +- %.5f\n", k, a[k], b[k], se[k]);
        assert_close(a[k], b[k], 4 * se[k]);
    }
    /* Radiance per unit strength (reference: Light): the narrow strip's radiance per unit
     * E_perp over its width is the line's. Every cell of S2, within 4 of the line's standard
     * errors (the same photons, entering 5e-4 apart at most). */
    const ppb_layout *lo = &l.mc.layout;
    for (int seg = 0; seg < lo->nseg[PPB_S2]; seg++)
        for (int k = 0; k < lo->nbins; k++) {
            size_t c = ppb_cell(lo, PPB_S2, seg, k);
            assert_close(n.mc.radiance[c] / 1e-3, l.mc.radiance[c], 4 * l.mc.se[c] + 1e-12);
        }
    mc_free(&l), mc_free(&n);
}

/* Chandrasekhar's H-function of isotropic scattering with albedo alpha at mu = 1, iterated to a
 * fixed point of H(mu) = 1 / (1 - (alpha/2) mu int_0^1 H(mu') / (mu + mu') dmu') on 64
 * Gauss-Legendre nodes (Chandrasekhar, Radiative Transfer, 1960; test_mc.c's rule). */
static double chandrasekhar_h1(double alpha)
{
    enum { NQ = 64 };
    double x[NQ], w[NQ], h[NQ];
    tu_gauss_legendre(NQ, 0, 1, x, w);
    for (int i = 0; i < NQ; i++)
        h[i] = 1;
    for (int it = 0; it < 20000; it++) {
        double change = 0, hn[NQ];
        for (int i = 0; i < NQ; i++) {
            double sum = 0;
            for (int j = 0; j < NQ; j++)
                sum += w[j] * h[j] / (x[i] + x[j]);
            hn[i] = 1 / (1 - 0.5 * alpha * x[i] * sum);
            change = fmax(change, fabs(hn[i] - h[i]));
        }
        memcpy(h, hn, sizeof h);
        if (change < 1e-15)
            break;
    }
    double sum = 0;
    for (int j = 0; j < NQ; j++)
        sum += w[j] * h[j] / (1 + x[j]);
    return 1 / (1 - 0.5 * alpha * sum);
}

/* A tube 40 mfp wide and 20 deep is semi-infinite for a searchlight near its top centre (what
 * leaves through S2 and the sides, ~5e-5, bounds the difference), and a semi-infinite medium is
 * invariant along x: whatever the lit strip or line, the fraction reflected is the plane albedo,
 * at normal light with isotropic scattering 1 - H(1) sqrt(1 - alpha) (Chandrasekhar 1960), of
 * which single scattering is (alpha/2)(1 - ln 2) (its closed form: (alpha/2) int_0^1 mu / (mu + 1)
 * dmu). mc (line and strip) and mc1 within 4 standard errors plus that leak; ss on the strip
 * within 3e-3 (its march error; measured 1.3e-3 at pp.step 0.05). */
static void test_semi_infinite(void **state)
{
    (void)state;
    const double alpha = 0.9;
    double r_all = 1 - chandrasekhar_h1(alpha) * sqrt(1 - alpha);
    double r_once = 0.5 * alpha * (1 - log(2.0));
    ppb_config cfg;
    ppb_err err;
    assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
    cfg.scene = strip_scene(3, 0, 0);
    cfg.scene.width = 40, cfg.scene.height = 20, cfg.scene.albedo = alpha;
    cfg.scene.segments_top = 40, cfg.scene.segments_side = 20;
    cfg.scene.ntheta = cfg.scene.nphi = 4;
    cfg.mc.photons = 400000;
    for (int c = 0; c < 2; c++) {
        cfg.scene.light_width = c; /* the line at x = 3, then the strip [2.5, 3.5] */
        mc_run r;
        run_mc(&cfg, &r);
        const ppb_totals *m = &r.all.mean, *m1 = &r.once.mean;
        double leak = m->T + m->sides;
        print_message("%s: R %.5f +- %.5f vs plane albedo %.5f; R1 %.5f +- %.5f vs %.5f; leak "
                      "%.2g\n",
                      c ? "strip [2.5, 3.5]" : "line x0 = 3", m->R, r.all.se.R, r_all, m1->R,
                      r.once.se.R, r_once, leak);
        assert_close(m->R, r_all, 4 * r.all.se.R + leak);
        assert_close(m1->R, r_once, 4 * r.once.se.R + leak);
        if (c == 1) {
            ppb_result s;
            run(&cfg, "ss", &s);
            print_message("ss strip: R1 %.6f vs %.6f (rel %.2g)\n", s.totals.R, r_once,
                          s.totals.R / r_once - 1);
            assert_close(s.totals.R, r_once, 3e-3 * r_once);
            ppb_result_free(&s);
        }
        mc_free(&r);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_keys),           cmocka_unit_test(test_lit_part),
        cmocka_unit_test(test_ballistic),      cmocka_unit_test(test_rte2d_matches_mc),
        cmocka_unit_test(test_ss_matches_mc1), cmocka_unit_test(test_line_is_narrow_strip_limit),
        cmocka_unit_test(test_semi_infinite),
    };
    return cmocka_run_group_tests(tests, tu_open_device, tu_close_device);
}
