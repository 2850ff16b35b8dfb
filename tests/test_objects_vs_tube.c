/* test_objects_vs_tube.c: the object methods against independent codes within the Monte Carlo's
 * noise. (1) mc3d in the middle of a box long in z whose cross-section is the study tube's
 * (10 x 3 mfp, configs/uniform_g0_normal.ini's medium, lit from the top) against the tube's mc
 * (methods/mc: its own OpenCL kernel, 2-D geometry, its own tallies): per (surface, segment,
 * theta bin) of the middle slice's S1 and S2, and per face (R, T, the sides). (2) ss3d (host march,
 * methods/pp3d) against mc3d1 (the Monte Carlo's once-scattered photons) on a box, a sphere and the
 * yokan with its inclusion, every patch cell. ss3d and pp3d against the tube's ss and pp are in
 * test_pp3d.
 *
 * Statistics: the Monte Carlo's standard errors come from B = 16 batch means, so
 * (x - ref) / se is a Student t with 15 degrees of freedom, whose square has mean 15/13 and
 * variance 2 15^2 14 / (13^2 11) (an F(1, 15)); a chi-square over N cells is held to that mean
 * plus 5 of its standard deviations sqrt(var / N) (cells independent: one photon leaves a
 * convex object once, so different cells hold different photons). */
#include "testutil.h"

#include <math.h>

#include "methods/mc/method_mc.h"
#include "methods/mc3d/method_mc3d.h"
#include "methods/pp3d/pp3d.h"
#include "model/object_build.h"

static ppb_run_ctx g_ctx;

static int setup(void **state)
{
    (void)state;
    memset(&g_ctx, 0, sizeof g_ctx);
    g_ctx.quiet = 2;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    ppb_ctx_close(&g_ctx);
    return 0;
}

/* The defaults with sets[] ("section.key=value"). */
static void load(ppb_config *cfg, const char *const *sets, int nsets)
{
    ppb_err err;
    if (ppb_config_defaults(cfg, &err))
        fail_msg("%s", err.msg);
    for (int i = 0; i < nsets; i++) {
        char sec[64], key[64], val[256];
        if (sscanf(sets[i], "%63[^.].%63[^=]=%255[^\n]", sec, key, val) != 3)
            fail_msg("bad set %s", sets[i]);
        if (ppb_config_set(cfg, sec, key, val, &err))
            fail_msg("%s", err.msg);
    }
}

/* The chi-square bound above for n cells of t-distributed residuals with B = 16 batches. */
static double chi2_bound(long n)
{
    double nu = 15.0, mean = nu / (nu - 2.0);
    double var = 2.0 * nu * nu * (nu - 1.0) / ((nu - 2.0) * (nu - 2.0) * (nu - 4.0));
    return mean + 5.0 * sqrt(var / (double)n);
}

/* The object of cfg, its patches and mc3d's two results (mc3d, mc3d1). */
static void trace(ppb_config *cfg, ppb_object *o, ppb_object_patches *p, ppb_object_result r[2])
{
    ppb_err err;
    g_ctx.cfg = cfg;
    if (ppb_object_build(cfg, o, &err) || ppb_object_patches_build(o, p, &err))
        fail_msg("%s", err.msg);
    int nb = o->ntheta * o->nphi;
    for (int i = 0; i < 2; i++)
        if (ppb_object_result_init(&r[i], i ? "mc3d1" : "mc3d", p->npatch, nb, o->img_w, o->img_h,
                                   &err))
            fail_msg("%s", err.msg);
    if (ppb_mc3d_trace(&g_ctx, o, p, r, NULL, &err))
        fail_msg("%s", err.msg);
}

/* The binning conversion (docs/reference.md, Objects and Bins). The box spans x in [0, 10],
 * y in [0, 3], z in [0, L]; the tube's x is the box's x - 5, its y the box's y, and its z (the
 * axis it is invariant along) the box's z. A tube cell is the radiance averaged over a segment
 * (1 mfp of S1 or S2 at segments_top = 10) and a bin of pi / (ntheta nphi) projected solid
 * angle, theta bins uniform in sin^2 theta on both; a box patch cell the same over a patch
 * (2 x 2 voxels of 0.5 mfp: 1 x 1 mfp) and a bin. The phi origins differ (the tube's from x,
 * over [0, pi) folded by its z symmetry; the box patch's from its own tangent, over
 * [0, 2 pi)), so each theta bin is compared averaged over phi (equal solid angles: a plain
 * mean), and the box's is also averaged over its patches in the middle slice z in [z0, z1]
 * (the tube is invariant along z): box cell (S, segment i, theta bin k) = mean over the patches
 * of face S with x in [i, i + 1], z in [z0, z1], and their phi bins, of theta bin k. A face's
 * total is its flux per unit length over the power W E_perp incident per unit length:
 * sum over cells of L x area x pi / nbins / (W (z1 - z0)) on the box, sum of L x segment
 * length x pi / nbins / W on the tube. */
static void test_mc3d_long_box_is_tube(void **state)
{
    (void)state;
    ppb_err err;
    const char *sets[] = {"medium.sigma_t=1",
                          "medium.albedo=0.95",
                          "medium.g=0",
                          "tube.width=10",
                          "tube.height=3",
                          "tube.segments_top=10",
                          "tube.segments_side=3",
                          "light.theta_deg=0",
                          "bins.theta=4",
                          "bins.phi=8",
                          "object.shape=box",
                          "object.grid_x=20",
                          "object.grid_y=6",
                          "object.grid_z=72",
                          "object.voxel=0.5",
                          "object.patch=2",
                          "object.light_theta=0",
                          "object.image_width=4",
                          "object.image_height=4",
                          "mc.batches=16",
                          "mc.photons=3e6",
                          "mc.seed=7"};
    ppb_config cfg;
    load(&cfg, sets, (int)(sizeof sets / sizeof sets[0]));
    ppb_object o;
    ppb_object_patches p;
    ppb_object_result r[2];
    trace(&cfg, &o, &p, r);

    /* The tube's mc, its own photons (a different seed) on the same medium. */
    if (ppb_config_set(&cfg, "mc", "photons", "1e6", &err) ||
        ppb_config_set(&cfg, "mc", "seed", "3", &err))
        fail_msg("%s", err.msg);
    ppb_layout lo = ppb_scene_layout(&cfg.scene);
    ppb_result tr[2]; /* mc and its once-scattered part mc1 (method_mc.h) */
    if (ppb_result_init(&tr[0], "mc", &lo, &err) || ppb_result_init(&tr[1], "mc1", &lo, &err) ||
        ppb_method_mc(&g_ctx, tr, &err))
        fail_msg("%s", err.msg);
    const ppb_result *tube = &tr[0];

    /* The middle slice: 15 mfp from either end (36 mfp long), about 5.8 diffusion lengths
     * 1 / sqrt(3 sigma_a sigma_t') = 2.58 mfp: the light the missing medium beyond the ends
     * would send is of order e^-5.8 / 2 = 0.15 % of the middle's, below the noise here. */
    const double z0 = 15.0, z1 = 21.0, W = 10.0;
    int nb = o.ntheta * o.nphi, nt = o.ntheta;
    double chi2 = 0.0;
    long ncells = 0;
    for (int s = 0; s < 2; s++) { /* S1 (top, +y) and S2 (bottom, -y) */
        double face_box = 0.0, face_box_v = 0.0, face_tube = 0.0, face_tube_v = 0.0;
        for (int seg = 0; seg < 10; seg++)
            for (int k = 0; k < nt; k++) {
                double sum = 0.0, var = 0.0;
                int n = 0;
                for (int i = 0; i < p.npatch; i++) {
                    const ppb_object_patch *pa = &p.patch[i];
                    if (pa->axis != 1 || pa->side != (s == PPB_S1 ? 1 : -1) || pa->c[2] < z0 ||
                        pa->c[2] > z1 || pa->c[0] < seg || pa->c[0] > seg + 1)
                        continue;
                    for (int j = 0; j < o.nphi; j++) {
                        size_t c = (size_t)i * nb + k * o.nphi + j;
                        sum += r[0].patch_rad[c], var += r[0].patch_se[c] * r[0].patch_se[c];
                        double f = pa->area * PPB_PI / nb / (W * (z1 - z0));
                        face_box += r[0].patch_rad[c] * f;
                        face_box_v += r[0].patch_se[c] * r[0].patch_se[c] * f * f;
                        n++;
                    }
                }
                assert_int_equal(n, 6 * o.nphi); /* 6 patches of 1 mfp along z, every phi bin */
                double tb = 0.0, tv = 0.0;
                for (int j = 0; j < cfg.scene.nphi; j++) {
                    size_t c = ppb_cell(&lo, s, seg, k * cfg.scene.nphi + j);
                    tb += tube->radiance[c], tv += tube->se[c] * tube->se[c];
                    double f = 1.0 * PPB_PI / lo.nbins / W;
                    face_tube += tube->radiance[c] * f;
                    face_tube_v += tube->se[c] * tube->se[c] * f * f;
                }
                double xb = sum / n, vb = var / ((double)n * n);
                double xt = tb / cfg.scene.nphi,
                       vt = tv / ((double)cfg.scene.nphi * cfg.scene.nphi);
                chi2 += (xb - xt) * (xb - xt) / (vb + vt);
                ncells++;
            }
        double z = (face_box - face_tube) / sqrt(face_box_v + face_tube_v);
        printf("mc3d's long box vs the tube's mc, %s flux: %.5f +- %.5f vs %.5f +- %.5f (%.2f "
               "sigma)\n",
               s == PPB_S1 ? "R (S1)" : "T (S2)", face_box, sqrt(face_box_v), face_tube,
               sqrt(face_tube_v), z);
        assert_true(fabs(z) < 4.0);
    }
    printf("mc3d's long box vs the tube's mc, S1 and S2, %ld (segment, theta bin) cells: chi2 per "
           "cell %.3f (bound %.3f)\n",
           ncells, chi2 / ncells, chi2_bound(ncells));
    assert_true(chi2 / ncells < chi2_bound(ncells));
    /* The sides: the box's faces x = 0 and x = 10 (axis 0) in the slice against S3 + S4 (3
     * segments of 1 mfp each), as fluxes per unit length over W E_perp. */
    double sb = 0.0, sbv = 0.0, st = 0.0, stv = 0.0;
    for (int i = 0; i < p.npatch; i++) {
        const ppb_object_patch *pa = &p.patch[i];
        if (pa->axis != 0 || pa->c[2] < z0 || pa->c[2] > z1)
            continue;
        double f = pa->area * PPB_PI / nb / (W * (z1 - z0));
        for (int b = 0; b < nb; b++) {
            size_t c = (size_t)i * nb + b;
            sb += r[0].patch_rad[c] * f, sbv += r[0].patch_se[c] * r[0].patch_se[c] * f * f;
        }
    }
    for (int s = PPB_S3; s <= PPB_S4; s++)
        for (int seg = 0; seg < lo.nseg[s]; seg++)
            for (int b = 0; b < lo.nbins; b++) {
                size_t c = ppb_cell(&lo, s, seg, b);
                double f = (3.0 / lo.nseg[s]) * PPB_PI / lo.nbins / W;
                st += tube->radiance[c] * f, stv += tube->se[c] * tube->se[c] * f * f;
            }
    double zs = (sb - st) / sqrt(sbv + stv);
    printf("mc3d's long box vs the tube's mc, sides (S3 + S4) flux: %.5f +- %.5f vs %.5f +- %.5f "
           "(%.2f sigma)\n",
           sb, sqrt(sbv), st, sqrt(stv), zs);
    assert_true(fabs(zs) < 4.0);
    for (int i = 0; i < 2; i++)
        ppb_result_free(&tr[i]);
    for (int i = 0; i < 2; i++)
        ppb_object_result_free(&r[i]);
    ppb_object_patches_free(&p);
    ppb_object_free(&o);
}

/* ss3d against mc3d1 on every patch cell of one object; cells whose batch error is over 30 %
 * of their mean are left out (few photons a batch: their batch means are far from normal, the
 * t statistic does not hold; the cut uses the reference's own noise, not the difference). */
static void ss3d_vs_mc3d1(const char *const *sets, int nsets, const char *what)
{
    ppb_config cfg;
    load(&cfg, sets, nsets);
    ppb_object o;
    ppb_object_patches p;
    ppb_object_result r[2], s;
    trace(&cfg, &o, &p, r);
    ppb_err err;
    int nb = o.ntheta * o.nphi;
    if (ppb_object_result_init(&s, "ss3d", p.npatch, nb, o.img_w, o.img_h, &err) ||
        ppb_object_method_ss3d.run(&g_ctx, &o, &p, &s, &err))
        fail_msg("%s", err.msg);
    double chi2 = 0.0, sum_s = 0.0, sum_m = 0.0, var_m = 0.0;
    long n = 0, ncell = (long)p.npatch * nb;
    for (long c = 0; c < ncell; c++) {
        double m = r[1].patch_rad[c], se = r[1].patch_se[c];
        sum_s += s.patch_rad[c], sum_m += m, var_m += se * se;
        if (!(m > 0.0) || se > 0.3 * m)
            continue;
        chi2 += (s.patch_rad[c] - m) * (s.patch_rad[c] - m) / (se * se);
        n++;
    }
    double z = (sum_s - sum_m) / sqrt(var_m);
    printf("ss3d vs mc3d1, %s: %ld of %ld cells, chi2 per cell %.3f (bound %.3f); sum of cells "
           "%.5f vs %.5f (ratio %.4f, %.2f sigma)\n",
           what, n, ncell, chi2 / n, chi2_bound(n), sum_s, sum_m, sum_s / sum_m, z);
    assert_true(n >= 1000); /* enough cells for the chi-square's bound to bite */
    assert_true(chi2 / n < chi2_bound(n));
    assert_true(fabs(z) < 4.0);
    ppb_object_result_free(&s);
    for (int i = 0; i < 2; i++)
        ppb_object_result_free(&r[i]);
    ppb_object_patches_free(&p);
    ppb_object_free(&o);
}

#define COMMON                                                                                     \
    "bins.theta=4", "bins.phi=8", "object.patch=4", "object.image_width=4",                        \
        "object.image_height=4", "mc.batches=16", "bins.samples_dir=2"

static void test_ss3d_box(void **state)
{
    (void)state;
    const char *sets[] = {"medium.albedo=0.95", "medium.g=0",
                          "object.shape=box",   "object.grid_x=16",
                          "object.grid_y=8",    "object.grid_z=12",
                          "object.voxel=0.5",   "object.light_theta=0",
                          "mc.photons=1e6",     COMMON};
    ss3d_vs_mc3d1(sets, (int)(sizeof sets / sizeof sets[0]), "box 8 x 4 x 6 mfp, light along -y");
}

/* A staircase sphere's faces see the radiance change within a face: ss3d's Latin-square samples
 * (docs/methods.md, pp3d) converge to the area average as samples_dir grows (on an 8-mfp ball
 * of 0.5-mfp voxels, sum of cells over mc3d1's: 1.0208 at 2 x 2 samples, 1.0087 at 4 x 4, both
 * beyond the noise; a 4-mfp ball: 1.0078 at 0.25-mfp voxels, 1.0028 +- 0.0021 at 0.125, both
 * 4 x 4), so this ball has 0.25-mfp voxels and 8 x 8 samples. */
static void test_ss3d_sphere(void **state)
{
    (void)state;
    const char *sets[] = {"medium.albedo=0.95",  "medium.g=0",
                          "object.shape=sphere", "object.grid_x=16",
                          "object.grid_y=16",    "object.grid_z=16",
                          "object.voxel=0.25",   "object.light_theta=30",
                          "mc.photons=1e6",      COMMON,
                          "bins.samples_dir=8"};
    ss3d_vs_mc3d1(sets, (int)(sizeof sets / sizeof sets[0]),
                  "sphere of 4 mfp (16^3), light 30 deg aside, 8 x 8 samples a bin");
}

static void test_ss3d_yokan(void **state)
{
    (void)state;
    const char *sets[] = {"medium.albedo=0.99",
                          "medium.g=0.5",
                          "object.shape=yokan",
                          "object.grid_x=16",
                          "object.grid_y=8",
                          "object.grid_z=12",
                          "object.voxel=0.5",
                          "object.inclusion_radius=0.4",
                          "object.inclusion_sigma_t=4",
                          "object.inclusion_albedo=0.7",
                          "object.light_theta=30",
                          "mc.photons=1e6",
                          COMMON};
    ss3d_vs_mc3d1(sets, (int)(sizeof sets / sizeof sets[0]),
                  "yokan 8 x 4 x 6 mfp with its chestnut, light 30 deg aside");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mc3d_long_box_is_tube),
        cmocka_unit_test(test_ss3d_box),
        cmocka_unit_test(test_ss3d_sphere),
        cmocka_unit_test(test_ss3d_yokan),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
