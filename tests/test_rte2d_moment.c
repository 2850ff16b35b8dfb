/* test_rte2d_moment.c: the first-moment correction of rte2d's cell phase matrix
 * (ppb_rte_moment_fix, methods/rte2d/rte2d_grid.h; `[rte2d] moment`), each check with its
 * source:
 * - analytic: the continuous HG phase function's mean cosine is g (Henyey and Greenstein 1941),
 *   which the corrected matrix must reproduce, sum_i P_ij c_i . c_j averaged over j, to 1e-12;
 *   the uncorrected one falls short (measured 4.1e-3 at g = 0.5, 7.1e-3 at 0.877 on 128 cells),
 *   so the check can fail;
 * - conservation: every row and column of the corrected P sums to 1 (what a cell scatters
 *   lands in some cell; an isotropic field scatters into an isotropic one) to 1e-12, as before
 *   the correction, and S = |Omega| P stays symmetric (reciprocity) to 1e-15;
 * - g < 0 on the antipodal partition (the one rte2d builds there): the same with the mix
 *   toward the antipode. */
#include "testutil.h"

#include "methods/rte2d/rte2d_grid.h"
#include "physics/directions.h"
#include "physics/phase.h"

/* Mean over the columns of sum_i P_ij c_i . c_j. */
static double mean_cosine(const pp_dirs *d, const double *P)
{
    int m = 2 * d->n;
    double s = 0.0;
    for (int j = 0; j < m; j++)
        for (int i = 0; i < m; i++) {
            const double *ci = d->centre + 3 * i, *cj = d->centre + 3 * j;
            s += P[(size_t)i * m + j] * (ci[0] * cj[0] + ci[1] * cj[1] + ci[2] * cj[2]);
        }
    return s / m;
}

static void check(int n, double g)
{
    pp_dirs d;
    ppb_err err;
    if ((g < 0.0 ? pp_dirs_make_antipodal(n, &d, &err) : pp_dirs_make(n, &d, &err)))
        fail_msg("%s", err.msg);
    int m = 2 * n;
    double *P = malloc(sizeof(double) * m * m);
    assert_non_null(P);
    if (pp_phase_matrix(&d, g, P, &err))
        fail_msg("%s", err.msg);
    double before = mean_cosine(&d, P);
    double b = ppb_rte_moment_fix(&d, g, P);
    double after = mean_cosine(&d, P);
    printf("%d cells, g = %g: mean cosine %.6f before, %.15f after (b = %.4g)\n", n, g, before,
           after, b);
    assert_true(fabs(before - g) > 1e-3); /* the blur the correction is for */
    assert_true(b > 0.0 && b < 0.2);
    assert_true(fabs(after - g) <= 1e-12);
    double worst_row = 0.0, worst_col = 0.0, worst_sym = 0.0;
    for (int i = 0; i < m; i++) {
        double r = 0.0, c = 0.0;
        for (int j = 0; j < m; j++) {
            r += P[(size_t)i * m + j];
            c += P[(size_t)j * m + i];
            worst_sym = fmax(worst_sym, fabs(P[(size_t)i * m + j] - P[(size_t)j * m + i]));
        }
        worst_row = fmax(worst_row, fabs(r - 1.0));
        worst_col = fmax(worst_col, fabs(c - 1.0));
    }
    printf("  rows %.2g, columns %.2g from 1, asymmetry %.2g\n", worst_row, worst_col, worst_sym);
    assert_true(worst_row <= 1e-12 && worst_col <= 1e-12);
    assert_true(worst_sym <= 1e-15);
    free(P);
    pp_dirs_free(&d);
}

static void test_moment_forward(void **state)
{
    (void)state;
    check(128, 0.5);
    check(128, 0.877);
    check(32, 0.3);
}

static void test_moment_backward(void **state)
{
    (void)state;
    check(128, -0.5);
}

/* Nothing to correct at g = 0 (P is uniform, its mean cosine 0 by the partition's symmetry). */
static void test_moment_isotropic(void **state)
{
    (void)state;
    pp_dirs d;
    ppb_err err;
    if (pp_dirs_make(32, &d, &err))
        fail_msg("%s", err.msg);
    double *P = malloc(sizeof(double) * 64 * 64);
    assert_non_null(P);
    if (pp_phase_matrix(&d, 0.0, P, &err))
        fail_msg("%s", err.msg);
    assert_true(ppb_rte_moment_fix(&d, 0.0, P) == 0.0);
    free(P);
    pp_dirs_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_moment_forward),
        cmocka_unit_test(test_moment_backward),
        cmocka_unit_test(test_moment_isotropic),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
