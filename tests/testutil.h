/* testutil.h: what the cmocka suites share: double comparisons that print both values, the
 * chi-square tail, a scratch directory under $TMPDIR (build/tmp when run by make) and a default
 * scene. Header-only so each suite stays one file. */
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
#include <sys/wait.h>
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

/* |a - b| <= rtol |b|: a relative tolerance; prints both values and the relative difference. */
#define assert_rel(a, b, rtol)                                                                     \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        if (!(fabs(a_ - b_) <= (rtol)*fabs(b_)))                                                   \
            fail_msg("%s = %.15g, expected %.15g (relative difference %.3g, tol %g)", #a, a_, b_,  \
                     b_ != 0 ? fabs(a_ - b_) / fabs(b_) : INFINITY, (double)(rtol));               \
    } while (0)

/* Orderings of doubles that print both sides on failure. */
#define assert_lt(a, b)                                                                            \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        if (!(a_ < b_))                                                                            \
            fail_msg("expected %s < %s: %.15g vs %.15g", #a, #b, a_, b_);                          \
    } while (0)
#define assert_le(a, b)                                                                            \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        if (!(a_ <= b_))                                                                           \
            fail_msg("expected %s <= %s: %.15g vs %.15g", #a, #b, a_, b_);                         \
    } while (0)
/* lo <= x <= hi */
#define assert_between(x, lo, hi)                                                                  \
    do {                                                                                           \
        double x_ = (x), lo_ = (lo), hi_ = (hi);                                                   \
        if (!(x_ >= lo_ && x_ <= hi_))                                                             \
            fail_msg("%s = %.15g, expected in [%.15g, %.15g]", #x, x_, lo_, hi_);                  \
    } while (0)

/* Upper tail P(X >= chi2) of a chi-square variable with dof degrees of freedom: the regularized
 * upper incomplete gamma function Q(dof/2, chi2/2), by its power series below a + 1 and its
 * continued fraction (modified Lentz) above (Numerical Recipes, 3rd ed., section 6.2). For two
 * degrees of freedom it is exp(-chi2/2) exactly; for 49 it agrees with the Wilson-Hilferty
 * approximation to 6 % of p at p = 4e-5. */
static inline double tu_chi2_pvalue(double chi2, int dof)
{
    double a = 0.5 * dof, x = 0.5 * chi2;
    if (x <= 0)
        return 1.0;
    double front = exp(-x + a * log(x) - lgamma(a));
    if (x < a + 1) { /* P(a, x) = front / a * (1 + x/(a+1) + x^2/((a+1)(a+2)) + ...) */
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < 10000 && term > 1e-17 * sum; n++)
            sum += term *= x / (a + n);
        return 1.0 - front * sum;
    }
    double b = x + 1 - a, c = 1e300, d = 1.0 / b, h = d; /* Q = front / (x + 1 - a - ...) */
    for (int i = 1; i < 10000; i++) {
        double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        d = fabs(d) < 1e-300 ? 1e-300 : d;
        c = b + an / c;
        c = fabs(c) < 1e-300 ? 1e-300 : c;
        d = 1.0 / d;
        h *= d * c;
        if (fabs(d * c - 1) < 1e-16)
            break;
    }
    return front * h;
}

/* Gauss-Legendre nodes x and weights w of order n (n <= 1000) on [a, b]: Newton on the
 * three-term recurrence of P_n from Tricomi's initial guesses. The tests' own rule, kept apart
 * from the project's generator (base/quadrature.h) that they check. */
static inline void tu_gauss_legendre(int n, double a, double b, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = cos(3.14159265358979323846 * (i + 0.75) / (n + 0.5)), dp = 1;
        for (int it = 0; it < 100; it++) {
            double p0 = 1, p1 = z;
            for (int k = 2; k <= n; k++) {
                double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                p0 = p1, p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1);
            double dz = p1 / dp;
            z -= dz;
            if (fabs(dz) < 1e-16)
                break;
        }
        x[i] = 0.5 * (a + b) + 0.5 * (b - a) * z;
        w[i] = (b - a) / ((1 - z * z) * dp * dp); /* 2 / ((1 - z^2) P_n'(z)^2), scaled */
    }
}

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

/* The binary under test: $PPBENCH (make sets it), else ./ppbench. */
static inline const char *tu_bin(void)
{
    const char *b = getenv("PPBENCH");
    return b ? b : "./ppbench";
}

/* A shell command built like printf; its exit code, -1 when it did not exit. */
static inline int tu_sh(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline int tu_sh(const char *fmt, ...)
{
    char cmd[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static inline void tu_write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f)
        fail_msg("cannot write %s", path);
    fputs(text, f);
    fclose(f);
}

/* The first 64 KiB of a file ("" when it cannot be read); a static buffer. */
static inline char *tu_read_text(const char *path)
{
    static char buf[1 << 16];
    buf[0] = '\0';
    FILE *f = fopen(path, "r");
    if (f) {
        size_t n = fread(buf, 1, sizeof buf - 1, f);
        buf[n] = '\0';
        fclose(f);
    }
    return buf;
}

/* Writes text to <scratch dir of name>/<name>.ini; returns its path (a static buffer). */
static inline const char *tu_config(const char *name, const char *text)
{
    static char path[1200];
    snprintf(path, sizeof path, "%s/%s.ini", tu_scratch(name), name);
    tu_write_file(path, text);
    return path;
}

/* The study's defaults (reference: Cases): W = 10, H = 3, sigma_t = 1, alpha = 0.95, g = 0, normal
 * light. */
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
