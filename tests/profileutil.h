/* profileutil.h: what the suites of the profile models (bdipole, burley, dirpole, pbd) share: an
 * independent graded quadrature for the profiles' singular integrands, the entering fraction
 * and the media on either side of a scene's step, and the runs of their method-level tests
 * (every study config, the robustness grid's corners, slab mode, [method] samples on the tube).
 * The runs are here once; what a suite expects of each run stays in the suite, as a callback.
 * Include after testutil.h and study_cases.h. */
#ifndef PPB_TEST_PROFILEUTIL_H
#define PPB_TEST_PROFILEUTIL_H

#include <math.h>

#include "kernels/ppb_fresnel.h"
#include "methods/registry.h"
#include "model/config.h"

/* int_a^b f by 10-point Gauss-Legendre panels halving toward a from b (down to 1e-15 of b - a),
 * then uniform panels of h: independent of the methods' own quadratures, which it checks. */
typedef double (*pu_fn1)(double x, const void *arg);
static inline double pu_graded(pu_fn1 f, const void *arg, double a, double b, double h)
{
    static const double x[5] = {0.1488743389816312, 0.4333953941292472, 0.6794095682990244,
                                0.8650633666889845, 0.9739065285171717};
    static const double w[5] = {0.2955242247147529, 0.2692667193099963, 0.2190863625159820,
                                0.1494513491505806, 0.0666713443086881};
    double sum = 0, c = fmin(b, a + h), hi = c;
    for (;;) {
        double lo = hi - a > 1e-15 * (c - a) ? a + 0.5 * (hi - a) : a;
        double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo);
        for (int j = 0; j < 5; j++)
            sum += half * w[j] * (f(mid - half * x[j], arg) + f(mid + half * x[j], arg));
        if (lo == a)
            break;
        hi = lo;
    }
    for (double lo = c; lo < b; lo += h) {
        double hi2 = fmin(b, lo + h), half = 0.5 * (hi2 - lo), mid = 0.5 * (hi2 + lo);
        for (int j = 0; j < 5; j++)
            sum += half * w[j] * (f(mid - half * x[j], arg) + f(mid + half * x[j], arg));
    }
    return sum;
}

/* The fraction of the beam that enters: 1 - F(theta_L) under a boundary, 1 at n = 1. */
static inline double pu_entry(const ppb_scene *sc)
{
    return sc->n > 1 ? 1 - ppb_fresnel(cos(sc->theta_deg * PPB_PI / 180), sc->n) : 1;
}

/* The medium of side 0 (left of a step, or the only one) or 1 (right of it): the bounds take
 * the larger of the two, so each suite looks at both. */
static inline void pu_side_medium(const ppb_scene *sc, int side, double *sigma_t, double *albedo)
{
    *sigma_t = side && sc->step == PPB_STEP_DENSITY ? sc->sigma_t_right : sc->sigma_t;
    *albedo = side && sc->step == PPB_STEP_ALBEDO ? sc->albedo_right : sc->albedo;
}

/* Every radiance of out finite and >= 0. */
static inline void pu_assert_cells(const ppb_result *out)
{
    for (size_t i = 0; i < out->layout.ncells; i++) {
        assert_true(isfinite(out->radiance[i]));
        assert_true(out->radiance[i] >= 0);
    }
}

/* S1's bins average R cos(theta_L) / pi: the exit lobe distributes the flux it is given. */
static inline void pu_assert_lobe_mean(const ppb_result *out, double mu)
{
    double mean = 0;
    for (int bin = 0; bin < out->layout.nbins; bin++)
        mean += out->radiance[ppb_cell(&out->layout, PPB_S1, 0, bin)] / out->layout.nbins;
    assert_rel(mean, out->totals.R * mu / PPB_PI, 1e-12);
}

/* A suite's settings on a config before it runs (NULL: none) and its checks of one run. */
typedef void (*pu_setup)(ppb_config *cfg);
typedef void (*pu_study_check)(const char *name, ppb_run_ctx *ctx, const ppb_result *out);

/* Method id on every study config (configs/study.list) after setup: every cell checked
 * (pu_assert_cells), then the suite's own bounds. */
static inline void pu_study_configs(const char *id, pu_setup setup, pu_study_check check)
{
    char names[STUDY_MAX_CASES][64];
    int ncase = study_cases(names);
    for (int c = 0; c < ncase; c++) {
        ppb_config cfg;
        study_load_config(names[c], &cfg);
        if (setup)
            setup(&cfg);
        ppb_run_ctx ctx = {.cfg = &cfg, .quiet = 1};
        ppb_result out;
        study_run_id(&ctx, id, &out);
        pu_assert_cells(&out);
        check(names[c], &ctx, &out);
        ppb_result_free(&out);
        ppb_ctx_close(&ctx);
    }
}

/* One corner of the robustness grid. */
typedef struct pu_corner {
    double albedo, g, height, theta, n;
} pu_corner;

/* One axis of the robustness grid: its values and their count (PU_AXIS of an array). */
typedef struct pu_axis {
    const double *v;
    int n;
} pu_axis;
#define PU_AXIS(a) ((pu_axis){(a), (int)(sizeof(a) / sizeof((a)[0]))})

/* The robustness grid of a suite (tests/test_robust.c's values, or a part of them): slab 1 runs
 * each corner as a tube and as a slab, 0 as a tube only; a theta of no values keeps the tube's
 * normal light. */
typedef struct pu_grid {
    int slab;
    pu_axis albedo, g, height, theta, n;
} pu_grid;

typedef void (*pu_corner_check)(const pu_corner *c, ppb_run_ctx *ctx, const ppb_result *out);

/* Method id at every corner of grid on a coarse scene (8 top and 4 side segments, one sample a
 * segment), after setup: every cell finite and >= 0 (a failure names the corner), then check
 * (NULL: none). The method's own result checks run inside study_run_id. */
static inline void pu_extremes(const char *id, const pu_grid *grid, pu_setup setup,
                               pu_corner_check check)
{
    /* The corners in the order of nested loops over geometry, albedo, g, H, theta_L and n. */
    const int len[6] = {grid->slab ? 2 : 1,
                        grid->albedo.n,
                        grid->g.n,
                        grid->height.n,
                        grid->theta.n ? grid->theta.n : 1,
                        grid->n.n};
    int total = len[0] * len[1] * len[2] * len[3] * len[4] * len[5];
    for (int k = 0; k < total; k++) {
        int at[6];
        for (int a = 5, r = k; a >= 0; r /= len[a], a--)
            at[a] = r % len[a];
        int geo = at[0];
        pu_corner c = {grid->albedo.v[at[1]], grid->g.v[at[2]], grid->height.v[at[3]],
                       grid->theta.n ? grid->theta.v[at[4]] : 0, grid->n.v[at[5]]};
        ppb_config cfg;
        ppb_err err;
        assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
        cfg.scene = geo ? tu_slab(c.height, c.albedo, c.g, c.theta) : tu_tube();
        cfg.scene.albedo = c.albedo;
        cfg.scene.g = c.g;
        cfg.scene.height = c.height;
        if (grid->theta.n)
            cfg.scene.theta_deg = c.theta;
        c.theta = cfg.scene.theta_deg;
        cfg.scene.n = c.n;
        cfg.scene.segments_top = 8;
        cfg.scene.segments_side = 4;
        cfg.samples_seg = 1;
        if (setup)
            setup(&cfg);
        ppb_run_ctx ctx = {.cfg = &cfg, .quiet = 1};
        ppb_result out;
        study_run_id(&ctx, id, &out);
        for (size_t i = 0; i < out.layout.ncells; i++)
            if (!(isfinite(out.radiance[i]) && out.radiance[i] >= 0))
                fail_msg("albedo %g g %g H %g theta %g n %g: cell %zu = %g", c.albedo, c.g,
                         c.height, c.theta, c.n, i, out.radiance[i]);
        if (check)
            check(&c, &ctx, &out);
        ppb_result_free(&out);
        ppb_ctx_close(&ctx);
    }
    print_message("%d runs at the extremes\n", total);
}

typedef void (*pu_slab_check)(ppb_run_ctx *ctx, const ppb_result *out, double mu, double entry);

/* Method id in slab mode on the slab every profile suite checks (H 3, albedo 0.95, g 0,
 * theta_L 30 deg) at n = 1 and 1.4; check gets mu = cos(theta_L) and the entering fraction. */
static inline void pu_slab_mode(const char *id, pu_slab_check check)
{
    const double n[] = {1.0, 1.4};
    for (int i = 0; i < 2; i++) {
        ppb_config cfg;
        ppb_err err;
        assert_int_equal(ppb_config_defaults(&cfg, &err), 0);
        cfg.scene = tu_slab(3.0, 0.95, 0.0, 30.0);
        cfg.scene.n = n[i];
        ppb_run_ctx ctx = {.cfg = &cfg, .quiet = 1};
        ppb_result out;
        study_run_id(&ctx, id, &out);
        check(&ctx, &out, cos(cfg.scene.theta_deg * PPB_PI / 180), pu_entry(&cfg.scene));
        ppb_result_free(&out);
        ppb_ctx_close(&ctx);
    }
}

/* Sets the method's [method] samples. */
typedef void (*pu_set_samples)(ppb_config *cfg, int samples);

/* Method id on the study's case name at 32 top and 12 side segments (albedo as given, NAN: the
 * case's own): every cell at samples 8 and 16 against 64, the difference printed, within 1e-10
 * at 16 (the default). */
static inline void pu_samples_converge(const char *id, const char *name, double albedo,
                                       pu_set_samples set)
{
    ppb_config cfg;
    study_load_config(name, &cfg);
    cfg.scene.segments_top = 32;
    cfg.scene.segments_side = 12;
    if (!isnan(albedo))
        cfg.scene.albedo = albedo;
    char label[160];
    if (isnan(albedo))
        snprintf(label, sizeof label, "%s", name);
    else
        snprintf(label, sizeof label, "%s (albedo %g)", name, albedo);
    ppb_run_ctx ctx = {.cfg = &cfg, .quiet = 1};
    ppb_result ref, r;
    set(&cfg, 64);
    study_run_id(&ctx, id, &ref);
    const int nodes[] = {8, 16};
    for (int k = 0; k < 2; k++) {
        set(&cfg, nodes[k]);
        study_run_id(&ctx, id, &r);
        double worst = 0;
        for (size_t i = 0; i < r.layout.ncells; i++)
            worst = fmax(worst, fabs(r.radiance[i] - ref.radiance[i]) / ref.radiance[i]);
        print_message("%s: samples %2d vs 64: largest relative cell difference %.2e\n", label,
                      nodes[k], worst);
        if (nodes[k] == 16)
            assert_lt(worst, 1e-10);
        ppb_result_free(&r);
    }
    ppb_result_free(&ref);
    ppb_ctx_close(&ctx);
}

#endif
