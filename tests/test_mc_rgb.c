/* test_mc_rgb.c: the multi-channel Monte Carlo (mc_rgb.cl; docs/methods.md, Monte Carlo: several
 * channels in one run). Its expected values come from the single-channel kernel (mc.cl), an
 * independent estimator of the same transport validated by tests/test_mc.c against closed forms
 * and published tables: every channel of one hero-sampled run must agree with that channel's
 * own single-channel run within their joint noise (per cell and per surface total), on a
 * measured material at rendering scale (skimmilk, mm) and on a density step with a g per channel
 * (white grapefruit juice), and on channels far apart in sigma_t, albedo and g. Energy is conserved
 * per channel in expectation (R + T + sides + ballistic + absorbed + specular = 1: each term is an
 * unbiased estimate of the channel's own). With three equal channels every weight is exactly the
 * single-channel weight, so the tallies are its bytes. The tallies do not depend on work-group size
 * or chunking, a target noise stops the run at a prefix, and the registry's entry uses cached
 * single-channel references when every channel has one. Experiments that differ beyond the medium
 * are refused. Every statistical bound is in units of the runs' own standard errors. */
#include "testutil.h"

#include <math.h>

#include "methods/mc/mc_tally.h"
#include "methods/mc/method_mc.h"
#include "model/materials.h"

/* One device for the whole suite ($PPBENCH_DEVICE or 0). */
static ppb_run_ctx ctx;

static ppb_config config_of(ppb_scene sc, long long photons)
{
    ppb_config cfg;
    ppb_err err;
    if (ppb_config_defaults(&cfg, &err))
        fail_msg("%s", err.msg);
    cfg.scene = sc;
    cfg.mc.first = 0, cfg.mc.chunk = 0, cfg.mc.workgroup = 0, cfg.mc.target_noise = 0;
    cfg.mc.photons = photons;
    cfg.mc.batches = 32;
    cfg.mc.seed = 7;
    return cfg;
}

/* The three channels of a material in a tube of W x H mm (its n; unit = mm). */
static void material_configs(const char *name, ppb_scene sc, long long photons, ppb_config *cfgs)
{
    const ppb_material *m = ppb_material_find(name);
    assert_non_null(m);
    for (int c = 0; c < 3; c++) {
        ppb_scene s = sc;
        ppb_material_medium(m, (ppb_channel)c, &s.sigma_t, &s.albedo, &s.g, &s.n);
        s.sigma_t_right = 0.5 * s.sigma_t, s.albedo_right = s.albedo;
        cfgs[c] = config_of(s, photons);
    }
}

static void trace_single(const ppb_config *cfg, ppb_mc_tallies *t)
{
    ppb_err err;
    ctx.cfg = cfg;
    if (ppb_mc_tallies_init(t, &cfg->scene, (uint64_t)cfg->mc.seed, cfg->mc.batches, &err) ||
        ppb_mc_trace(&ctx, 0, cfg->mc.photons, t, NULL, &err))
        fail_msg("%s", err.msg);
}

static void trace_rgb(const ppb_config *cfgs, int nch, ppb_mc_tallies *t)
{
    ppb_err err;
    ppb_mc_rgb_params ch;
    if (ppb_mc_rgb_params_of(cfgs, nch, &ch, &err))
        fail_msg("%s", err.msg);
    for (int c = 0; c < nch; c++)
        if (ppb_mc_tallies_init(&t[c], &cfgs[c].scene, (uint64_t)cfgs[c].mc.seed,
                                cfgs[c].mc.batches, &err))
            fail_msg("%s", err.msg);
    ctx.cfg = &cfgs[0];
    ppb_mc_trace_info info;
    if (ppb_mc_trace_channels(&ctx, &ch, 0, cfgs[0].mc.photons, t, &info, &err))
        fail_msg("%s", err.msg);
    assert_int_equal(info.traced, cfgs[0].mc.photons);
}

/* Channel c of the hero run (a) against its single run (b): the mean of z^2 = (a - b)^2 /
 * (se_a^2 + se_b^2) over the cells of mc where both runs have relative error below 0.2 (so
 * that z is near normal), and each total within 3 joint standard errors. With standard errors
 * from 32 batches z follows about Student's t with 62 degrees of freedom, E z^2 = 62/60; over N
 * cells the mean has spread sqrt(2/N) or so (correlated cells widen it a little), so it must
 * lie in [0.75, 1.35] when N > 150 (an error of the weights as small as 2% of the
 * noise in every cell would move it by 0.0004 per cell, a wrong density ratio by far more). */
static void compare_channel(const ppb_config *cfg, const ppb_mc_tallies *a, const ppb_mc_tallies *b,
                            const char *what)
{
    ppb_err err;
    ppb_layout lo = ppb_scene_layout(&cfg->scene);
    ppb_result ra, rb;
    if (ppb_result_init(&ra, "mc", &lo, &err) || ppb_result_init(&rb, "mc", &lo, &err))
        fail_msg("%s", err.msg);
    ppb_mc_tallies_to_results(a, &cfg->scene, &ra, NULL);
    ppb_mc_tallies_to_results(b, &cfg->scene, &rb, NULL);
    double chi2 = 0;
    int n = 0;
    for (size_t i = 0; i < lo.ncells; i++) {
        if (!(ra.se[i] > 0 && rb.se[i] > 0 && ra.se[i] < 0.2 * ra.radiance[i] &&
              rb.se[i] < 0.2 * rb.radiance[i]))
            continue;
        double d = ra.radiance[i] - rb.radiance[i];
        chi2 += d * d / (ra.se[i] * ra.se[i] + rb.se[i] * rb.se[i]);
        n++;
    }
    print_message("%s: chi2/bin %.3f over %d cells; R %.5f vs %.5f\n", what, chi2 / n, n,
                  ra.totals.R, rb.totals.R);
    if (n < 150)
        fail_msg("%s: only %d well-measured cells", what, n);
    assert_between(chi2 / n, 0.75, 1.35);
    ppb_mc_totals_stats sa, sb;
    ppb_mc_tallies_totals(a, &cfg->scene, 0, &sa);
    ppb_mc_tallies_totals(b, &cfg->scene, 0, &sb);
    const double va[5] = {sa.mean.R, sa.mean.T, sa.mean.sides, sa.mean.absorbed, sa.mean.ballistic};
    const double ea[5] = {sa.se.R, sa.se.T, sa.se.sides, sa.se.absorbed, sa.se.ballistic};
    const double vb[5] = {sb.mean.R, sb.mean.T, sb.mean.sides, sb.mean.absorbed, sb.mean.ballistic};
    const double eb[5] = {sb.se.R, sb.se.T, sb.se.sides, sb.se.absorbed, sb.se.ballistic};
    const char *names[5] = {"R", "T", "sides", "absorbed", "ballistic"};
    for (int k = 0; k < 5; k++) {
        double bound = 3 * sqrt(ea[k] * ea[k] + eb[k] * eb[k]);
        if (!(fabs(va[k] - vb[k]) <= bound))
            fail_msg("%s: %s %.6f (hero) vs %.6f (single), beyond 3 joint se %.6f", what, names[k],
                     va[k], vb[k], bound);
    }
    assert_true(sa.mean.specular == sb.mean.specular);
    /* Energy per channel: the terms' standard errors added (at least the sum's). */
    double sum = sa.mean.R + sa.mean.T + sa.mean.sides + sa.mean.absorbed + sa.mean.ballistic +
                 sa.mean.specular;
    double bound = 3 * (sa.se.R + sa.se.T + sa.se.sides + sa.se.absorbed + sa.se.ballistic);
    if (!(fabs(sum - 1) <= bound))
        fail_msg("%s: energy %.6f, 1 expected +- %.6f", what, sum, bound);
    ppb_result_free(&ra);
    ppb_result_free(&rb);
}

/* Coarse bins, so that most cells are well measured with 2e5 photons. */
static ppb_scene coarse_tube(double w, double h)
{
    ppb_scene sc = tu_tube();
    sc.width = w, sc.height = h;
    sc.segments_top = 16, sc.segments_side = 6;
    sc.ntheta = 4, sc.nphi = 4;
    return sc;
}

static void agree_with_single(const ppb_config *cfgs, const char *name)
{
    ppb_mc_tallies rgb[3], one;
    trace_rgb(cfgs, 3, rgb);
    for (int c = 0; c < 3; c++) {
        char what[96];
        snprintf(what, sizeof what, "%s channel %d", name, c);
        /* Another seed: with the same one, the photons whose hero is c would fly the single
         * run's paths, and the two runs' noise would be correlated. */
        ppb_config single = cfgs[c];
        single.mc.seed = cfgs[c].mc.seed + 1;
        trace_single(&single, &one);
        compare_channel(&cfgs[c], &rgb[c], &one, what);
        ppb_mc_tallies_free(&one);
        ppb_mc_tallies_free(&rgb[c]);
    }
}

/* Skimmilk (Jensen et al. 2001; sigma_t 0.70 to 1.91 /mm, n = 1.3) in a 4 x 2 mm tube. */
static void test_skimmilk_agrees(void **state)
{
    (void)state;
    ppb_config cfgs[3];
    material_configs("skimmilk", coarse_tube(4, 2), 200000, cfgs);
    agree_with_single(cfgs, "skimmilk");
}

/* White grapefruit juice (Narasimhan et al. 2006: g 0.545 to 0.565 by channel, so the HG ratio
 * acts) in a 6 x 3 mm tube with the density step (sigma_t halved right of x = 0), light at 30
 * degrees. */
static void test_density_step_g_agrees(void **state)
{
    (void)state;
    ppb_scene sc = coarse_tube(6, 3);
    sc.step = PPB_STEP_DENSITY;
    sc.theta_deg = 30;
    ppb_config cfgs[3];
    material_configs("white_grapefruit_juice", sc, 200000, cfgs);
    assert_true(cfgs[0].scene.g != cfgs[2].scene.g);
    agree_with_single(cfgs, "grapefruit step");
}

/* Channels far apart in every coefficient (sigma_t 1, 1.6, 2.5 per mm; albedo 0.99, 0.95, 0.9;
 * g 0, 0.5, 0.85), n = 1.33, in a 5 x 2 mm tube lit at 45 degrees: the HG ratio and the
 * density ratio both far from 1 (a small g spread, as in the measured rows, hardly tests it). */
static void test_spread_channels_agree(void **state)
{
    (void)state;
    const double sig[3] = {1.0, 1.6, 2.5}, alb[3] = {0.99, 0.95, 0.9}, g[3] = {0.0, 0.5, 0.85};
    ppb_config cfgs[3];
    for (int c = 0; c < 3; c++) {
        ppb_scene sc = coarse_tube(5, 2);
        sc.n = 1.33, sc.theta_deg = 45;
        sc.sigma_t = sig[c], sc.albedo = alb[c], sc.g = g[c];
        cfgs[c] = config_of(sc, 200000);
    }
    agree_with_single(cfgs, "spread");
}

/* Three equal channels: every l_k is 0, so W_c = a_c, mc.cl's weight, operation for operation
 * (mc_rgb.cl): the bytes of the single run, at n = 1 and at n = 1.4 with the density step. */
static void test_equal_channels_are_single_bytes(void **state)
{
    (void)state;
    for (int variant = 0; variant < 2; variant++) {
        ppb_scene sc = tu_tube();
        if (variant) {
            sc.n = 1.4, sc.step = PPB_STEP_DENSITY, sc.theta_deg = 45, sc.g = 0.5;
        }
        ppb_config cfgs[3];
        for (int c = 0; c < 3; c++)
            cfgs[c] = config_of(sc, 50000);
        ppb_mc_tallies rgb[3], one;
        trace_rgb(cfgs, 3, rgb);
        trace_single(&cfgs[0], &one);
        for (int c = 0; c < 3; c++) {
            if (!ppb_mc_tallies_equal(&rgb[c], &one))
                fail_msg("variant %d: channel %d's tallies differ from the single run's", variant,
                         c);
            ppb_mc_tallies_free(&rgb[c]);
        }
        ppb_mc_tallies_free(&one);
    }
}

/* The same bytes whatever the work-group size, chunking and lanes (as tests/test_mc.c checks
 * mc). */
static void test_reproducible(void **state)
{
    (void)state;
    ppb_scene sc = coarse_tube(4, 2);
    sc.step = PPB_STEP_DENSITY;
    ppb_config cfgs[3];
    material_configs("skimmilk", sc, 40000, cfgs);
    ppb_mc_tallies ref[3], t[3];
    trace_rgb(cfgs, 3, ref);
    for (int v = 0; v < 3; v++) {
        for (int c = 0; c < 3; c++) {
            cfgs[c].mc.workgroup = v == 0 ? 16 : 0;
            cfgs[c].mc.chunk = v == 1 ? 10000 : v == 2 ? 7777 : 0;
        }
        trace_rgb(cfgs, 3, t);
        for (int c = 0; c < 3; c++) {
            if (!ppb_mc_tallies_equal(&ref[c], &t[c]))
                fail_msg("channel %d differs with %s", c,
                         v == 0   ? "work-group size 16"
                         : v == 1 ? "4 chunks"
                                  : "7777-photon chunks");
            ppb_mc_tallies_free(&t[c]);
        }
    }
    /* Lanes per work-item (method_mc.c's device_shape; PPBENCH_MC_LANES): the exp and log of
     * mc_rgb.cl are plain arithmetic, so no lane width changes a bit. */
    for (int c = 0; c < 3; c++)
        cfgs[c].mc.workgroup = 0, cfgs[c].mc.chunk = 0;
    const char *lanes[4] = {"2", "4", "8", "16"};
    for (int i = 0; i < 4; i++) {
        setenv("PPBENCH_MC_LANES", lanes[i], 1);
        trace_rgb(cfgs, 3, t);
        unsetenv("PPBENCH_MC_LANES");
        for (int c = 0; c < 3; c++) {
            if (!ppb_mc_tallies_equal(&ref[c], &t[c]))
                fail_msg("channel %d differs with %s lanes", c, lanes[i]);
            ppb_mc_tallies_free(&t[c]);
        }
    }
    for (int c = 0; c < 3; c++)
        ppb_mc_tallies_free(&ref[c]);
}

/* A target noise stops the joint run between chunks once every channel meets it (checked as
 * mc checks it, noise_rel at the Table 2 cells); what was traced is a prefix, so the tallies are
 * those of a run of that many photons. */
static void test_target_noise(void **state)
{
    (void)state;
    ppb_config cfgs[3];
    material_configs("skimmilk", coarse_tube(4, 2), 2000000, cfgs);
    for (int c = 0; c < 3; c++)
        cfgs[c].mc.chunk = 20000, cfgs[c].mc.target_noise = 0.3;
    ppb_mc_rgb_params ch;
    ppb_err err;
    ppb_mc_tallies t[3], u[3];
    if (ppb_mc_rgb_params_of(cfgs, 3, &ch, &err))
        fail_msg("%s", err.msg);
    for (int c = 0; c < 3; c++)
        if (ppb_mc_tallies_init(&t[c], &cfgs[c].scene, (uint64_t)cfgs[c].mc.seed,
                                cfgs[c].mc.batches, &err))
            fail_msg("%s", err.msg);
    ctx.cfg = &cfgs[0];
    ppb_mc_trace_info info;
    if (ppb_mc_trace_channels(&ctx, &ch, 0, cfgs[0].mc.photons, t, &info, &err))
        fail_msg("%s", err.msg);
    assert_true(info.reached_noise);
    assert_true(info.traced < cfgs[0].mc.photons && info.traced % 20000 == 0);
    for (int c = 0; c < 3; c++)
        cfgs[c].mc.photons = info.traced, cfgs[c].mc.target_noise = 0;
    trace_rgb(cfgs, 3, u);
    for (int c = 0; c < 3; c++) {
        assert_true(ppb_mc_tallies_equal(&t[c], &u[c]));
        ppb_mc_tallies_free(&t[c]);
        ppb_mc_tallies_free(&u[c]);
    }
}

/* The registry's entry (ppb_mc_run_channels): without a cache, the hero run's results (the
 * same bytes as ppb_mc_trace_channels' tallies converted); with every channel's single-channel
 * reference in the cache (stored by ppb_method_mc), those references, no photon traced. */
static void test_run_channels_entry(void **state)
{
    (void)state;
    ppb_config cfgs[3];
    material_configs("skimmilk", coarse_tube(4, 2), 20000, cfgs);
    ppb_layout lo = ppb_scene_layout(&cfgs[0].scene);
    ppb_result out[6], single[2];
    ppb_err err;
    for (int i = 0; i < 6; i++)
        if (ppb_result_init(&out[i], i % 2 ? "mc1" : "mc", &lo, &err))
            fail_msg("%s", err.msg);
    ppb_mc_tallies t[3];
    trace_rgb(cfgs, 3, t);
    if (ppb_mc_run_channels(&ctx, cfgs, 3, out, &err))
        fail_msg("%s", err.msg);
    for (int c = 0; c < 3; c++) {
        ppb_result r;
        if (ppb_result_init(&r, "mc", &lo, &err))
            fail_msg("%s", err.msg);
        ppb_mc_tallies_to_results(&t[c], &cfgs[c].scene, &r, NULL);
        assert_memory_equal(r.radiance, out[2 * c].radiance, lo.ncells * sizeof(double));
        assert_true(out[2 * c].photons == 20000 && !out[2 * c].partial);
        ppb_result_free(&r);
        ppb_mc_tallies_free(&t[c]);
    }
    char dir[1100];
    snprintf(dir, sizeof dir, "%s/cache", tu_scratch("mc_rgb_cache"));
    ctx.ref_cache = dir;
    for (int c = 0; c < 3; c++) {
        ctx.cfg = &cfgs[c];
        for (int i = 0; i < 2; i++)
            if (ppb_result_init(&single[i], i ? "mc1" : "mc", &lo, &err))
                fail_msg("%s", err.msg);
        if (ppb_method_mc(&ctx, single, &err))
            fail_msg("%s", err.msg);
        ppb_result_free(&single[1]);
        if (c < 2)
            ppb_result_free(&single[0]);
    }
    if (ppb_mc_run_channels(&ctx, cfgs, 3, out, &err))
        fail_msg("%s", err.msg);
    ctx.ref_cache = NULL;
    assert_memory_equal(single[0].radiance, out[4].radiance, lo.ncells * sizeof(double));
    assert_true(ctx.mc_reference[0] != '\0');
    ppb_result_free(&single[0]);
    for (int i = 0; i < 6; i++)
        ppb_result_free(&out[i]);
}

/* Channels that differ beyond the medium, or in their [mc] settings, are refused by name. */
static void test_refuses_other_scenes(void **state)
{
    (void)state;
    ppb_config cfgs[3];
    material_configs("skimmilk", coarse_tube(4, 2), 1000, cfgs);
    ppb_mc_rgb_params ch;
    ppb_err err;
    assert_int_equal(ppb_mc_rgb_params_of(cfgs, 3, &ch, &err), 0);
    cfgs[1].scene.width = 5;
    assert_int_equal(ppb_mc_rgb_params_of(cfgs, 3, &ch, &err), -1);
    assert_non_null(strstr(err.msg, "channel 1"));
    cfgs[1].scene.width = 4;
    cfgs[2].scene.n = 1.5;
    assert_int_equal(ppb_mc_rgb_params_of(cfgs, 3, &ch, &err), -1);
    assert_non_null(strstr(err.msg, "channel 2"));
    cfgs[2].scene.n = cfgs[0].scene.n;
    cfgs[2].mc.seed = 9;
    assert_int_equal(ppb_mc_rgb_params_of(cfgs, 3, &ch, &err), -1);
    assert_non_null(strstr(err.msg, "[mc]"));
    assert_int_equal(ppb_mc_rgb_params_of(cfgs, 4, &ch, &err), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_refuses_other_scenes),
        cmocka_unit_test(test_equal_channels_are_single_bytes),
        cmocka_unit_test(test_reproducible),
        cmocka_unit_test(test_run_channels_entry),
        cmocka_unit_test(test_target_noise),
        cmocka_unit_test(test_skimmilk_agrees),
        cmocka_unit_test(test_density_step_g_agrees),
        cmocka_unit_test(test_spread_channels_agree),
    };
    ctx.quiet = 1;
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    ppb_ctx_close(&ctx);
    return rc;
}
