/* test_plots.c: the figures of a run and of a sweep (scripts/plots.sh, src/io/plots.c,
 * src/drivers/sweep_plot.c; reference: Outputs, Sweeps). `ppbench run` draws them inside its
 * output set; every figure is there as PNG and PDF with the panels, labels and markers
 * docs/reference.md (Outputs) describes, read from the gnuplot scripts plots.sh keeps under
 * PPB_PLOTS_KEEP; without mc the run still succeeds and draws what exists; a sweep's heat map has a
 * row of panels per value of its third key and a 1-D sweep gets a line plot; rms_vs_x's four panels
 * share one y range; sweeps plot the RMS beyond the noise floor (docs/reference.md: Sweeps). */
#include "testutil.h"

#include <sys/stat.h>
#include <unistd.h>

static int exists(const char *dir, const char *name)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    struct stat st;
    return stat(path, &st) == 0 && st.st_size > 0;
}

/* Width and height of a PNG from its IHDR chunk (big-endian at bytes 16..23). */
static void png_size(const char *path, int *w, int *h)
{
    unsigned char b[24] = {0};
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    assert_int_equal(fread(b, 1, sizeof b, f), sizeof b);
    fclose(f);
    *w = (b[16] << 24) | (b[17] << 16) | (b[18] << 8) | b[19];
    *h = (b[20] << 24) | (b[21] << 16) | (b[22] << 8) | b[23];
}

static void assert_has(const char *text, const char *needle)
{
    if (!strstr(text, needle))
        fail_msg("missing \"%s\" in:\n%.2000s", needle, text);
}

static const char *small = "--quiet --set mc.photons=2e4 --set pp.directions=16 "
                           "--set bins.samples_dir=2 --set tube.segments_top=32 "
                           "--set tube.segments_side=8";

static void test_run_draws_every_figure(void **state)
{
    (void)state;
    const char *dir = tu_scratch("plots_run");
    char out[1200], keep[1200], path[2048];
    snprintf(out, sizeof out, "%s/out", dir);
    snprintf(keep, sizeof keep, "%s/gp", dir);
    assert_int_equal(tu_sh("mkdir -p '%s'", keep), 0);
    /* the density step: step_x = 0, sigma_t = 1, so the markers sit at 0 and +-2 */
    assert_int_equal(tu_sh("PPB_PLOTS_KEEP='%s' %s run %s --set experiment.methods=mc,pp,mp "
                           "--out '%s' configs/density_step.ini",
                           keep, tu_bin(), small, out),
                     0);
    const char *files[] = {"plots/rms_vs_x",  "plots/angular_x0", "plots/angular_x0_polar",
                           "images/all",      "images/error_pp",  "images/error_mp",
                           "images/error_mc1"};
    for (size_t i = 0; i < sizeof files / sizeof *files; i++)
        for (int t = 0; t < 2; t++) {
            snprintf(path, sizeof path, "%s.%s", files[i], t ? "pdf" : "png");
            if (!exists(out, path))
                fail_msg("%s/%s not written", out, path);
        }
    assert_false(exists(out, "images/error_mc.png")); /* the reference has none */
    /* no staging left beside it: the plots were drawn before the set was put in place */
    assert_int_equal(tu_sh("ls -d '%s'.tmp.* 2>/dev/null | grep -q .", out), 1);

    snprintf(path, sizeof path, "%s/rms_vs_x.gp", keep);
    char *gp = tu_read_text(path);
    for (int s = 1; s <= 4; s++) {
        char t[16];
        snprintf(t, sizeof t, "'S%d (", s);
        assert_has(gp, t);
    }
    assert_has(gp, "set arrow 1 from 0, graph 0");
    assert_has(gp, "set arrow 2 from (0 + -2 * 1), graph 0");
    assert_has(gp, "set arrow 3 from (0 + 2 * 1), graph 0");
    assert_has(gp, "set key at screen 0.99"); /* beside the panels, not over the curves */
    assert_has(gp, "lc rgb mcolor('pp')");
    /* S1 and S2 share one y range */
    char *a = strstr(gp, "S1 (top"), *b = strstr(gp, "S2 (bottom");
    assert_non_null(a);
    assert_non_null(b);
    char ra[64] = "", rb[64] = "";
    assert_int_equal(sscanf(strstr(a, "set yrange"), "set yrange %63s", ra), 1);
    assert_int_equal(sscanf(strstr(b, "set yrange"), "set yrange %63s", rb), 1);
    assert_string_equal(ra, rb);

    snprintf(path, sizeof path, "%s/angular_x0.gp", keep);
    gp = tu_read_text(path);
    assert_has(gp, "with yerrorbars");
    assert_has(gp, "red dotted line");
    if (strstr(gp, "arrow:"))
        fail_msg("a dotted line labelled as an arrow:\n%.2000s", gp);
    snprintf(path, sizeof path, "%s/angular_x0_polar.gp", keep);
    assert_has(tu_read_text(path), "set polar");

    snprintf(path, sizeof path, "%s/all.gp", keep);
    gp = tu_read_text(path);
    const char *ids[] = {"mc", "mc1", "pp", "mp"};
    for (int i = 0; i < 4; i++) {
        char t[64];
        snprintf(t, sizeof t, "set title '%s' font", ids[i]);
        assert_has(gp, t);
    }
    /* a colour bar of the pictures' grey levels: images.c's tone curve (shoulder above 0.75,
     * sRGB-encoded) over radiance / L_white (all.png had none: a grey read as nothing) */
    assert_has(gp, "set palette functions enc(sh(2 * gray))");
    assert_has(gp, "set colorbox horizontal");
    assert_has(gp, "set cblabel 'radiance / L_white");
    snprintf(path, sizeof path, "%s/error_pp.gp", keep);
    gp = tu_read_text(path);
    assert_has(gp, "pp vs mc");
    assert_has(gp, "'-50%%' -50, '-25%%' -25, '0' 0, '+25%%' 25, '+50%%' 50");
    snprintf(path, sizeof path, "%s/images/all.png", out);
    int w, h;
    png_size(path, &w, &h);
    assert_int_equal(w, 4 * 250 + 20); /* one panel per method: mc, mc1, pp, mp */
}

/* Without the Monte Carlo: no reference, so no rms_vs_x and no error figures, and the run
 * (and plots.sh) still succeed with the rest. */
static void test_without_mc(void **state)
{
    (void)state;
    const char *dir = tu_scratch("plots_nomc");
    char out[1200];
    snprintf(out, sizeof out, "%s/out", dir);
    assert_int_equal(tu_sh("%s run %s --set experiment.methods=pp,ss --out '%s' "
                           "configs/uniform_g0_normal.ini",
                           tu_bin(), small, out),
                     0);
    assert_true(exists(out, "plots/angular_x0.png"));
    assert_true(exists(out, "plots/angular_x0_polar.pdf"));
    assert_true(exists(out, "images/all.png"));
    assert_false(exists(out, "plots/rms_vs_x.png"));
    assert_false(exists(out, "images/error_pp.png"));
    char path[2048];
    snprintf(path, sizeof path, "%s/images/all.png", out);
    int w, h;
    png_size(path, &w, &h);
    assert_int_equal(w, 2 * 250 + 20);
}

/* rms_vs_x's four panels share one y range: a set whose side errors (S3, S4) are a hundred
 * times its top and bottom errors (a synthetic rms.csv: 1 % on S1, S2, 100 % on S3, S4; the
 * Monte Carlo floor 0.5 %) gave S1, S2 the range [0.1:1] and S3, S4 [0.1:100], so the sides
 * looked as good as the top. Now every panel has [0.1:100] (the decades around 0.5 % .. 100 %). */
static void test_rms_panels_share_one_range(void **state)
{
    (void)state;
    const char *dir = tu_scratch("plots_range");
    char path[2048];
    snprintf(path, sizeof path, "%s/case/provenance.txt", dir);
    assert_int_equal(tu_sh("mkdir -p '%s/case' '%s/gp'", dir, dir), 0);
    tu_write_file(path, "# ppbench provenance: test\nexperiment.name = r\n"
                        "experiment.geometry = tube\nmedium.step = none\n");
    snprintf(path, sizeof path, "%s/case/rms.csv", dir);
    tu_write_file(path, "method,surface,segment,s,rms_rel,noise_rel,rms_excess\n"
                        "pp,S1,0,-1,0.01,0.005,0.0087\npp,S1,1,1,0.01,0.005,0.0087\n"
                        "pp,S2,0,-1,0.01,0.005,0.0087\npp,S2,1,1,0.01,0.005,0.0087\n"
                        "pp,S3,0,-1,1,0.005,1\npp,S3,1,-0.5,1,0.005,1\n"
                        "pp,S4,0,-1,1,0.005,1\npp,S4,1,-0.5,1,0.005,1\n");
    assert_int_equal(
        tu_sh("PPB_PLOTS_KEEP='%s/gp' bash scripts/plots.sh '%s/case' > /dev/null", dir, dir), 0);
    snprintf(path, sizeof path, "%s/gp/rms_vs_x.gp", dir);
    char *gp = tu_read_text(path);
    const char *panels[] = {"S1 (top", "S2 (bottom", "S3 (left", "S4 (right"};
    for (int i = 0; i < 4; i++) {
        char *at = strstr(gp, panels[i]), r[64] = "";
        assert_non_null(at);
        assert_int_equal(sscanf(strstr(at, "set yrange"), "set yrange %63s", r), 1);
        assert_string_equal(r, "[0.1:100]");
    }
}

static void write_sweep(const char *path, const char *lists, const char *out)
{
    char text[2048];
    snprintf(text, sizeof text,
             "[experiment]\nname = s\ngeometry = slab\nmethods = mc, ss\n%s[mc]\nphotons = "
             "2e3\n[pp]\ndirections = 16\n[output]\ndir = %s\n",
             lists, out);
    tu_write_file(path, text);
}

/* Three swept keys: a row of (R, T) panels per value of the third, so the PNG is 60 + 330 x 3
 * pixels high (sweep_plot.c); one key: a line plot and no heat map. */
static void test_sweep_plots(void **state)
{
    (void)state;
    const char *dir = tu_scratch("plots_sweep");
    char ini[1200], out[1200], path[2048];
    snprintf(ini, sizeof ini, "%s/s3.ini", dir);
    snprintf(out, sizeof out, "%s/s3", dir);
    write_sweep(ini, "[medium]\ng = 0, 0.5\nalbedo = 0.5, 0.9\n[light]\ntheta_deg = 0, 30, 60\n",
                out);
    assert_int_equal(
        tu_sh("PPB_PLOTS_KEEP='%s' %s sweep --quiet '%s' > /dev/null 2>&1", dir, tu_bin(), ini), 0);
    assert_true(exists(out, "heatmap_ss.png"));
    /* sweep.csv gains the noise floor and the RMS beyond it of every cell (model/metrics.h:
     * noise_rel, rms_excess); the heat map is coloured by the excess, and a cell within the
     * noise is grey and says so (an RMS alone read as the method's error where it was the
     * reference's noise) */
    snprintf(path, sizeof path, "%s/sweep.csv", out);
    char *csv = tu_read_text(path);
    assert_has(csv, ",noise_R_x0,noise_T_x0,noise_S1_all,noise_S2_all,noise_S3_all,noise_S4_all,"
                    "excess_R_x0,excess_T_x0,excess_S1_all,");
    snprintf(path, sizeof path, "%s/heatmap_ss.png.gp", dir);
    char *hm = tu_read_text(path);
    assert_has(hm, "RMS beyond the MC noise (%)");
    assert_has(hm, "with boxxyerror fs solid noborder fc rgb '#BBBBBB'");
    assert_has(hm, "'noise'");
    assert_has(hm, "set output ARG1"); /* the path is data, not script text */
    assert_true(exists(out, "heatmap_ss.pdf"));
    assert_false(exists(out, "heatmap_mc.png"));
    snprintf(path, sizeof path, "%s/heatmap_ss.png", out);
    int w, h;
    png_size(path, &w, &h);
    assert_int_equal(h, 60 + 330 * 3);

    snprintf(ini, sizeof ini, "%s/s1.ini", dir);
    snprintf(out, sizeof out, "%s/s1", dir);
    write_sweep(ini, "[medium]\ng = 0, 0.5, 0.8\n", out);
    assert_int_equal(
        tu_sh("PPB_PLOTS_KEEP='%s' %s sweep --quiet '%s' > /dev/null 2>&1", dir, tu_bin(), ini), 0);
    assert_true(exists(out, "sweep_rms.png"));
    /* the excess with the noise floor dashed; padded so the first and last values' markers
     * are not drawn on the frame (a sweep of two values had both there) */
    snprintf(path, sizeof path, "%s/sweep_rms.png.gp", dir);
    char *lp = tu_read_text(path);
    assert_has(lp, "set offsets graph 0.06, graph 0.06");
    assert_has(lp, "title 'MC noise floor'");
    assert_has(lp, "RMS beyond the MC noise (%)");
    assert_true(exists(out, "sweep_rms.pdf"));
    assert_false(exists(out, "heatmap_ss.png"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_run_draws_every_figure),
        cmocka_unit_test(test_without_mc),
        cmocka_unit_test(test_rms_panels_share_one_range),
        cmocka_unit_test(test_sweep_plots),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
