/* test_mc3d.c: the object Monte Carlo (methods/mc3d; docs/methods.md, mc3d). Expected values:
 * conservation of energy (every photon that reaches the medium is escaped or absorbed), the
 * image estimator against the same run's patch tallies (two estimators of one radiance), the
 * plane-parallel slab's reflectance from the project's slab solver (physics/ppsolver, an
 * independent method), and the once-scattered reflectance of a half-space in closed form. */
#include "testutil.h"

#include "methods/mc3d/method_mc3d.h"
#include "kernels/ppb_object.h"
#include "model/object_build.h"
#include "physics/ppsolver.h"

typedef struct fixture {
    ppb_config cfg;
    ppb_run_ctx ctx;
    ppb_object o;
    ppb_object_patches p;
    ppb_object_result r[2];
    ppb_mc3d_totals t;
} fixture;

static fixture F;

static int setup(void **state)
{
    (void)state;
    memset(&F, 0, sizeof F);
    F.ctx.quiet = 2;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    ppb_ctx_close(&F.ctx);
    return 0;
}

/* Loads the defaults with sets[] ("section.key=value"), builds the object and traces it. */
/* Changes the built object before it is traced (NULL: none). */
static void (*edit_object)(ppb_object *o);

static void run(const char *const *sets, int nsets)
{
    ppb_err err;
    if (ppb_config_defaults(&F.cfg, &err))
        fail_msg("%s", err.msg);
    for (int i = 0; i < nsets; i++) {
        char sec[64], key[64], val[256];
        if (sscanf(sets[i], "%63[^.].%63[^=]=%255[^\n]", sec, key, val) != 3)
            fail_msg("bad set %s", sets[i]);
        if (ppb_config_set(&F.cfg, sec, key, val, &err))
            fail_msg("%s", err.msg);
    }
    F.ctx.cfg = &F.cfg;
    if (ppb_object_build(&F.cfg, &F.o, &err))
        fail_msg("%s", err.msg);
    if (edit_object)
        edit_object(&F.o);
    if (ppb_object_patches_build(&F.o, &F.p, &err))
        fail_msg("%s", err.msg);
    int nb = F.o.ntheta * F.o.nphi;
    for (int i = 0; i < 2; i++)
        if (ppb_object_result_init(&F.r[i], i ? "mc3d1" : "mc3d", F.p.npatch, nb, F.o.img_w,
                                   F.o.img_h, &err))
            fail_msg("%s", err.msg);
    if (ppb_mc3d_trace(&F.ctx, &F.o, &F.p, F.r, &F.t, &err))
        fail_msg("%s", err.msg);
}

static void done(void)
{
    for (int i = 0; i < 2; i++)
        ppb_object_result_free(&F.r[i]);
    ppb_object_patches_free(&F.p);
    ppb_object_free(&F.o);
}

/* Energy: escaped + absorbed + roulette's loss - its gain is every hit photon's weight 1 (to the
 * fixed-point rounding, 2^-33 per addition), and escaped + absorbed is 1 within the roulette's
 * noise; a sphere lit obliquely, g = 0.5, albedo 0.9. */
static void test_energy(void **state)
{
    (void)state;
    const char *sets[] = {"object.shape=sphere", "object.grid_x=16",      "object.grid_y=16",
                          "object.grid_z=16",    "object.voxel=0.25",     "medium.albedo=0.9",
                          "medium.g=0.5",        "object.light_theta=30", "mc.photons=400000",
                          "mc.batches=8"};
    run(sets, 10);
    printf("energy: hits %lld of %lld, escaped %.6f (ballistic %.6f), absorbed %.6f, rgain %.3g, "
           "rloss %.3g, events %lld, %.3f s (%.3g events/s)\n",
           F.t.hits, F.t.launched, F.t.escaped, F.t.ballistic, F.t.absorbed, F.t.rgain, F.t.rloss,
           F.t.events, F.r[0].seconds, F.t.events / F.r[0].seconds);
    assert_true(F.t.hits > 0 && F.t.hits <= F.t.launched);
    assert_close(F.t.escaped + F.t.absorbed + F.t.rloss - F.t.rgain, 1.0, 1e-9);
    double se = hypot(F.t.escaped_se, F.t.absorbed_se);
    assert_close(F.t.escaped + F.t.absorbed, 1.0, 4 * se + 1e-12);
    done();
}

/* The photons that reach the medium: a box of a x b x c lit along L receives the flux of its
 * projection across L, sum over axes |L_axis| x the face area normal to it, out of the entry
 * area the photons are spread over (a binomial fraction). */
static void test_hits(void **state)
{
    (void)state;
    const char *sets[] = {"object.grid_x=16",    "object.grid_y=8",   "object.grid_z=12",
                          "object.voxel=0.25",   "medium.albedo=0.5", "object.light_theta=30",
                          "object.light_phi=20", "mc.photons=200000", "mc.batches=8"};
    run(sets, 9);
    double a = 4, b = 2, c = 3, L[3];
    ppb_obj_dir(30, 20, L);
    double proj = fabs(L[0]) * b * c + fabs(L[1]) * a * c + fabs(L[2]) * a * b;
    double expect = proj / F.t.proj_area, frac = (double)F.t.hits / F.t.launched;
    assert_close(frac, expect, 4 * sqrt(expect * (1 - expect) / F.t.launched));
    assert_close(F.t.escaped + F.t.absorbed + F.t.rloss - F.t.rgain, 1.0, 1e-9);
    done();
}

/* The slab-like box: 24 x 1 x 24 mfp (voxels of 0.5), albedo 0.9, g = 0, lit along -y on its
 * top face; its middle 8 x 8 mfp, 8 mfp from every edge, is the plane-parallel slab's (a
 * grazing path to the edge has transmittance e^-8 = 3e-4). */
static const char *slab_sets[] = {
    "object.grid_x=48",      "object.grid_y=2",        "object.grid_z=48",
    "object.voxel=0.5",      "medium.albedo=0.9",      "medium.g=0",
    "object.patch=16",       "bins.theta=8",           "bins.phi=1",
    "object.image_width=12", "object.image_height=12", "mc.photons=600000",
    "mc.batches=16",         "object.light_theta=0",   "object.camera_theta=0",
    "object.camera_phi=0"};
enum { NSLAB = sizeof slab_sets / sizeof slab_sets[0] };

/* The middle top patch: axis y, side +1, centroid at (12, 1, 12). */
static int middle_patch(void)
{
    for (int i = 0; i < F.p.npatch; i++) {
        const ppb_object_patch *pa = &F.p.patch[i];
        if (pa->axis == 1 && pa->side == 1 && fabs(pa->c[0] - 12) < 1e-9 &&
            fabs(pa->c[2] - 12) < 1e-9)
            return i;
    }
    fail_msg("no middle patch");
    return -1;
}

/* Mean and standard error of the image over the pixels whose view ray meets the top face
 * (y = top) within the middle 8 x 8 mfp (their centres). */
static void middle_pixels(const ppb_object_result *r, double *mean, double *se, double top)
{
    double c[3] = {-F.o.view_dir[0], -F.o.view_dir[1], -F.o.view_dir[2]};
    ppb_obj_camera cam = ppb_obj_camera_make(c, 24, top, 24, F.o.img_w, F.o.img_h);
    double s = 0, v = 0;
    int n = 0;
    for (int row = 0; row < F.o.img_h; row++)
        for (int col = 0; col < F.o.img_w; col++) {
            double pr = cam.r0 + (col + 0.5) * cam.pixel, pu = cam.u1 - (row + 0.5) * cam.pixel;
            double x[3];
            for (int k = 0; k < 3; k++)
                x[k] = pr * cam.r[k] + pu * cam.u[k];
            double t = (top - x[1]) / c[1]; /* along c to the top face, y = top */
            double px = x[0] + t * c[0], pz = x[2] + t * c[2];
            if (fabs(px - 12) < 4 && fabs(pz - 12) < 4) {
                size_t q = (size_t)row * F.o.img_w + col;
                s += r->img[q], v += r->img_se[q], n++;
            }
        }
    assert_true(n >= 4);
    *mean = s / n;
    /* The pixels' errors are correlated (one photon feeds many), so the mean's standard error
     * is bounded by the mean of theirs (the standard deviation of a sum is at most the sum of
     * the standard deviations), not their root sum of squares over n. */
    *se = v / n;
}

/* Once-scattered reflected radiance of a slab of optical thickness tau0 lit normally, g = 0,
 * leaving at cosine mu (Chandrasekhar 1960, single scattering; per unit E_perp):
 * L1 = albedo / (4 pi) 1 / (1 + mu) (1 - exp(-tau0 (1 + 1 / mu))). */
static double ss_slab(double albedo, double tau0, double mu)
{
    return albedo / (4 * PPB_PI) / (1 + mu) * (1 - exp(-tau0 * (1 + 1 / mu)));
}

/* The slab: the middle patch's reflectance against the plane-parallel solver's R (physics/
 * ppsolver, 200 cells a hemisphere, within 2e-3 of adding-doubling there: tests/test_ppsolver.c);
 * the image at the normal against the solver's radiance; the image against the patch's own
 * theta bins extrapolated to the normal (linear in sin^2 theta over bins 0 and 1: the bins are
 * uniform in sin^2 theta); the once-scattered part against the closed form, per theta bin (its
 * average over the bin by a 400-node midpoint rule in sin^2 theta) and in the image. */
static void test_slab(void **state)
{
    (void)state;
    run(slab_sets, NSLAB);
    int q = middle_patch(), nt = F.o.ntheta;
    double omega = PPB_PI / nt, R = 0, Rv = 0;
    for (int b = 0; b < nt; b++) {
        size_t c = (size_t)q * nt + b;
        R += F.r[0].patch_rad[c] * omega, Rv += pow(F.r[0].patch_se[c] * omega, 2);
    }
    pp_params pp = {.tau0 = 1, .albedo = 0.9, .g = 0, .mu0 = 1, .directions = 200};
    pp_solution *s;
    ppb_err err;
    if (pp_solve(&pp, &s, &err))
        fail_msg("%s", err.msg);
    double Rpp, Tpp, bal, up[3] = {0, 1, 0};
    pp_totals(s, &Rpp, &Tpp, &bal);
    double Lpp = pp_radiance(s, 0, up);
    pp_free(s);
    printf("slab: R mc3d %.5f +- %.5f, pp %.5f; events %lld in %.2f s\n", R, sqrt(Rv), Rpp,
           F.t.events, F.r[0].seconds);
    assert_close(R, Rpp, 4 * sqrt(Rv) + 2e-3 * Rpp);
    double img, img_se;
    middle_pixels(&F.r[0], &img, &img_se, 1);
    size_t c0 = (size_t)q * nt, c1 = c0 + 1;
    double ext = 1.5 * F.r[0].patch_rad[c0] - 0.5 * F.r[0].patch_rad[c1];
    double ext_se = hypot(1.5 * F.r[0].patch_se[c0], 0.5 * F.r[0].patch_se[c1]);
    printf("slab: image at the normal %.5f +- %.5f, pp %.5f, patch bins extrapolated %.5f +- "
           "%.5f\n",
           img, img_se, Lpp, ext, ext_se);
    assert_close(img, Lpp, 4 * img_se + 2e-3 * Lpp);
    assert_close(img, ext, 4 * hypot(img_se, ext_se));
    /* Once scattered, per bin. */
    for (int b = 0; b < nt; b++) {
        double avg = 0;
        for (int k = 0; k < 400; k++) {
            double s2 = (b + (k + 0.5) / 400.0) / nt;
            avg += ss_slab(0.9, 1, sqrt(1 - s2)) / 400.0;
        }
        size_t c = (size_t)q * nt + b;
        assert_close(F.r[1].patch_rad[c], avg, 4 * F.r[1].patch_se[c] + 1e-12);
    }
    middle_pixels(&F.r[1], &img, &img_se, 1);
    printf("slab: once-scattered image %.6f +- %.6f, closed form %.6f\n", img, img_se,
           ss_slab(0.9, 1, 1));
    assert_close(img, ss_slab(0.9, 1, 1), 4 * img_se);
    done();
}

/* The same slab lit at 30 degrees (travelling toward +x, as the tube's light and the slab
 * solver's beam) and seen from 50 degrees on the far side, g = 0.5: the image (its
 * projection and pixel area at an oblique view) against the solver's radiance in the camera's
 * direction (334 cells; the cells' first-moment loss at g = 0.5 is 0.3 %: ppsolver.h, delta-M,
 * hence 5e-3 allowed), its once-scattered part against the closed form
 * L1 = albedo p(w_L . c) mu0 / (mu0 + mu) (1 - exp(-tau0 (1 / mu0 + 1 / mu))). */
static void test_slab_oblique(void **state)
{
    (void)state;
    const char *sets[NSLAB + 4];
    for (int i = 0; i < NSLAB; i++)
        sets[i] = slab_sets[i];
    sets[NSLAB] = "object.light_theta=30", sets[NSLAB + 1] = "object.light_phi=180";
    sets[NSLAB + 2] = "object.camera_theta=50", sets[NSLAB + 3] = "medium.g=0.5";
    run(sets, NSLAB + 4);
    double c[3], mu0 = cos(30 * PPB_PI / 180), mu = cos(50 * PPB_PI / 180);
    ppb_obj_dir(50, 0, c);
    pp_params pp = {.tau0 = 1, .albedo = 0.9, .g = 0.5, .mu0 = mu0, .directions = 334};
    pp_solution *s;
    ppb_err err;
    if (pp_solve(&pp, &s, &err))
        fail_msg("%s", err.msg);
    double Lpp = pp_radiance(s, 0, c);
    pp_free(s);
    double img, img_se;
    middle_pixels(&F.r[0], &img, &img_se, 1);
    printf("oblique slab: image %.5f +- %.5f, pp %.5f\n", img, img_se, Lpp);
    assert_close(img, Lpp, 4 * img_se + 5e-3 * Lpp);
    double cosang = F.o.light_dir[0] * c[0] + F.o.light_dir[1] * c[1] + F.o.light_dir[2] * c[2];
    double L1 = 0.9 * ppb_hg_phase(0.5, cosang) * mu0 / (mu0 + mu) * (1 - exp(-(1 / mu0 + 1 / mu)));
    middle_pixels(&F.r[1], &img, &img_se, 1);
    printf("oblique slab: once-scattered image %.6f +- %.6f, closed form %.6f\n", img, img_se, L1);
    assert_close(img, L1, 4 * img_se);
    done();
}

/* The lower half of the slab box (y < 1 of its 2 mfp) made a second material, sigma_t 3,
 * albedo 0.5. */
static void two_layers(ppb_object *o)
{
    o->nmat = 2;
    o->material[2].sigma_t = 3, o->material[2].albedo = 0.5;
    for (int k = 0; k < o->nz; k++)
        for (int j = 0; j < o->ny / 2; j++)
            for (int i = 0; i < o->nx; i++)
                o->mat[ppb_object_voxel(o, i, j, k)] = 2;
}

/* Two layers (the exact traversal across a change of sigma_t): 1 mfp of optical depth t1 = 1 at
 * albedo a1 = 0.9 over 1 mfp of sigma_t 3 (t2 = 3) at albedo a2 = 0.5, lit and seen at 30 and
 * 50 degrees, g = 0.5. Its
 * once-scattered radiance in closed form, the layers' single scattering each attenuated by
 * what lies above: with k = 1 / mu0 + 1 / mu, P = p(w_L . c) mu0 / (mu0 + mu),
 * L1 = P [a1 (1 - exp(-t1 k)) + a2 exp(-t1 k) (1 - exp(-t2 k))]. */
static void test_two_layers(void **state)
{
    (void)state;
    const char *sets[NSLAB + 5];
    for (int i = 0; i < NSLAB; i++)
        sets[i] = slab_sets[i];
    sets[NSLAB] = "object.light_theta=30", sets[NSLAB + 1] = "object.light_phi=180";
    sets[NSLAB + 2] = "object.camera_theta=50", sets[NSLAB + 3] = "medium.g=0.5";
    sets[NSLAB + 4] = "object.grid_y=4";
    edit_object = two_layers;
    run(sets, NSLAB + 5);
    edit_object = NULL;
    double c[3] = {-F.o.view_dir[0], -F.o.view_dir[1], -F.o.view_dir[2]};
    double mu0 = -F.o.light_dir[1], mu = c[1], k = 1 / mu0 + 1 / mu;
    double cosang = F.o.light_dir[0] * c[0] + F.o.light_dir[1] * c[1] + F.o.light_dir[2] * c[2];
    double P = ppb_hg_phase(0.5, cosang) * mu0 / (mu0 + mu);
    double L1 = P * (0.9 * (1 - exp(-1 * k)) + 0.5 * exp(-1 * k) * (1 - exp(-3 * k)));
    double img, img_se;
    middle_pixels(&F.r[1], &img, &img_se, 2);
    printf("two layers: once-scattered image %.6f +- %.6f, closed form %.6f\n", img, img_se, L1);
    assert_close(img, L1, 4 * img_se);
    done();
}

/* The same photons give the same bytes whatever the work-group size and the photons per launch
 * (integer tallies, a photon's path a function of the seed and its index alone). */
static void test_reproducible(void **state)
{
    (void)state;
    const char *sets[] = {"object.shape=yokan",    "object.grid_x=10",       "object.grid_y=10",
                          "object.grid_z=10",      "mc.photons=20000",       "mc.batches=4",
                          "object.image_width=16", "object.image_height=16", NULL};
    run(sets, 8);
    size_t nc = (size_t)F.p.npatch * F.o.ntheta * F.o.nphi, np = 16 * 16;
    double *a = malloc(nc * sizeof *a), *b = malloc(np * sizeof *b);
    memcpy(a, F.r[0].patch_rad, nc * sizeof *a);
    memcpy(b, F.r[0].img, np * sizeof *b);
    ppb_mc3d_totals t0 = F.t;
    done();
    sets[8] = "mc.chunk=777";
    const char *more[10];
    memcpy(more, sets, sizeof sets);
    more[9] = "mc.workgroup=4";
    run(more, 10);
    assert_memory_equal(a, F.r[0].patch_rad, nc * sizeof *a);
    assert_memory_equal(b, F.r[0].img, np * sizeof *b);
    assert_true(t0.events == F.t.events && t0.escaped == F.t.escaped);
    free(a), free(b);
    done();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_energy),     cmocka_unit_test(test_hits),
        cmocka_unit_test(test_slab),       cmocka_unit_test(test_slab_oblique),
        cmocka_unit_test(test_two_layers), cmocka_unit_test(test_reproducible),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
