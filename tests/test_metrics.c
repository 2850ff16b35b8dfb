/* test_metrics.c: the region metric of src/model/metrics.h (which segments a region holds, and
 * the rms_rel / noise_rel / rms_excess (reference: Metrics) over them, with and without unequal bin
 * weights w_k) and regions.csv as src/io/csv.c writes it. Every expected value is worked out by
 * hand from a tiny synthetic result; the arithmetic is in the comments. */
#include "testutil.h"

#include "io/csv.h"
#include "model/metrics.h"

/* A tube of W = 10 with 8 segments on S1/S2, so the centres are s = -5 + (i + 0.5) * 1.25:
 *   i:  0       1       2       3       4      5      6      7
 *   s: -4.375  -3.125  -1.875  -0.625  0.625  1.875  3.125  4.375   (all exact in binary)
 * and 2 bins per segment (ntheta = 1, nphi = 2). */
static ppb_scene tiny(int step, double step_x)
{
    ppb_scene sc = tu_tube();
    sc.segments_top = 8;
    sc.segments_side = 2;
    sc.ntheta = 1;
    sc.nphi = 2;
    sc.step = step;
    sc.step_x = step_x;
    return sc;
}

/* The segments of one region, as a bit mask over S1's or S2's 8 segments. */
static unsigned region_mask(const ppb_scene *sc, int region, int *surf)
{
    ppb_layout lo = ppb_scene_layout(sc);
    ppb_point pts[8];
    int n = ppb_region_points(sc, &lo, region, pts, 8);
    unsigned mask = 0;
    for (int i = 0; i < n; i++) {
        mask |= 1u << pts[i].seg;
        *surf = pts[i].surf;
    }
    return mask;
}

#define SEGS(...) segs_mask((int[]){__VA_ARGS__, -1})
static unsigned segs_mask(const int *segs)
{
    unsigned m = 0;
    for (int i = 0; segs[i] >= 0; i++)
        m |= 1u << segs[i];
    return m;
}

static void check_region(const ppb_scene *sc, int region, int surf, unsigned want)
{
    int got_surf = -1;
    unsigned got = region_mask(sc, region, &got_surf);
    if (got != want || got_surf != surf)
        fail_msg("%s: segments mask 0x%x on surface %d, expected 0x%x on %d",
                 ppb_region_name(region), got, got_surf, want, surf);
}

/* step_x = 1 (albedo step): x0 - 2 = -1, x0 + 2 = 3, so
 *   x<x0-2: s < -1         -> segments 0, 1, 2
 *   x>x0+2: s > 3          -> 6, 7
 *   |x-x0|<=2: -1 <= s <= 3 -> 3, 4, 5           (the three partition the 8 segments)
 *   x<-W/2+3: s < -2        -> 0, 1
 *   x>W/2-3:  s > 2         -> 6, 7
 * S2's regions are the same segments on S2. */
static void test_region_segments(void **state)
{
    (void)state;
    ppb_scene sc = tiny(PPB_STEP_ALBEDO, 1.0);
    for (int half = 0; half < 2; half++) {
        int surf = half ? PPB_S2 : PPB_S1, r0 = half * PPB_NREGIONS_PER_SURF;
        check_region(&sc, r0 + PPB_REGION_LEFT, surf, SEGS(0, 1, 2));
        check_region(&sc, r0 + PPB_REGION_RIGHT, surf, SEGS(6, 7));
        check_region(&sc, r0 + PPB_REGION_STEP, surf, SEGS(3, 4, 5));
        check_region(&sc, r0 + PPB_REGION_WALL_LEFT, surf, SEGS(0, 1));
        check_region(&sc, r0 + PPB_REGION_WALL_RIGHT, surf, SEGS(6, 7));
    }
    assert_string_equal(ppb_region_name(PPB_REGION_RIGHT), "S1:x>x0+2");
    assert_string_equal(ppb_region_name(PPB_NREGIONS_PER_SURF + PPB_REGION_LEFT), "S2:x<x0-2");
}

/* Without a step x0 = 0 whatever step_x says: x<x0-2 is s < -2 -> 0, 1; |x|<=2 -> 2..5. */
static void test_region_no_step(void **state)
{
    (void)state;
    ppb_scene sc = tiny(PPB_STEP_NONE, 1.0);
    check_region(&sc, PPB_REGION_LEFT, PPB_S1, SEGS(0, 1));
    check_region(&sc, PPB_REGION_STEP, PPB_S1, SEGS(2, 3, 4, 5));
    check_region(&sc, PPB_REGION_RIGHT, PPB_S1, SEGS(6, 7));
}

/* The bounds: step_x = 0.125 puts segment 2 (s = -1.875) exactly at x0 - 2; it belongs to the
 * middle region (inclusive), not to the left one (strict). x0 + 2 = 2.125: right = 6, 7. */
static void test_region_boundary(void **state)
{
    (void)state;
    ppb_scene sc = tiny(PPB_STEP_DENSITY, 0.125);
    check_region(&sc, PPB_REGION_LEFT, PPB_S1, SEGS(0, 1));
    check_region(&sc, PPB_REGION_STEP, PPB_S1, SEGS(2, 3, 4, 5));
    check_region(&sc, PPB_REGION_RIGHT, PPB_S1, SEGS(6, 7));
}

/* Slab mode has no x: every region is empty. */
static void test_region_slab(void **state)
{
    (void)state;
    ppb_scene sc = tu_slab(1.0, 0.9, 0.0, 0.0);
    ppb_layout lo = ppb_scene_layout(&sc);
    ppb_point pts[8];
    for (int r = 0; r < PPB_NREGIONS; r++)
        assert_int_equal(ppb_region_points(&sc, &lo, r, pts, 8), 0);
}

/* Two results on the tiny tube: ref ("mc") L = 1, se = 0.1 everywhere; m ("pp") L = 1, se = 0,
 * except S1 segment 0 bin 0 where m = 2. */
static void make_pair(const ppb_scene *sc, ppb_result rs[2])
{
    ppb_layout lo = ppb_scene_layout(sc);
    ppb_err err;
    if (ppb_result_init(&rs[0], "mc", &lo, &err) || ppb_result_init(&rs[1], "pp", &lo, &err))
        fail_msg("%s", err.msg);
    for (size_t c = 0; c < lo.ncells; c++) {
        rs[0].radiance[c] = 1.0;
        rs[0].se[c] = 0.1;
        rs[1].radiance[c] = 1.0;
    }
    rs[1].radiance[ppb_cell(&lo, PPB_S1, 0, 0)] = 2.0;
}

/* Over a region, with equal bins (by hand; n cells, each L_r = 1, se = 0.1, one d = 1):
 *   x<x0-2 (segments 0-2, 6 cells): rms = sqrt(1/6) = 0.408248, noise = sqrt(6 * 0.01 / 6) = 0.1,
 *     excess = sqrt(1/6 - 0.01) = 0.395811;
 *   x<-W/2+3 (segments 0-1, 4 cells): rms = sqrt(1/4) = 0.5, excess = sqrt(0.24) = 0.489898;
 *   x>x0+2 (segments 6-7): rms = 0, excess = sqrt(max(0, 0 - 0.01)) = 0. */
static void test_region_rms(void **state)
{
    (void)state;
    ppb_scene sc = tiny(PPB_STEP_ALBEDO, 1.0);
    ppb_result rs[2];
    make_pair(&sc, rs);
    ppb_point pts[8];
    int n = ppb_region_points(&sc, &rs[0].layout, PPB_REGION_LEFT, pts, 8);
    ppb_rms e = ppb_rms_points(&rs[1], &rs[0], pts, n);
    assert_close(e.rms_rel, sqrt(1.0 / 6.0), 1e-15);
    assert_close(e.noise_rel, 0.1, 1e-15);
    assert_close(e.rms_excess, sqrt(1.0 / 6.0 - 0.01), 1e-15);
    n = ppb_region_points(&sc, &rs[0].layout, PPB_REGION_WALL_LEFT, pts, 8);
    e = ppb_rms_points(&rs[1], &rs[0], pts, n);
    assert_close(e.rms_rel, 0.5, 1e-15);
    assert_close(e.rms_excess, sqrt(0.24), 1e-15);
    n = ppb_region_points(&sc, &rs[0].layout, PPB_REGION_RIGHT, pts, 8);
    e = ppb_rms_points(&rs[1], &rs[0], pts, n);
    assert_close(e.rms_rel, 0.0, 0.0);
    assert_close(e.rms_excess, 0.0, 0.0);
    ppb_result_free(&rs[0]);
    ppb_result_free(&rs[1]);
}

/* Unequal w_k (reference: Metrics). Points A = (S1, 3), B = (S1, 4), bins 0 and 1:
 *   L_r: A (1, 2), B (2, 1);  L_m: A (1.5, 2), B (2, 0);  se_r: A (0.1, 0.3), B (0.2, 0.1).
 *   d = L_m - L_r: A (0.5, 0), B (0, -1).
 * With w = (1, 3):
 *   num   = 1 * (0.25 + 0) + 3 * (0 + 1)          = 3.25
 *   den   = 1 * (1 + 4) + 3 * (4 + 1)              = 20
 *   noise = 1 * (0.01 + 0.04) + 3 * (0.09 + 0.01) = 0.35
 *   rms_rel = sqrt(0.1625), noise_rel = sqrt(0.0175), excess = sqrt(0.145).
 * Equal bins (w = NULL, or any constant w such as (2, 2), which cancels):
 *   num = 1.25, den = 10, noise = 0.15: rms = sqrt(0.125), noise = sqrt(0.015),
 *   excess = sqrt(0.11). The weighted and unweighted values differ, so ignoring w_k fails. */
static void test_weights(void **state)
{
    (void)state;
    ppb_scene sc = tiny(PPB_STEP_NONE, 0.0);
    ppb_result rs[2];
    make_pair(&sc, rs);
    const ppb_layout *lo = &rs[0].layout;
    ppb_point pts[2] = {{PPB_S1, 3}, {PPB_S1, 4}};
    const double lr[2][2] = {{1, 2}, {2, 1}}, lm[2][2] = {{1.5, 2}, {2, 0}};
    const double se[2][2] = {{0.1, 0.3}, {0.2, 0.1}};
    for (int p = 0; p < 2; p++)
        for (int k = 0; k < 2; k++) {
            size_t c = ppb_cell(lo, pts[p].surf, pts[p].seg, k);
            rs[0].radiance[c] = lr[p][k];
            rs[0].se[c] = se[p][k];
            rs[1].radiance[c] = lm[p][k];
        }
    const double w[2] = {1, 3}, w2[2] = {2, 2};
    ppb_rms e = ppb_rms_points_w(&rs[1], &rs[0], pts, 2, w);
    assert_close(e.rms_rel, sqrt(0.1625), 1e-15);
    assert_close(e.noise_rel, sqrt(0.0175), 1e-15);
    assert_close(e.rms_excess, sqrt(0.145), 1e-15);
    ppb_rms u = ppb_rms_points(&rs[1], &rs[0], pts, 2);
    assert_close(u.rms_rel, sqrt(0.125), 1e-15);
    assert_close(u.noise_rel, sqrt(0.015), 1e-15);
    assert_close(u.rms_excess, sqrt(0.11), 1e-15);
    ppb_rms c = ppb_rms_points_w(&rs[1], &rs[0], pts, 2, w2);
    assert_close(c.rms_rel, u.rms_rel, 1e-15);
    assert_close(c.noise_rel, u.noise_rel, 1e-15);
    assert_close(c.rms_excess, u.rms_excess, 1e-15);
    ppb_result_free(&rs[0]);
    ppb_result_free(&rs[1]);
}

/* regions.csv: the header, one row per (measured method, region) in ppb_region_name order, the
 * reference left out, and the values of test_region_rms printed with %.6g. */
static void test_regions_csv(void **state)
{
    (void)state;
    ppb_scene sc = tiny(PPB_STEP_ALBEDO, 1.0);
    ppb_result rs[2];
    make_pair(&sc, rs);
    char path[1200];
    snprintf(path, sizeof path, "%s/regions.csv", tu_scratch("regions_csv"));
    ppb_err err;
    if (ppb_write_regions_csv(path, &sc, rs, 2, &rs[0], NULL, &err))
        fail_msg("%s", err.msg);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[256];
    assert_non_null(fgets(line, sizeof line, f));
    assert_string_equal(line, "method,region,rms_rel,noise_rel,rms_excess\n");
    int rows = 0;
    while (fgets(line, sizeof line, f)) {
        char method[32], region[32];
        double rms, noise, excess;
        if (sscanf(line, "%31[^,],%31[^,],%lf,%lf,%lf", method, region, &rms, &noise, &excess) != 5)
            fail_msg("bad row: %s", line);
        assert_string_equal(method, "pp");
        assert_string_equal(region, ppb_region_name(rows));
        assert_close(noise, 0.1, 1e-6);
        if (rows == PPB_REGION_LEFT) {
            assert_close(rms, 0.408248, 1e-6);
            assert_close(excess, 0.395811, 1e-6);
        } else if (rows == PPB_REGION_WALL_LEFT) {
            assert_close(rms, 0.5, 1e-6);
            assert_close(excess, 0.489898, 1e-6);
        } else {
            /* Every other region misses the one differing cell (S1 segment 0). */
            assert_close(rms, 0.0, 0.0);
            assert_close(excess, 0.0, 0.0);
        }
        rows++;
    }
    fclose(f);
    assert_int_equal(rows, PPB_NREGIONS);
    ppb_result_free(&rs[0]);
    ppb_result_free(&rs[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_region_segments), cmocka_unit_test(test_region_no_step),
        cmocka_unit_test(test_region_boundary), cmocka_unit_test(test_region_slab),
        cmocka_unit_test(test_region_rms),      cmocka_unit_test(test_weights),
        cmocka_unit_test(test_regions_csv),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
