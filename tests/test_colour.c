/* test_colour.c: a colour run (`[medium] channel = rgb`, docs/reference.md: Colour) of every
 * method on a material case, against independent runs: each channel's results equal, bit for
 * bit, those of the same config run with channel = r, g or b (a separate experiment with its
 * own context), except a method that traces the channels together (its run_channels: the
 * Monte Carlo), whose results equal that hook's called here on the three grey configs (the
 * runner's plumbing; that they agree with the grey runs within noise is test_mc_rgb's); the
 * luminance subset is the BT.709 weighted sum of those expected results, and its metrics are
 * the metrics of that sum (computed here); no NaN; the Monte Carlo conserves energy in every
 * channel and in the luminance: exactly (to the tallies' fixed point) in a grey run, within
 * its noise when the channels are traced together. The
 * written set: one grey set per channel and y, summary.csv with its channel column, the colour
 * pictures read back. The refusals: a channel outside a key's range, rgb without a material, rgb in
 * a sweep, a run into the committed materials study. */
#include "testutil.h"

#include <sys/stat.h>

#include "base/file_read.h"
#include "drivers/experiment.h"
#include "io/image_exr.h"
#include "io/image_png.h"
#include "methods/registry.h"
#include "model/metrics.h"

/* Every method of the study on skin1 (albedo 0.96 / 0.84 / 0.68 per mm, n = 1.3) in a tube of
 * 3 x 1 mm, about 3 x 1 mean free paths: small settings, so that four runs of every method
 * take seconds. */
static const char case_text[] =
    "[experiment]\nname = colour_case\nunit = mm\nmethods = mc, pp, ss, mp, mp+ss, burley, "
    "burley+ss, bdipole, bdipole+ss, dirpole, dirpole+ss, pbd, rte2d\n"
    "[tube]\nwidth = 3\nheight = 1\nsegments_top = 16\nsegments_side = 6\n"
    "[medium]\nmaterial = skin1\nchannel = rgb\n"
    "[bins]\ntheta = 4\nphi = 4\nsamples_dir = 1\nsamples_seg = 2\n"
    "[mc]\nphotons = 200000\nbatches = 4\n"
    "[pp]\ndirections = 32\n[burley]\ndirections = 32\n"
    "[dirpole]\nsamples = 4\n[pbd]\nnodes = 3\n"
    "[rte2d]\nspacing = 0.1\ndirections = 16\n";

static ppb_config cfg, grey_cfg[3];
static ppb_experiment colour, grey[3];
/* The results of the methods with run_channels, from that hook on grey_cfg: joint[c][k]. */
static ppb_result joint[3][PPB_MAX_RESULTS];
static int njoint;

static void compute(ppb_experiment *ex, const ppb_config *c)
{
    ppb_run_ctx ctx = {.quiet = 2};
    ppb_err err;
    if (ppb_experiment_compute(ex, c, &ctx, &err))
        fail_msg("%s: %s", c->name, err.msg);
    ppb_ctx_close(&ctx);
}

/* Every method of the config that has run_channels, called on the three grey configs. */
static int run_joint(ppb_err *err)
{
    for (int i = 0; i < cfg.nmethods; i++) {
        const ppb_method *m = ppb_method_find(&cfg, cfg.methods[i]);
        if (!m || !m->run_channels)
            continue;
        int nout = m->also ? 2 : 1;
        ppb_result all[6];
        memset(all, 0, sizeof all);
        for (int c = 0; c < 3; c++) {
            ppb_layout lo = ppb_scene_layout(&grey_cfg[c].scene);
            if (ppb_result_init(&all[2 * c], m->id, &lo, err) ||
                (m->also && ppb_result_init(&all[2 * c + 1], m->also, &lo, err)))
                return -1;
        }
        ppb_run_ctx ctx = {.quiet = 2, .cfg = &grey_cfg[0], .self = m};
        int rc = m->run_channels(&ctx, grey_cfg, 3, all, err);
        ppb_ctx_close(&ctx);
        if (rc)
            return -1;
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < nout; k++)
                joint[c][njoint + k] = all[2 * c + k];
        njoint += nout;
    }
    return 0;
}

/* What channel c's result `method` of the colour run must equal: the joint run's for a method
 * with run_channels, else the grey run's. */
static const ppb_result *expected(int c, int i)
{
    for (int k = 0; k < njoint; k++)
        if (!strcmp(joint[c][k].method, grey[c].res[i].method))
            return &joint[c][k];
    return &grey[c].res[i];
}

/* Whether channel c's result i came from a joint trace (its energy holds within noise). */
static int is_joint(int c, int i)
{
    return expected(c, i) != &grey[c].res[i];
}

/* The colour run and the three grey runs, once for the suite. */
static int setup(void **state)
{
    (void)state;
    const char *path = tu_config("colour_case", case_text);
    ppb_err err;
    if (ppb_config_load(&cfg, path, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    int n = snprintf(cfg.out_dir, sizeof cfg.out_dir, "%.1000s/out", tu_scratch("colour_out"));
    if (n >= (int)sizeof cfg.out_dir)
        return -1;
    compute(&colour, &cfg);
    const char *names[3] = {"r", "g", "b"};
    for (int c = 0; c < 3; c++) {
        char set[32];
        snprintf(set, sizeof set, "medium.channel=%s", names[c]);
        const char *sets[] = {set};
        if (ppb_config_load_sets(&grey_cfg[c], NULL, path, sets, 1, &err)) {
            fprintf(stderr, "%s\n", err.msg);
            return -1;
        }
        compute(&grey[c], &grey_cfg[c]);
    }
    return run_joint(&err) ? (fprintf(stderr, "%s\n", err.msg), -1) : 0;
}

static int teardown(void **state)
{
    (void)state;
    ppb_experiment_free(&colour);
    for (int c = 0; c < 3; c++) {
        ppb_experiment_free(&grey[c]);
        for (int k = 0; k < njoint; k++)
            ppb_result_free(&joint[c][k]);
    }
    return 0;
}

/* Every method ran in every channel, and each channel's results are the expected ones
 * (expected(): the grey run's, or the joint trace's), bit for bit: radiance, standard errors and
 * totals. */
static void test_channels_equal_grey_runs(void **state)
{
    (void)state;
    assert_non_null(colour.colour);
    for (int c = 0; c < 3; c++) {
        const ppb_experiment *s = &colour.colour->sub[c];
        assert_int_equal(s->nfailed, 0);
        assert_int_equal(grey[c].nfailed, 0);
        /* 13 methods and mc's companion mc1 */
        assert_int_equal(s->n, cfg.nmethods + 1);
        assert_int_equal(s->n, grey[c].n);
        for (int i = 0; i < s->n; i++) {
            const ppb_result *a = &s->res[i], *b = expected(c, i);
            assert_string_equal(a->method, b->method);
            assert_int_equal(a->layout.ncells, b->layout.ncells);
            size_t bytes = a->layout.ncells * sizeof(double);
            if (memcmp(a->radiance, b->radiance, bytes) || memcmp(a->se, b->se, bytes))
                fail_msg("channel %d, %s: radiance differs from the expected run", c, a->method);
            const double ta[] = {a->totals.R,        a->totals.T,         a->totals.sides,
                                 a->totals.absorbed, a->totals.ballistic, a->totals.specular},
                         tb[] = {b->totals.R,        b->totals.T,         b->totals.sides,
                                 b->totals.absorbed, b->totals.ballistic, b->totals.specular};
            if (memcmp(ta, tb, sizeof ta))
                fail_msg("channel %d, %s: totals differ from the expected run", c, a->method);
        }
    }
}

/* No NaN or inf in any channel's or the luminance's radiance and totals; the Monte Carlo's
 * energy balance holds per channel and for the luminance (BT.709's weights sum to 1). */
static void test_finite_and_energy(void **state)
{
    (void)state;
    for (int s = 0; s < PPB_NSUBSETS; s++) {
        const ppb_experiment *e = &colour.colour->sub[s];
        for (int i = 0; i < e->n; i++) {
            const ppb_result *r = &e->res[i];
            for (size_t k = 0; k < r->layout.ncells; k++)
                if (!isfinite(r->radiance[k]) || !(r->radiance[k] >= 0) || !isfinite(r->se[k]))
                    fail_msg("%s %s: cell %zu is %g", ppb_subset_name(s), r->method, k,
                             r->radiance[k]);
            ppb_totals t = r->totals;
            ppb_totals_complete(&t);
            double sum = t.R + t.T + t.sides + t.absorbed + t.ballistic + t.specular;
            assert_true(isfinite(sum));
            /* A grey trace: exact but for the fixed-point tallies (PPB_MC_FIXED_SCALE = 2^32,
             * mc_params.h): a deposit loses at most 2^-32 = 2.3e-10 of a photon; fewer than 400
             * deposits a photon here (albedo <= 0.96 in a 3 x 1 mfp tube) keep the loss below
             * 1e-7. A joint trace (the hero estimator, docs/methods.md) conserves a channel's
             * energy in expectation: a photon's weight in a channel lies in [0, 3] (the balance
             * heuristic over three channels), so its energy's standard deviation is at most
             * 1.5 and the mean's at most 1.5 / sqrt(photons); five of those bound the sum. The
             * luminance inherits the bound (weights summing to 1). */
            if (!strcmp(r->method, "mc")) {
                int joint_trace = s == PPB_SUBSET_Y ? is_joint(0, i) : is_joint(s, i);
                double tol = joint_trace ? 5 * 1.5 / sqrt((double)cfg.mc.photons) : 1e-7;
                assert_close(sum, 1.0, tol);
            }
        }
    }
}

/* y holds the BT.709 sum of the expected runs (weights stated here, independently of the
 * code's table) cell by cell, and its summary.csv holds the metrics of that sum against the
 * Monte Carlo's sum, computed here with the metrics module from those runs. */
static void test_luminance(void **state)
{
    (void)state;
    static const double w[3] = {0.2126, 0.7152, 0.0722};
    const ppb_experiment *y = &colour.colour->sub[PPB_SUBSET_Y];
    assert_int_equal(y->n, grey[0].n);
    ppb_result lum[PPB_MAX_RESULTS];
    ppb_err err;
    for (int i = 0; i < y->n; i++) {
        assert_string_equal(y->res[i].method, grey[0].res[i].method);
        ppb_layout lo = grey[0].res[i].layout;
        assert_int_equal(ppb_result_init(&lum[i], grey[0].res[i].method, &lo, &err), 0);
        for (size_t k = 0; k < lo.ncells; k++) {
            double L = 0, se = 0;
            for (int c = 0; c < 3; c++) {
                L += w[c] * expected(c, i)->radiance[k];
                se += w[c] * expected(c, i)->se[k];
            }
            lum[i].radiance[k] = L;
            lum[i].se[k] = se;
            assert_close(y->res[i].radiance[k], L, 1e-15 * fabs(L));
        }
    }
    /* The written y/summary.csv against the metrics of the sums. */
    assert_int_equal(ppb_experiment_write(&colour, &err), 0);
    char path[1300];
    snprintf(path, sizeof path, "%s/y/summary.csv", cfg.out_dir);
    size_t len;
    char *text = ppb_read_file(path, &len);
    assert_non_null(text);
    ppb_point pts[256];
    int checked = 0;
    for (int i = 1; i < y->n; i++) { /* 0 is mc, the reference */
        if (!strcmp(lum[i].method, "mc1"))
            continue;
        for (int cell = 0; cell < PPB_NCELLS; cell++) {
            int np = ppb_cell_points(&lum[i].layout, cell, pts, 256);
            ppb_rms e = ppb_rms_points(&lum[i], &lum[0], pts, np);
            char row[256];
            snprintf(row, sizeof row, "\n%s,%s,%.6g,%.6g,%.6g\n", lum[i].method,
                     ppb_cell_name(cell), e.rms_rel, e.noise_rel, e.rms_excess);
            if (!strstr(text, row))
                fail_msg("y/summary.csv has no row %s", row + 1);
            checked++;
        }
    }
    assert_int_equal(checked, (cfg.nmethods - 1) * PPB_NCELLS);
    free(text);
    for (int i = 0; i < y->n; i++)
        ppb_result_free(&lum[i]);
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* The written set (after test_luminance wrote it): a grey set per subset, summary.csv with
 * the channel column and every subset's rows, the colour pictures read back with their
 * channels equal to the grey sets' pictures (R = G = B there) bit for bit. */
static void test_written_set(void **state)
{
    (void)state;
    char path[1400], path2[1400];
    const char *files[] = {"radiance.csv", "summary.csv",   "totals.csv",          "provenance.txt",
                           "config.ini",   "images/mc.exr", "images/errmap_pp.png"};
    for (int s = 0; s < PPB_NSUBSETS; s++)
        for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
            snprintf(path, sizeof path, "%s/%s/%s", cfg.out_dir, ppb_subset_name(s), files[f]);
            if (!exists(path))
                fail_msg("%s is missing", path);
        }
    snprintf(path, sizeof path, "%s/summary.csv", cfg.out_dir);
    const char *text = tu_read_text(path);
    assert_true(!strncmp(text, "channel,method,cell,rms_rel,noise_rel,rms_excess\n", 49));
    assert_non_null(strstr(text, "\nr,pp,R_x0,"));
    assert_non_null(strstr(text, "\ng,rte2d,S2_all,"));
    assert_non_null(strstr(text, "\nb,burley+ss,T_x0,"));
    assert_non_null(strstr(text, "\ny,pbd,S1_all,"));
    ppb_err err;
    int w, h, w1, h1;
    float *rgb = NULL, *one = NULL;
    snprintf(path, sizeof path, "%s/images/pbd.exr", cfg.out_dir);
    if (ppb_exr_read_rgb(path, &w, &h, &rgb, &err))
        fail_msg("%s", err.msg);
    for (int c = 0; c < 3; c++) {
        snprintf(path2, sizeof path2, "%s/%s/images/pbd.exr", cfg.out_dir, ppb_subset_name(c));
        if (ppb_exr_read_rgb(path2, &w1, &h1, &one, &err))
            fail_msg("%s", err.msg);
        assert_int_equal(w, w1);
        assert_int_equal(h, h1);
        for (long k = 0; k < (long)w * h; k++)
            if (rgb[3 * k + c] != one[3 * k])
                fail_msg("pixel %ld channel %d: %g, the grey set's %g", k, c, rgb[3 * k + c],
                         one[3 * k]);
        free(one);
    }
    /* The PNG: the tone curve scales the three channels alike, so where it does not clip,
     * their order is the radiance's (skin: red above green above blue). */
    unsigned char *png = NULL;
    snprintf(path, sizeof path, "%s/images/mc.png", cfg.out_dir);
    if (ppb_png_read_rgb(path, &w1, &h1, &png, &err))
        fail_msg("%s", err.msg);
    assert_int_equal(w1, w);
    assert_int_equal(h1, h);
    free(rgb);
    snprintf(path, sizeof path, "%s/images/mc.exr", cfg.out_dir);
    if (ppb_exr_read_rgb(path, &w, &h, &rgb, &err))
        fail_msg("%s", err.msg);
    long ordered = 0;
    for (long k = 0; k < (long)w * h; k++) {
        const float *L = rgb + 3 * k;
        const unsigned char *p = png + 3 * k;
        if (!(L[0] > L[1] && L[1] > L[2] && L[2] > 0) || p[0] == 255)
            continue;
        assert_true(p[0] >= p[1] && p[1] >= p[2]);
        ordered++;
    }
    assert_true(ordered > 1000);
    free(rgb);
    free(png);
}

/* Refused before any work, exit 2, naming the key: a material whose channel is outside a key's
 * range (coke's red g = 0.965 > 0.95), rgb without a material, rgb in a sweep. */
static void test_refusals(void **state)
{
    (void)state;
    const char *dir = tu_scratch("colour_refusals");
    char cmd[4096];
    const char *path = tu_config("colour_coke", "[experiment]\nunit = mm\nmethods = mc\n[medium]\n"
                                                "material = coke\nchannel = rgb\n");
    snprintf(cmd, sizeof cmd, "%s run --out %s/a %s > %s/a.log 2>&1", tu_bin(), dir, path, dir);
    assert_int_equal(tu_sh("%s", cmd), 2);
    snprintf(cmd, sizeof cmd, "%s/a.log", dir);
    assert_non_null(strstr(tu_read_text(cmd), "[medium] channel: rgb runs every channel, and "
                                              "coke's r channel has g = 0.965"));
    path = tu_config("colour_nomat", "[experiment]\nmethods = mc\n[medium]\nchannel = rgb\n");
    snprintf(cmd, sizeof cmd, "%s run --out %s/b %s > %s/b.log 2>&1", tu_bin(), dir, path, dir);
    assert_int_equal(tu_sh("%s", cmd), 2);
    snprintf(cmd, sizeof cmd, "%s/b.log", dir);
    assert_non_null(strstr(tu_read_text(cmd), "[medium] channel: rgb selects a colour channel"));
    path = tu_config("colour_sweep", "[experiment]\nunit = mm\nmethods = mc\n[tube]\nwidth = 3, "
                                     "4\n[medium]\nmaterial = skin1\nchannel = rgb\n");
    snprintf(cmd, sizeof cmd, "%s sweep --out %s/c %s > %s/c.log 2>&1", tu_bin(), dir, path, dir);
    assert_int_equal(tu_sh("%s", cmd), 2);
    snprintf(cmd, sizeof cmd, "%s/c.log", dir);
    assert_non_null(strstr(tu_read_text(cmd), "is `ppbench run`'s alone"));
    /* The materials study's sets (results/materials/<case>) are make bench's alone
     * (drivers/study_guard.h): the case's own config, without --out, is refused untouched. */
    snprintf(cmd, sizeof cmd,
             "cd %s && env -u PPB_BENCH_STUDY %s run configs/material_marble.ini > %s/d.log 2>&1",
             PPB_SOURCE_DIR, tu_bin(), dir);
    assert_int_equal(tu_sh("%s", cmd), 2);
    snprintf(cmd, sizeof cmd, "%s/d.log", dir);
    assert_non_null(strstr(tu_read_text(cmd), "is the committed study's"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_channels_equal_grey_runs),
        cmocka_unit_test(test_finite_and_energy),
        cmocka_unit_test(test_luminance),
        cmocka_unit_test(test_written_set),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
