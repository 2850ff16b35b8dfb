/* testutil.h: what the cmocka suites share: a scratch directory under $TMPDIR (build/tmp when
 * run by make) and a default scene. Header-only so each suite stays one file. */
#ifndef PPB_TESTUTIL_H
#define PPB_TESTUTIL_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <math.h>

#include "model/scene.h"

/* cmocka's assert_float_equal compares floats; these checks need doubles. */
#define assert_close(a, b, tol)                                                                    \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        if (!(fabs(a_ - b_) <= (tol)))                                                             \
            fail_msg("%s = %.15g, expected %.15g (tol %g)", #a, a_, b_, (double)(tol));            \
    } while (0)

/* A fresh scratch directory for one test, named after it; returns a static buffer. */
static inline const char *tu_scratch(const char *name)
{
    static char dir[1024];
    /* Absolute, so tests that change directory or hand it to a child still find it. */
    char *base = realpath(getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp", NULL);
    snprintf(dir, sizeof dir, "%s/ppbench-%s-%d", base ? base : "/tmp", name, (int)getpid());
    free(base);
    char cmd[2200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", dir, dir);
    if (system(cmd) != 0)
        fail_msg("cannot make %s", dir);
    return dir;
}

/* SPEC.md section 6's defaults: W = 10, H = 3, sigma_t = 1, alpha = 0.95, g = 0, normal light. */
static inline ppb_scene tu_tube(void)
{
    ppb_scene sc = {.geometry = PPB_GEOM_TUBE,
                    .width = 10,
                    .height = 3,
                    .segments_top = 128,
                    .segments_side = 36,
                    .sigma_t = 1,
                    .albedo = 0.95,
                    .g = 0,
                    .step = PPB_STEP_NONE,
                    .step_x = 0,
                    .sigma_t_right = 0.5,
                    .albedo_right = 0.475,
                    .theta_deg = 0,
                    .ntheta = 8,
                    .nphi = 8};
    return sc;
}

static inline ppb_scene tu_slab(double tau0, double albedo, double g, double theta_deg)
{
    ppb_scene sc = tu_tube();
    sc.geometry = PPB_GEOM_SLAB;
    sc.height = tau0;
    sc.albedo = albedo;
    sc.g = g;
    sc.theta_deg = theta_deg;
    return sc;
}

#endif
