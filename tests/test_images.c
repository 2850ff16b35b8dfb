/* test_images.c: the shaded tube images (images.c, render_tube.c, image_exr.c, image_png.c):
 * EXR and PNG round trips through the libraries' own readers, the camera's analytic
 * projection, uniform and per-segment radiance fields end to end, one exposure per view shared
 * by the methods, the light arrow on the top view only, atomic outputs (no temporary left,
 * a failure leaves no file), and the EXR header's string attributes (method, case, seed,
 * photons, version, what the image shows), read back through the OpenEXR C API itself. */
#include "testutil.h"

#include <dirent.h>
#include <math.h>
#include <sys/stat.h>

#include <OpenEXR/openexr.h>

#include "drivers/experiment.h"
#include "io/image_exr.h"
#include "io/image_png.h"
#include "io/images.h"
#include "io/render_tube.h"

/* cmocka 1.1.5 has no double comparison; this one prints both values. */
static void near_at(double a, double b, double tol, int line)
{
    if (!(fabs(a - b) <= tol))
        fail_msg("line %d: %.17g != %.17g (tolerance %g)", line, a, b, tol);
}
#define assert_near(a, b, tol) near_at((a), (b), (tol), __LINE__)

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Number of entries in dir whose name contains needle. */
static int count_named(const char *dir, const char *needle)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e = readdir(d); e; e = readdir(d))
        n += strstr(e->d_name, needle) != NULL;
    closedir(d);
    return n;
}

/* ---- file formats ---- */

static void test_exr_roundtrip(void **state)
{
    (void)state;
    /* 37 rows: not a multiple of ZIP's 16-line chunks, so the short last chunk is exercised. */
    enum { W = 7, H = 37 };
    float rgb[W * H * 3];
    for (int k = 0; k < W * H * 3; k++)
        rgb[k] = (float)((k % 5 - 2) * pow(10.0, k % 7 - 3) + 1e-3 * k);
    char path[1200];
    snprintf(path, sizeof path, "%s/a.exr", tu_scratch("exr"));
    ppb_err err;
    assert_int_equal(ppb_exr_write_rgb(path, W, H, rgb, NULL, 0, &err), 0);
    int w = 0, h = 0;
    float *back = NULL;
    if (ppb_exr_read_rgb(path, &w, &h, &back, &err))
        fail_msg("%s", err.msg);
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    /* Lossless 32-bit float: the values written, bit for bit. */
    assert_memory_equal(back, rgb, sizeof rgb);
    free(back);
}

/* The string attribute `name` of path's header, read by the OpenEXR C API (not by
 * image_exr.c), copied into out; fails the test if the file or the attribute is missing or
 * not a string. */
static void exr_string_attr(const char *path, const char *name, char *out, size_t cap)
{
    exr_context_t ctxt = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_result_t rv = exr_start_read(&ctxt, path, &init);
    if (rv != EXR_ERR_SUCCESS)
        fail_msg("%s: cannot read: %s", path, exr_get_default_error_message(rv));
    int32_t len = 0;
    const char *v = NULL;
    rv = exr_attr_get_string(ctxt, 0, name, &len, &v);
    if (rv == EXR_ERR_SUCCESS)
        snprintf(out, cap, "%.*s", (int)len, v);
    exr_finish(&ctxt);
    if (rv != EXR_ERR_SUCCESS)
        fail_msg("%s: no string attribute %s: %s", path, name, exr_get_default_error_message(rv));
}

/* Attributes given to the writer come back by name with their values, pixels unchanged. */
static void test_exr_string_attributes(void **state)
{
    (void)state;
    enum { W = 3, H = 2 };
    float rgb[W * H * 3];
    for (int k = 0; k < W * H * 3; k++)
        rgb[k] = 0.25f * (float)k;
    char path[1200], got[512];
    snprintf(path, sizeof path, "%s/meta.exr", tu_scratch("exrattr"));
    const ppb_exr_attr attrs[] = {
        {"ppbench.method", "pp"}, {"ppbench.case", "density_step"}, {"ppbench.seed", "42"}};
    ppb_err err;
    if (ppb_exr_write_rgb(path, W, H, rgb, attrs, 3, &err))
        fail_msg("%s", err.msg);
    for (int a = 0; a < 3; a++) {
        exr_string_attr(path, attrs[a].name, got, sizeof got);
        assert_string_equal(got, attrs[a].value);
    }
    int w, h;
    float *back = NULL;
    if (ppb_exr_read_rgb(path, &w, &h, &back, &err))
        fail_msg("%s", err.msg);
    assert_memory_equal(back, rgb, sizeof rgb);
    free(back);
}

static void test_png_roundtrip(void **state)
{
    (void)state;
    enum { W = 5, H = 3 };
    unsigned char rgb[W * H * 3];
    for (int k = 0; k < W * H * 3; k++)
        rgb[k] = (unsigned char)(k * 17 + 3);
    char path[1200];
    snprintf(path, sizeof path, "%s/a.png", tu_scratch("png"));
    ppb_err err;
    assert_int_equal(ppb_png_write_rgb(path, W, H, rgb, &err), 0);
    int w = 0, h = 0;
    unsigned char *back = NULL;
    if (ppb_png_read_rgb(path, &w, &h, &back, &err))
        fail_msg("%s", err.msg);
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    assert_memory_equal(back, rgb, sizeof rgb);
    free(back);
}

/* A failure leaves neither the file nor a temporary: the target is a directory, so the final
 * rename fails after the whole image was written; a missing directory fails at the start. */
static void test_writers_atomic_on_failure(void **state)
{
    (void)state;
    const char *dir = tu_scratch("atomic");
    char blocked[1200], missing[1200];
    float f[3] = {1, 2, 3};
    unsigned char b[3] = {1, 2, 3};
    ppb_err err;
    snprintf(blocked, sizeof blocked, "%s/blocked.exr", dir);
    assert_int_equal(mkdir(blocked, 0777), 0);
    assert_int_equal(ppb_exr_write_rgb(blocked, 1, 1, f, NULL, 0, &err), -1);
    snprintf(blocked, sizeof blocked, "%s/blocked.png", dir);
    assert_int_equal(mkdir(blocked, 0777), 0);
    assert_int_equal(ppb_png_write_rgb(blocked, 1, 1, b, &err), -1);
    assert_int_equal(count_named(dir, ".tmp"), 0);
    snprintf(missing, sizeof missing, "%s/no/such/dir/a.exr", dir);
    assert_int_equal(ppb_exr_write_rgb(missing, 1, 1, f, NULL, 0, &err), -1);
    assert_non_null(strstr(err.msg, "a.exr"));
    snprintf(missing, sizeof missing, "%s/no/such/dir/a.png", dir);
    assert_int_equal(ppb_png_write_rgb(missing, 1, 1, b, &err), -1);
    assert_false(exists(missing));
    assert_int_equal(count_named(dir, ".tmp"), 0);
}

/* ---- camera ---- */

static const double above[3] = {-0.6, 0.7, 0.4};

static void unit(const double a[3], double out[3])
{
    double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (int k = 0; k < 3; k++)
        out[k] = a[k] / n;
}

static void test_camera_projection_analytic(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    ppb_tube_view v;
    ppb_err err;
    assert_int_equal(ppb_tube_view_init(&v, &sc, 4.0, above, 320, 240, &err), 0);
    /* right = y x w / |y x w| = (w_z, 0, -w_x) / |.|, up = w x right. */
    double w[3], right[3], up[3];
    unit(above, w);
    double r_norm = hypot(w[2], w[0]);
    right[0] = w[2] / r_norm, right[1] = 0, right[2] = -w[0] / r_norm;
    up[0] = w[1] * right[2] - w[2] * right[1];
    up[1] = w[2] * right[0] - w[0] * right[2];
    up[2] = w[0] * right[1] - w[1] * right[0];
    for (int k = 0; k < 3; k++) {
        assert_near(v.right[k], right[k], 1e-12);
        assert_near(v.up[k], up[k], 1e-12);
    }
    /* The box centre is framed at the image centre. */
    double centre[3] = {0, -0.5 * sc.height, 0}, px, py;
    ppb_tube_view_project(&v, centre, &px, &py);
    assert_near(px, 160.0, 1e-9);
    assert_near(py, 120.0, 1e-9);
    /* A point on S1 lands where u = p.right, v = p.up predict, and the ray cast there finds
     * S1 at that very point. */
    double p[3] = {2.0, 0.0, 1.0};
    ppb_tube_view_project(&v, p, &px, &py);
    double u = p[0] * right[0] + p[1] * right[1] + p[2] * right[2];
    double vv = p[0] * up[0] + p[1] * up[1] + p[2] * up[2];
    assert_near(px, (u - v.u0) / v.pixel, 1e-9);
    assert_near(py, (v.v0 - vv) / v.pixel, 1e-9);
    ppb_tube_hit h = ppb_tube_view_hit(&v, px, py);
    assert_int_equal(h.kind, PPB_PIX_SURFACE);
    assert_int_equal(h.surf, PPB_S1);
    for (int k = 0; k < 3; k++)
        assert_near(h.p[k], p[k], 1e-9);
    /* S3 is seen from the left; S4 faces away, so its point is hidden behind S1 or S3. */
    double p3[3] = {-5.0, -1.0, -2.0}, p4[3] = {5.0, -1.5, 0.0};
    ppb_tube_view_project(&v, p3, &px, &py);
    h = ppb_tube_view_hit(&v, px, py);
    assert_int_equal(h.surf, PPB_S3);
    assert_near(h.p[1], -1.0, 1e-9);
    ppb_tube_view_project(&v, p4, &px, &py);
    h = ppb_tube_view_hit(&v, px, py);
    assert_int_not_equal(h.surf, PPB_S4);
}

/* The cell a pixel shows: segment by ppb_segment_of's numbering, bin of the direction toward
 * the camera in the surface's frame. */
static void test_camera_cell(void **state)
{
    (void)state;
    ppb_scene sc = tu_tube();
    ppb_layout lo = ppb_scene_layout(&sc);
    ppb_tube_view v;
    ppb_err err;
    assert_int_equal(ppb_tube_view_init(&v, &sc, 4.0, above, 320, 240, &err), 0);
    double w[3];
    unit(above, w);
    int surf[2] = {PPB_S1, PPB_S3}, seg[2] = {100, 7};
    for (int t = 0; t < 2; t++) {
        double p[3] = {0, 0, 0.5}, px, py;
        ppb_scene_sample_point(&sc, surf[t], seg[t], &p[0], &p[1]);
        ppb_tube_view_project(&v, p, &px, &py);
        ppb_tube_hit h = ppb_tube_view_hit(&v, px, py);
        assert_int_equal(h.surf, surf[t]);
        int bin = ppb_dir_bin(surf[t], w[0], w[1], w[2], sc.ntheta, sc.nphi);
        assert_int_equal(ppb_tube_view_cell(&v, &lo, &h), ppb_cell(&lo, surf[t], seg[t], bin));
    }
}

/* ---- whole experiments ---- */

typedef struct fake {
    ppb_config cfg;
    ppb_experiment ex;
} fake;

/* A test-only experiment: the default tube, results "mc" (the reference) and "pp". */
static fake *fake_new(const char *name, ppb_geometry geometry)
{
    fake *f = calloc(1, sizeof *f);
    assert_non_null(f);
    f->cfg.scene = tu_tube();
    f->cfg.scene.geometry = geometry;
    int len = snprintf(f->cfg.out_dir, sizeof f->cfg.out_dir, "%s/out", tu_scratch(name));
    assert_true(len < (int)sizeof f->cfg.out_dir);
    f->ex.cfg = &f->cfg;
    ppb_layout lo = ppb_scene_layout(&f->cfg.scene);
    const char *ids[2] = {"mc", "pp"};
    ppb_err err;
    for (int i = 0; i < 2; i++)
        assert_int_equal(ppb_result_init(&f->ex.res[i], ids[i], &lo, &err), 0);
    f->ex.n = 2;
    return f;
}

static void fake_fill(fake *f, int i, double value)
{
    for (size_t k = 0; k < f->ex.res[i].layout.ncells; k++)
        f->ex.res[i].radiance[k] = value;
}

/* The light arrow's colour (images.c): never a grey, so it cannot be mistaken for a surface. */
static int is_arrow(const unsigned char *px)
{
    return px[0] == 255 && px[1] == 226 && px[2] == 110;
}

static void fake_free(fake *f)
{
    for (int i = 0; i < f->ex.n; i++)
        ppb_result_free(&f->ex.res[i]);
    free(f);
}

static void image_file(const fake *f, const char *name, char *path, size_t cap)
{
    snprintf(path, cap, "%s/images/%s", f->cfg.out_dir, name);
}

static float *read_exr(const fake *f, const char *name, int *w, int *h)
{
    char path[1300];
    image_file(f, name, path, sizeof path);
    float *rgb = NULL;
    ppb_err err;
    if (ppb_exr_read_rgb(path, w, h, &rgb, &err))
        fail_msg("%s", err.msg);
    return rgb;
}

static unsigned char *read_png(const fake *f, const char *name, int *w, int *h)
{
    char path[1300];
    image_file(f, name, path, sizeof path);
    unsigned char *rgb = NULL;
    ppb_err err;
    if (ppb_png_read_rgb(path, w, h, &rgb, &err))
        fail_msg("%s", err.msg);
    return rgb;
}

static void write_images(fake *f)
{
    ppb_err err;
    if (ppb_images_write(f->cfg.out_dir, &f->cfg.scene, NULL, f->ex.res, f->ex.n, 0, &err))
        fail_msg("%s", err.msg);
}

/* A uniform field gives a uniform image: every tube pixel of the EXR holds the value, every
 * tube pixel of the PNG the same grey; both views show their surfaces. */
static void test_uniform_field(void **state)
{
    (void)state;
    fake *f = fake_new("uniform", PPB_GEOM_TUBE);
    fake_fill(f, 0, 0.7);
    fake_fill(f, 1, 0.7);
    write_images(f);
    int w, h, pw, ph;
    float *exr = read_exr(f, "pp.exr", &w, &h);
    unsigned char *png = read_png(f, "pp.png", &pw, &ph);
    assert_int_equal(pw, w);
    assert_int_equal(ph, h);
    long lit[2] = {0, 0}, arrow[2] = {0, 0};
    int grey = -1;
    for (long k = 0; k < (long)w * h; k++) {
        float L = exr[3 * k];
        assert_true(L == 0.0f || L == 0.7f);
        assert_true(exr[3 * k + 1] == L && exr[3 * k + 2] == L);
        if (is_arrow(png + 3 * k)) {
            arrow[k >= (long)w * h / 2]++;
            continue;
        }
        if (L == 0.0f)
            continue;
        lit[k >= (long)w * h / 2]++;
        assert_true(png[3 * k] == png[3 * k + 1] && png[3 * k] == png[3 * k + 2]);
        if (grey < 0)
            grey = png[3 * k];
        assert_int_equal(png[3 * k], grey);
    }
    /* Both views (top half: S1 and S3, bottom half: S2 and S3) cover a good part of the frame. */
    assert_true(lit[0] > (long)w * h / 10 && lit[1] > (long)w * h / 10);
    /* The light arrow (0.6 W long, 3 pixels wide) is drawn on the top view and only there. */
    assert_true(arrow[0] > 60);
    assert_int_equal(arrow[1], 0);
    free(exr);
    free(png);
    fake_free(f);
}

/* The light arrow points at a searchlight's strip (images.c): with the strip at x0 = W/4 (the
 * whole face's arrow ends at -W/4, W/2 away) and only S1's segments inside it bright, the
 * arrow's tip (its lowest pixel: the tail is above S1, the head's strokes go back up from the
 * tip) lies within 3 pixels of a bright pixel of the strip (the arrow at -W/4, as drawn before
 * it followed the strip, ended 70 pixels from the nearest). */
static void test_arrow_at_strip(void **state)
{
    (void)state;
    fake *f = fake_new("arrow_strip", PPB_GEOM_TUBE);
    ppb_scene *sc = &f->cfg.scene;
    sc->searchlight = 1;
    sc->light_x0 = 0.25 * sc->width;
    sc->light_width = 0.1 * sc->width;
    ppb_layout lo = ppb_scene_layout(sc);
    for (int i = 0; i < 2; i++)
        for (int seg = 0; seg < lo.nseg[PPB_S1]; seg++) {
            double x, y;
            ppb_scene_sample_point(sc, PPB_S1, seg, &x, &y);
            for (int b = 0; b < lo.nbins; b++)
                f->ex.res[i].radiance[ppb_cell(&lo, PPB_S1, seg, b)] =
                    fabs(x - sc->light_x0) < 0.5 * sc->light_width ? 1.0 : 0.0;
        }
    write_images(f);
    int w, h, pw, ph;
    float *exr = read_exr(f, "pp.exr", &w, &h);
    unsigned char *png = read_png(f, "pp.png", &pw, &ph);
    long tip = -1;
    for (long k = 0; k < (long)w * h / 2; k++)
        if (is_arrow(png + 3 * k))
            tip = k; /* the last in row order: the lowest row */
    assert_true(tip >= 0);
    double best = INFINITY;
    for (long k = 0; k < (long)w * h / 2; k++)
        if (exr[3 * k] > 0.0f)
            best = fmin(best, hypot((double)(k % w - tip % w), (double)(k / w - tip / w)));
    assert_true(best <= 3.0);
    free(exr);
    free(png);
    fake_free(f);
}

/* The pixel showing segment k of S1 (S2) holds exactly that segment's radiance: the camera
 * mapping end to end, through the EXR. */
static void test_segment_field_through_exr(void **state)
{
    (void)state;
    fake *f = fake_new("segments", PPB_GEOM_TUBE);
    ppb_result *r = &f->ex.res[1];
    for (int s = 0; s < PPB_NSURF; s++)
        for (int k = 0; k < r->layout.nseg[s]; k++)
            for (int b = 0; b < r->layout.nbins; b++)
                r->radiance[ppb_cell(&r->layout, s, k, b)] = 1000 * s + k;
    fake_fill(f, 0, 1.0);
    write_images(f);
    int w, h;
    float *exr = read_exr(f, "pp.exr", &w, &h);
    ppb_tube_view views[2];
    ppb_err err;
    assert_int_equal(ppb_tube_views_paper(views, &f->cfg.scene, w, h / 2, &err), 0);
    int surf[2] = {PPB_S1, PPB_S2};
    double width = f->cfg.scene.width;
    for (int v = 0; v < 2; v++)
        for (int k = 5; k < 128; k += 20) {
            /* The pixel holding segment k's centre is shaded from the ray through the pixel's
             * own centre, which may fall in a neighbouring segment: compare with the segment
             * of the point that ray meets, counted from x = -W/2 (reference: Geometry). */
            double p[3] = {0, 0, 0}, px, py;
            ppb_scene_sample_point(&f->cfg.scene, surf[v], k, &p[0], &p[1]);
            ppb_tube_view_project(&views[v], p, &px, &py);
            ppb_tube_hit hit = ppb_tube_view_hit(&views[v], floor(px) + 0.5, floor(py) + 0.5);
            assert_int_equal(hit.surf, surf[v]);
            int seg = (int)floor((hit.p[0] + 0.5 * width) / width * 128);
            assert_true(abs(seg - k) <= 1);
            long at = ((long)py + (long)v * (h / 2)) * w + (long)px;
            assert_near(exr[3 * at], 1000.0 * surf[v] + seg, 0);
        }
    free(exr);
    fake_free(f);
}

/* One exposure for every method: half the reference's radiance is sRGB(0.5) grey, and the
 * reference's own level is not clipped to white (the shoulder).
 * Every file is there and no temporary is left; all.png and error_<m>.png are plots.sh's (the
 * labelled figures), not written here. */
static void test_shared_exposure_and_files(void **state)
{
    (void)state;
    fake *f = fake_new("exposure", PPB_GEOM_TUBE);
    fake_fill(f, 0, 2.0);
    fake_fill(f, 1, 1.0);
    write_images(f);
    int w, h;
    unsigned char *mc = read_png(f, "mc.png", &w, &h), *pp = read_png(f, "pp.png", &w, &h);
    float *exr = read_exr(f, "mc.exr", &w, &h);
    for (long k = 0; k < (long)w * h; k++)
        if (exr[3 * k] > 0 && !is_arrow(mc + 3 * k)) {
            /* the reference at its white level, x = 1: the shoulder gives
             * 0.75 + 0.25 (1 - e^-1) = 0.908, sRGB 244, not a clipped 255 */
            assert_int_equal(mc[3 * k], 244);
            assert_int_equal(pp[3 * k],
                             188); /* below the knee: 255 * (1.055 * 0.5^(1/2.4) - 0.055) */
        }
    char path[1300];
    const char *want[] = {"mc.exr", "mc.png", "pp.exr", "pp.png", "errmap_pp.png"};
    for (int i = 0; i < 5; i++) {
        image_file(f, want[i], path, sizeof path);
        assert_true(exists(path));
    }
    const char *unwanted[] = {"errmap_mc.png", "all.png", "error_pp.png"};
    for (int i = 0; i < 3; i++) {
        image_file(f, unwanted[i], path, sizeof path);
        assert_false(exists(path));
    }
    image_file(f, "", path, sizeof path);
    assert_int_equal(count_named(path, ".tmp"), 0);
    free(mc);
    free(pp);
    free(exr);
    fake_free(f);
}

/* One exposure per view (a shared one saturated the top view): the reference's S1
 * four times as bright as the rest. Each view's white is the reference's 99th percentile in
 * that view, so S1 (most of the top view) and S2 (most of the bottom view) are both white on
 * the reference, and half of each is sRGB(0.5) = 188 on pp. With one exposure for the panel,
 * S2 on pp would be sRGB(1/8) = 99. */
static void test_exposure_per_view(void **state)
{
    (void)state;
    fake *f = fake_new("perview", PPB_GEOM_TUBE);
    for (int i = 0; i < 2; i++) {
        ppb_result *r = &f->ex.res[i];
        for (int s = 0; s < PPB_NSURF; s++)
            for (int k = 0; k < r->layout.nseg[s]; k++)
                for (int b = 0; b < r->layout.nbins; b++)
                    r->radiance[ppb_cell(&r->layout, s, k, b)] =
                        (s == PPB_S1 ? 4.0 : 1.0) * (i == 0 ? 1.0 : 0.5);
    }
    write_images(f);
    int w, h;
    unsigned char *pp = read_png(f, "pp.png", &w, &h);
    ppb_tube_view views[2];
    ppb_err err;
    assert_int_equal(ppb_tube_views_paper(views, &f->cfg.scene, w, h / 2, &err), 0);
    long seen[2] = {0, 0};
    for (int v = 0; v < 2; v++)
        for (int j = 0; j < h / 2; j++)
            for (int x = 0; x < w; x++) {
                ppb_tube_hit hit = ppb_tube_view_hit(&views[v], x + 0.5, j + 0.5);
                const unsigned char *px = pp + 3 * ((long)(j + v * (h / 2)) * w + x);
                if (hit.kind != PPB_PIX_SURFACE || hit.surf != (v ? PPB_S2 : PPB_S1) ||
                    is_arrow(px))
                    continue;
                assert_int_equal(px[0], 188);
                seen[v]++;
            }
    assert_true(seen[0] > 1000 && seen[1] > 1000);
    free(pp);
    fake_free(f);
}

static void test_error_image(void **state)
{
    (void)state;
    fake *f = fake_new("error", PPB_GEOM_TUBE);
    fake_fill(f, 0, 1.0);
    fake_fill(f, 1, 1.0);
    write_images(f);
    int w, h, ew, eh;
    float *exr = read_exr(f, "pp.exr", &w, &h);
    unsigned char *e = read_png(f, "errmap_pp.png", &ew, &eh);
    /* the map, then a 64-pixel strip at its right with the colour bar (images.c: BAR_STRIP),
     * which the bare map lacked: +50% (warm, 180 4 38) at row 40, 0 (neutral, 221) at the
     * middle, -50% (cool, 59 76 192) at row h - 40, in the bar's columns (the map's width + 6
     * on); the colours are the map's own stops (images.c, Moreland's cool-warm) */
    assert_int_equal(ew, w + 64);
    assert_int_equal(eh, h);
    for (long k = 0; k < (long)w * h; k++) {
        const unsigned char *px = e + 3 * (k / w * ew + k % w);
        if (exr[3 * k] > 0)
            assert_true(px[0] == 221 && px[1] == 221 && px[2] == 221);
    }
    const int rows[3] = {40, h / 2, h - 40};
    const unsigned char want[3][3] = {{180, 4, 38}, {221, 221, 221}, {59, 76, 192}};
    for (int i = 0; i < 3; i++) {
        const unsigned char *px = e + 3 * ((long)rows[i] * ew + w + 10);
        assert_memory_equal(px, want[i], 3);
    }
    free(exr);
    free(e);
    fake_free(f);
}

static void test_slab_writes_nothing(void **state)
{
    (void)state;
    fake *f = fake_new("slab", PPB_GEOM_SLAB);
    write_images(f);
    char path[1300];
    image_file(f, "", path, sizeof path);
    assert_false(exists(path));
    fake_free(f);
}

/* Every EXR of an experiment names its method, case, seed, photon budget, version and what it
 * shows (pbrt-v4 writes its settings into its EXRs); without a meta, "unknown". */
static void test_image_exr_metadata(void **state)
{
    (void)state;
    fake *f = fake_new("exrmeta", PPB_GEOM_TUBE);
    fake_fill(f, 0, 0.5);
    fake_fill(f, 1, 0.6);
    const ppb_image_meta meta = {"uniform_g0_normal", "v1.2-3-gabc", 123456789012345LL, 400000000};
    ppb_err err;
    if (ppb_images_write(f->cfg.out_dir, &f->cfg.scene, &meta, f->ex.res, f->ex.n, 0, &err))
        fail_msg("%s", err.msg);
    char path[1300], got[1024];
    const char *methods[2] = {"mc", "pp"};
    for (int i = 0; i < 2; i++) {
        char file[64];
        snprintf(file, sizeof file, "%s.exr", methods[i]);
        image_file(f, file, path, sizeof path);
        exr_string_attr(path, "ppbench.method", got, sizeof got);
        assert_string_equal(got, methods[i]);
        exr_string_attr(path, "ppbench.case", got, sizeof got);
        assert_string_equal(got, "uniform_g0_normal");
        exr_string_attr(path, "ppbench.seed", got, sizeof got);
        assert_string_equal(got, "123456789012345"); /* every digit: a seed is an integer */
        exr_string_attr(path, "ppbench.photons", got, sizeof got);
        assert_string_equal(got, "400000000");
        exr_string_attr(path, "ppbench.version", got, sizeof got);
        assert_string_equal(got, "v1.2-3-gabc");
        exr_string_attr(path, "ppbench.shows", got, sizeof got);
        if (!strstr(got, "radiance") || !strstr(got, "1/sr") || !strstr(got, "S1") ||
            !strstr(got, "S2") || !strstr(got, "S3"))
            fail_msg("ppbench.shows does not say what the image shows: '%s'", got);
    }
    /* No meta: the method is still known, the rest says so. */
    if (ppb_images_write(f->cfg.out_dir, &f->cfg.scene, NULL, f->ex.res, f->ex.n, 0, &err))
        fail_msg("%s", err.msg);
    image_file(f, "pp.exr", path, sizeof path);
    exr_string_attr(path, "ppbench.method", got, sizeof got);
    assert_string_equal(got, "pp");
    exr_string_attr(path, "ppbench.case", got, sizeof got);
    assert_string_equal(got, "unknown");
    exr_string_attr(path, "ppbench.seed", got, sizeof got);
    assert_string_equal(got, "unknown");
    fake_free(f);
}

/* An output directory that cannot be made fails cleanly with a message. */
static void test_unwritable_dir_fails(void **state)
{
    (void)state;
    fake *f = fake_new("unwritable", PPB_GEOM_TUBE);
    FILE *blocker = fopen(f->cfg.out_dir, "w"); /* a file where the directory should be */
    assert_non_null(blocker);
    fclose(blocker);
    ppb_err err = {{0}};
    assert_int_equal(
        ppb_images_write(f->cfg.out_dir, &f->cfg.scene, NULL, f->ex.res, f->ex.n, 0, &err), -1);
    assert_true(strlen(err.msg) > 0);
    fake_free(f);
}

/* ---- colour (ppb_images_write_colour; docs/reference.md: Colour) ---- */

/* A uniform colour field, R, G, B = 0.3, 0.2, 0.1 in every cell of both results: the EXR holds
 * each channel's value on every surface pixel, bit for bit, with the colour attributes; the
 * PNG's surface pixels are the stated tone curve's bytes, computed here from its definition:
 * L_white = the reference's luminance (uniform: its 99th percentile is the value), Y = 0.2126 R
 * + 0.7152 G + 0.0722 B (BT.709), x = L / L_white, so the luminance of x is 1, above the knee
 * 0.75: every channel scaled by s(1) = 0.75 + 0.25 (1 - e^-1), then the sRGB OETF
 * (IEC 61966-2-1: 12.92 x below 0.0031308, 1.055 x^(1/2.4) - 0.055 above). */
static void test_colour_uniform(void **state)
{
    (void)state;
    fake *ch[3];
    const double L[3] = {0.3, 0.2, 0.1};
    const ppb_result *res[3];
    for (int c = 0; c < 3; c++) {
        ch[c] = fake_new("colour_uniform", PPB_GEOM_TUBE);
        fake_fill(ch[c], 0, L[c]);
        fake_fill(ch[c], 1, L[c]);
        res[c] = ch[c]->ex.res;
    }
    const ppb_image_meta meta = {"colour_case", "v9", 7, 1000};
    ppb_err err;
    if (ppb_images_write_colour(ch[0]->cfg.out_dir, &ch[0]->cfg.scene, &meta, "marble", "mm", res,
                                2, 0, &err))
        fail_msg("%s", err.msg);
    int w, h, pw, ph;
    float *exr = read_exr(ch[0], "pp.exr", &w, &h);
    unsigned char *png = read_png(ch[0], "pp.png", &pw, &ph);
    assert_int_equal(pw, w);
    assert_int_equal(ph, h);
    double y = 0.2126 * L[0] + 0.7152 * L[1] + 0.0722 * L[2];
    double s = 0.75 + 0.25 * (1 - exp(-1.0));
    unsigned char want[3];
    for (int c = 0; c < 3; c++) {
        double x = s * L[c] / y;
        x = x > 1 ? 1 : x;
        double e = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1 / 2.4) - 0.055;
        want[c] = (unsigned char)lround(255 * e);
    }
    long lit = 0;
    for (long k = 0; k < (long)w * h; k++) {
        if (exr[3 * k] == 0.0f && exr[3 * k + 1] == 0.0f && exr[3 * k + 2] == 0.0f)
            continue;
        for (int c = 0; c < 3; c++)
            assert_true(exr[3 * k + c] == (float)L[c]);
        if (is_arrow(png + 3 * k))
            continue;
        lit++;
        for (int c = 0; c < 3; c++)
            assert_int_equal(png[3 * k + c], want[c]);
    }
    assert_true(lit > (long)w * h / 5);
    char path[1300], v[512];
    image_file(ch[0], "mc.exr", path, sizeof path);
    exr_string_attr(path, "ppbench.material", v, sizeof v);
    assert_string_equal(v, "marble");
    exr_string_attr(path, "ppbench.units", v, sizeof v);
    assert_string_equal(v, "mm");
    exr_string_attr(path, "ppbench.primaries", v, sizeof v);
    assert_non_null(strstr(v, "Rec. 709"));
    exr_string_attr(path, "ppbench.luminance", v, sizeof v);
    assert_string_equal(v, "Y = 0.2126 R + 0.7152 G + 0.0722 B");
    exr_string_attr(path, "ppbench.exposure", v, sizeof v);
    char white[64];
    snprintf(white, sizeof white, "L_white = %.6g (top view), %.6g (bottom view)", y, y);
    if (!strstr(v, white))
        fail_msg("exposure attribute '%s' lacks '%s'", v, white);
    free(exr);
    free(png);
    for (int c = 0; c < 3; c++)
        fake_free(ch[c]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exr_roundtrip),
        cmocka_unit_test(test_exr_string_attributes),
        cmocka_unit_test(test_png_roundtrip),
        cmocka_unit_test(test_writers_atomic_on_failure),
        cmocka_unit_test(test_camera_projection_analytic),
        cmocka_unit_test(test_camera_cell),
        cmocka_unit_test(test_uniform_field),
        cmocka_unit_test(test_arrow_at_strip),
        cmocka_unit_test(test_segment_field_through_exr),
        cmocka_unit_test(test_shared_exposure_and_files),
        cmocka_unit_test(test_exposure_per_view),
        cmocka_unit_test(test_error_image),
        cmocka_unit_test(test_slab_writes_nothing),
        cmocka_unit_test(test_image_exr_metadata),
        cmocka_unit_test(test_unwritable_dir_fails),
        cmocka_unit_test(test_colour_uniform),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
