/* images.c: the shaded tube images of an experiment (paper Fig. 6-7; reference: Outputs).
 *
 * Every method's picture is two views of the tube clipped along z (render_tube.h): on top the
 * view from above-left (S1 and S3), underneath the view from below-left (S2 and S3), as the
 * paper's rows are laid out. Each view is VIEW_NX x VIEW_NY pixels. Written under
 * <out_dir>/images/, every file atomically:
 *   <method>.exr        linear 32-bit float RGB, R = G = B = the radiance toward the camera
 *                       (1/sr per unit E_perp); 0 on the background and on the cut caps. No
 *                       arrow, no labels: the data. Its header carries string attributes
 *                       (as pbrt-v4 writes its settings into its EXRs): ppbench.method,
 *                       ppbench.case, ppbench.seed, ppbench.photons (mc.photons),
 *                       ppbench.version and ppbench.shows (what the pixels are: quantity,
 *                       unit, the two views and their surfaces).
 *   <method>.png        tone-mapped: x = L / L_white through a shoulder curve, then
 *                       sRGB-encoded. L_white is set PER VIEW and shared by all methods: the
 *                       99th percentile of the reference's (Monte Carlo's, else the first
 *                       method's) surface pixels in that view. The curve is the identity up
 *                       to x = KNEE (0.75) and above it rolls off smoothly (same slope at the
 *                       knee) toward 1, k + (1 - k)(1 - exp(-(x - k) / (1 - k))), so only
 *                       pixels above about 1.8 L_white are pure white. A plain clamp with one
 *                       exposure for the whole picture left much of S1 pure white (about
 *                       36% of S1 pixels) and hid the density step's pattern on S1
 *                       (paper Fig. 7); a method brighter than the reference (pp, mp) clipped
 *                       most of its top view even with one exposure per view (63% of pp's on
 *                       uniform_g0_normal). Below the knee, grey levels compare linearly
 *                       between methods; the top view carries the
 *                       light arrow: the beam's direction w_L drawn in light yellow ending on
 *                       S1 at z = 0 and x = -W/4, or a searchlight's centre (its strip or
 *                       line). Background slate blue, cut caps brown.
 *   errmap_<method>.png for every method but the reference, when there is one: false colour of
 *                       the relative error e = (L_m - L_ref) / L_ref, clamped to +-50%,
 *                       diverging map blue (-50%) .. light grey (0) .. red (+50%), linear in
 *                       sRGB bytes between those three stops; black where L_ref <= 0 or L_m is
 *                       not finite (no relative error). The map is the size of <method>.png;
 *                       a strip of BAR_STRIP pixels at its right holds the colour bar, ticked
 *                       and labelled +50%, +25%, 0, -25%, -50%, so the file reads on its own.
 *                       scripts/plots.sh composes the map (without the strip) into the titled
 *                       error_<method>.png with gnuplot's numbered colour bar, and the
 *                       per-method PNGs into the labelled all.png (reference: Outputs).
 * Nothing is written in slab mode. */
#include "io/images.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"
#include "io/image_exr.h"
#include "io/image_png.h"
#include "io/render_tube.h"
#include "model/colour.h"

#define VIEW_NX      320
#define VIEW_NY      240
#define PANEL_NY     (2 * VIEW_NY)
#define PANEL_PIXELS ((size_t)VIEW_NX * PANEL_NY)
#define ERR_CLAMP    0.5  /* relative error at the ends of the colour map */
#define WHITE_PCTL   0.99 /* percentile of the reference's surface pixels at x = 1 */
#define KNEE         0.75 /* the tone curve is the identity below, a shoulder above */

typedef unsigned char rgb8[3];

static const rgb8 background = {48, 56, 72};
static const rgb8 cap_colour = {120, 96, 64};
static const rgb8 no_reference = {0, 0, 0};
/* Diverging map end points and middle (Moreland's cool-warm), display-space sRGB. */
static const rgb8 arrow_colour = {255, 226, 110};
static const rgb8 cool = {59, 76, 192}, neutral = {221, 221, 221}, warm = {180, 4, 38};

/* Everything rendered once and shared by the writers. */
typedef struct img_ctx {
    const ppb_scene *scene;
    const ppb_image_meta *meta; /* NULL: attributes "unknown" */
    const ppb_result *res;
    int n;
    char dir[1100];
    unsigned char *kind; /* PPB_PIX_* per panel pixel, the same for every method */
    float **value;       /* per result, n of them */
    int ref;             /* index of the reference result, -1 if none */
    double white[2];     /* radiance shown as white, per view (top, bottom) */
    double arrow[2][2];  /* the light arrow on the top view: tail and tip, pixel coordinates */
} img_ctx;

static void free_ctx(img_ctx *c)
{
    free(c->kind);
    for (int i = 0; c->value && i < c->n; i++)
        free(c->value[i]);
    free(c->value);
}

/* Where the light arrow meets S1 (ppb_scene_lit_range): a searchlight's centre, else -W/4. */
static double arrow_x(const ppb_scene *sc)
{
    if (!ppb_scene_searchlight(sc))
        return -0.25 * sc->width;
    double lo, hi;
    ppb_scene_lit_range(sc, &lo, &hi);
    return 0.5 * (lo + hi);
}

static int render_panels(img_ctx *c, ppb_err *err)
{
    ppb_tube_view views[2];
    if (ppb_tube_views_paper(views, c->scene, VIEW_NX, VIEW_NY, err))
        return -1;
    c->kind = malloc(PANEL_PIXELS);
    c->value = calloc((size_t)c->n, sizeof *c->value);
    if (!c->kind || !c->value)
        return ppb_fail(err, "images: out of memory");
    /* The light arrow: w_L ending on S1 (y = 0) at z = 0, 0.6 W long (the top view looks down
     * steeply, so the shaft is foreshortened); at x = -W/4 when the whole face (or the part
     * before a shadow step) is lit, at the searchlight's centre (strip or line) otherwise. */
    double w[3], tip[3] = {arrow_x(c->scene), 0, 0}, tail[3];
    ppb_scene_light_dir(c->scene, w);
    for (int k = 0; k < 3; k++)
        tail[k] = tip[k] - 0.6 * c->scene->width * w[k];
    ppb_tube_view_project(&views[0], tail, &c->arrow[0][0], &c->arrow[0][1]);
    ppb_tube_view_project(&views[0], tip, &c->arrow[1][0], &c->arrow[1][1]);
    size_t half = PANEL_PIXELS / 2;
    for (int i = 0; i < c->n; i++) {
        c->value[i] = malloc(PANEL_PIXELS * sizeof(float));
        if (!c->value[i])
            return ppb_fail(err, "images: out of memory");
        ppb_tube_view_render(&views[0], &c->res[i], c->value[i], c->kind);
        ppb_tube_view_render(&views[1], &c->res[i], c->value[i] + half, c->kind + half);
    }
    return 0;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The percentile rather than the maximum, so that a few hot pixels (a bright bin, MC noise)
 * do not darken every picture: of the surface pixels of value[] in the view. */
static double white_of(const img_ctx *c, const float *value, int view)
{
    size_t half = PANEL_PIXELS / 2, k0 = (size_t)view * half;
    float *v = malloc(half * sizeof *v);
    size_t n = 0;
    for (size_t k = k0; v && k < k0 + half; k++)
        if (c->kind[k] == PPB_PIX_SURFACE && isfinite(value[k]))
            v[n++] = value[k];
    double white = 0.0;
    if (n > 0) {
        qsort(v, n, sizeof *v, cmp_float);
        white = v[(size_t)(WHITE_PCTL * (double)(n - 1))];
        if (!(white > 0))
            white = v[n - 1];
    }
    free(v);
    return white > 0 ? white : 1.0;
}

static double white_level(const img_ctx *c, int from, int view)
{
    return white_of(c, c->value[from], view);
}

static unsigned char srgb_byte(double linear)
{
    double x = !(linear > 0) ? 0 : (linear > 1 ? 1 : linear); /* NaN shows black */
    double e = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
    return (unsigned char)lround(255.0 * e);
}

static void put(unsigned char *px, const rgb8 colour)
{
    memcpy(px, colour, 3);
}

/* The shoulder (see the header): identity to KNEE, then exp roll-off toward 1, C1 at KNEE. */
static double shoulder(double x)
{
    if (!(x > KNEE))
        return x;
    return KNEE + (1 - KNEE) * (1 - exp(-(x - KNEE) / (1 - KNEE)));
}

/* The tone-mapped picture of result i into an RGB buffer of row stride `stride` pixels. */
static void tone_map(const img_ctx *c, int i, unsigned char *rgb, size_t stride)
{
    for (size_t j = 0; j < PANEL_NY; j++)
        for (size_t x = 0; x < VIEW_NX; x++) {
            size_t k = j * VIEW_NX + x;
            unsigned char *px = rgb + 3 * (j * stride + x);
            if (c->kind[k] == PPB_PIX_SURFACE)
                memset(px, srgb_byte(shoulder(c->value[i][k] / c->white[j >= VIEW_NY])), 3);
            else
                put(px, c->kind[k] == PPB_PIX_CAP ? cap_colour : background);
        }
}

static void dot(unsigned char *rgb, size_t stride, double x, double y)
{
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            long px = lround(x) + dx, py = lround(y) + dy;
            if (px >= 0 && px < VIEW_NX && py >= 0 && py < VIEW_NY)
                put(rgb + 3 * ((size_t)py * stride + (size_t)px), arrow_colour);
        }
}

static void segment(unsigned char *rgb, size_t stride, const double a[2], const double b[2])
{
    double len = hypot(b[0] - a[0], b[1] - a[1]);
    int steps = (int)ceil(2 * len) + 1;
    for (int k = 0; k <= steps; k++) {
        double t = (double)k / steps;
        dot(rgb, stride, a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
    }
}

/* The light arrow on the top view: a shaft and a head of two strokes at +-25 degrees. */
static void draw_arrow(const img_ctx *c, unsigned char *rgb, size_t stride)
{
    const double *tail = c->arrow[0], *tip = c->arrow[1];
    double dx = tip[0] - tail[0], dy = tip[1] - tail[1], len = hypot(dx, dy);
    if (!(len > 1))
        return;
    segment(rgb, stride, tail, tip);
    double head = 0.25 * len < 12 ? 0.25 * len : 12, ux = dx / len, uy = dy / len;
    for (int sgn = -1; sgn <= 1; sgn += 2) {
        double ca = cos(25 * M_PI / 180), sa = sgn * sin(25 * M_PI / 180);
        double end[2] = {tip[0] - head * (ca * ux - sa * uy), tip[1] - head * (sa * ux + ca * uy)};
        segment(rgb, stride, tip, end);
    }
}

static void image_path(const img_ctx *c, const char *prefix, const char *method, const char *ext,
                       char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s%s.%s", c->dir, prefix, method, ext);
}

/* What every EXR shows, in its ppbench.shows attribute (the header comment above). */
static const char exr_shows[] =
    "radiance toward the camera, 1/sr per unit E_perp (scattered light only), R = G = B; "
    "top half: view from above-left (S1 and S3), bottom half: view from below-left (S2 and "
    "S3), tube clipped to |z| <= 0.4 W; 0 on the background and the cut caps";

static int write_exr(const img_ctx *c, int i, ppb_err *err)
{
    float *rgb = malloc(3 * PANEL_PIXELS * sizeof *rgb);
    if (!rgb)
        return ppb_fail(err, "images: out of memory");
    for (size_t k = 0; k < PANEL_PIXELS; k++)
        rgb[3 * k] = rgb[3 * k + 1] = rgb[3 * k + 2] = c->value[i][k];
    const ppb_image_meta *m = c->meta;
    char seed[32] = "unknown", photons[32] = "unknown";
    if (m) {
        snprintf(seed, sizeof seed, "%lld", m->seed);
        snprintf(photons, sizeof photons, "%lld", m->photons);
    }
    const ppb_exr_attr attrs[] = {
        {"ppbench.method", c->res[i].method},
        {"ppbench.case", m && m->case_name ? m->case_name : "unknown"},
        {"ppbench.seed", seed},
        {"ppbench.photons", photons},
        {"ppbench.version", m && m->version ? m->version : "unknown"},
        {"ppbench.shows", exr_shows},
    };
    char path[1300];
    image_path(c, "", c->res[i].method, "exr", path, sizeof path);
    int rc = ppb_exr_write_rgb(path, VIEW_NX, PANEL_NY, rgb, attrs,
                               (int)(sizeof attrs / sizeof attrs[0]), err);
    free(rgb);
    return rc;
}

static int write_png(const img_ctx *c, int i, ppb_err *err)
{
    unsigned char *rgb = malloc(3 * PANEL_PIXELS);
    if (!rgb)
        return ppb_fail(err, "images: out of memory");
    tone_map(c, i, rgb, VIEW_NX);
    draw_arrow(c, rgb, VIEW_NX);
    char path[1300];
    image_path(c, "", c->res[i].method, "png", path, sizeof path);
    int rc = ppb_png_write_rgb(path, VIEW_NX, PANEL_NY, rgb, err);
    free(rgb);
    return rc;
}

/* Diverging colour of a relative error e, clamped to +-ERR_CLAMP. */
static void error_colour(double e, unsigned char *px)
{
    double t = e / ERR_CLAMP;
    t = t < -1 ? -1 : (t > 1 ? 1 : t);
    const unsigned char *end = t < 0 ? cool : warm;
    double a = fabs(t);
    for (int k = 0; k < 3; k++)
        px[k] = (unsigned char)lround((1 - a) * neutral[k] + a * end[k]);
}

/* The error map's colour bar: a strip BAR_STRIP pixels wide at the right of the map, the
 * colour scale from +ERR_CLAMP (top) to -ERR_CLAMP (bottom) between BAR_TOP and BAR_BOTTOM
 * (rows), ticks and labels at +-ERR_CLAMP, +-ERR_CLAMP / 2 and 0, so the picture reads on its
 * own (scripts/plots.sh shows the map alone, beside gnuplot's own bar, in error_<m>.png). */
#define BAR_STRIP  64
#define BAR_X      (VIEW_NX + 6) /* the bar's first column */
#define BAR_W      12
#define BAR_TOP    40
#define BAR_BOTTOM (PANEL_NY - 40)
#define GLYPH_S    2 /* a 3 x 5 glyph drawn at this scale */

/* A 3 x 5 glyph of the characters the labels use, a row of 3 bits per line (top first). */
static const unsigned char *glyph(char ch)
{
    static const unsigned char g[][5] = {{7, 5, 5, 5, 7}, {7, 1, 7, 4, 7}, {7, 4, 7, 1, 7},
                                         {0, 2, 7, 2, 0}, {0, 0, 7, 0, 0}, {5, 1, 2, 4, 5},
                                         {0, 0, 0, 0, 0}};
    const char *set = "025+-%";
    const char *at = strchr(set, ch);
    return g[at && ch ? at - set : 6];
}

/* text with its top left corner at (x, y) of an image stride pixels wide. */
static void draw_text(unsigned char *rgb, int stride, int x, int y, const char *text)
{
    static const rgb8 ink = {221, 221, 221};
    for (; *text; text++, x += 4 * GLYPH_S) {
        const unsigned char *g = glyph(*text);
        for (int r = 0; r < 5 * GLYPH_S; r++)
            for (int col = 0; col < 3 * GLYPH_S; col++)
                if (g[r / GLYPH_S] & (4 >> (col / GLYPH_S)))
                    put(rgb + 3 * ((size_t)(y + r) * stride + x + col), ink);
    }
}

static void draw_error_bar(unsigned char *rgb, int stride)
{
    for (int y = 0; y < PANEL_NY; y++)
        for (int x = VIEW_NX; x < stride; x++)
            put(rgb + 3 * ((size_t)y * stride + x), background);
    for (int y = BAR_TOP; y <= BAR_BOTTOM; y++) {
        double e = ERR_CLAMP * (1 - 2.0 * (y - BAR_TOP) / (BAR_BOTTOM - BAR_TOP));
        for (int x = BAR_X; x < BAR_X + BAR_W; x++)
            error_colour(e, rgb + 3 * ((size_t)y * stride + x));
    }
    for (int t = 0; t <= 4; t++) {
        int y = BAR_TOP + t * (BAR_BOTTOM - BAR_TOP) / 4;
        for (int x = BAR_X + BAR_W; x < BAR_X + BAR_W + 4; x++)
            put(rgb + 3 * ((size_t)y * stride + x), neutral);
        char label[16];
        double pct = 100 * ERR_CLAMP * (1 - t / 2.0);
        snprintf(label, sizeof label, t == 2 ? "0" : "%+.0f%%", pct);
        draw_text(rgb, stride, BAR_X + BAR_W + 6, y - 5 * GLYPH_S / 2, label);
    }
}

static int write_error(const img_ctx *c, int i, ppb_err *err)
{
    const int stride = VIEW_NX + BAR_STRIP;
    unsigned char *rgb = malloc(3 * (size_t)stride * PANEL_NY);
    if (!rgb)
        return ppb_fail(err, "images: out of memory");
    for (size_t k = 0; k < PANEL_PIXELS; k++) {
        unsigned char *px = rgb + 3 * (k / VIEW_NX * stride + k % VIEW_NX);
        double ref = c->value[c->ref][k];
        if (c->kind[k] != PPB_PIX_SURFACE)
            put(px, c->kind[k] == PPB_PIX_CAP ? cap_colour : background);
        else if (!(ref > 0) || !isfinite(c->value[i][k]))
            put(px, no_reference);
        else
            error_colour((c->value[i][k] - ref) / ref, px);
    }
    draw_error_bar(rgb, stride);
    char path[1300];
    image_path(c, "errmap_", c->res[i].method, "png", path, sizeof path);
    int rc = ppb_png_write_rgb(path, stride, PANEL_NY, rgb, err);
    free(rgb);
    return rc;
}

static int write_all(const img_ctx *c, ppb_err *err)
{
    for (int i = 0; i < c->n; i++) {
        if (write_exr(c, i, err) || write_png(c, i, err))
            return -1;
        if (c->ref >= 0 && i != c->ref && write_error(c, i, err))
            return -1;
    }
    return 0;
}

int ppb_images_write(const char *out_dir, const ppb_scene *sc, const ppb_image_meta *meta,
                     const ppb_result *res, int n, int ref, ppb_err *err)
{
    if (sc->geometry != PPB_GEOM_TUBE || n <= 0)
        return 0;
    img_ctx c = {
        .scene = sc, .meta = meta, .res = res, .n = n, .ref = (ref >= 0 && ref < n) ? ref : -1};
    snprintf(c.dir, sizeof c.dir, "%s/images", out_dir);
    if (ppb_mkdirs(c.dir, err))
        return -1;
    int rc = render_panels(&c, err);
    if (rc == 0) {
        for (int view = 0; view < 2; view++)
            c.white[view] = white_level(&c, c.ref >= 0 ? c.ref : 0, view);
        rc = write_all(&c, err);
    }
    free_ctx(&c);
    return rc;
}

/* What a colour EXR shows (ppb_images_write_colour). */
static const char exr_shows_colour[] =
    "radiance toward the camera, 1/sr per unit E_perp (scattered light only), R, G, B = the "
    "material's channels; top half: view from above-left (S1 and S3), bottom half: view from "
    "below-left (S2 and S3), tube clipped to |z| <= 0.4 W; 0 on the background and the cut caps";

/* The colour picture of result i of the three channel contexts, as write_png's. */
static void tone_map_colour(const img_ctx *ch, int i, const double white[2], unsigned char *rgb)
{
    for (size_t k = 0; k < PANEL_PIXELS; k++) {
        unsigned char *px = rgb + 3 * k;
        if (ch[0].kind[k] != PPB_PIX_SURFACE) {
            put(px, ch[0].kind[k] == PPB_PIX_CAP ? cap_colour : background);
            continue;
        }
        double x[3], y = 0;
        for (int c = 0; c < 3; c++) {
            x[c] = ch[c].value[i][k] / white[k >= PANEL_PIXELS / 2];
            y += ppb_luma[c] * x[c];
        }
        double scale = y > KNEE ? shoulder(y) / y : 1;
        for (int c = 0; c < 3; c++)
            px[c] = srgb_byte(scale * x[c]);
    }
}

int ppb_images_write_colour(const char *out_dir, const ppb_scene *sc, const ppb_image_meta *meta,
                            const char *material, const char *unit, const ppb_result *const res[3],
                            int n, int ref, ppb_err *err)
{
    if (sc->geometry != PPB_GEOM_TUBE || n <= 0)
        return 0;
    img_ctx ch[3];
    float *lum = NULL, *rgbf = NULL;
    unsigned char *rgb = NULL;
    int rc = 0;
    memset(ch, 0, sizeof ch);
    for (int c = 0; c < 3 && rc == 0; c++) {
        ch[c] = (img_ctx){.scene = sc, .meta = meta, .res = res[c], .n = n, .ref = ref};
        snprintf(ch[c].dir, sizeof ch[c].dir, "%s/images", out_dir);
        rc = render_panels(&ch[c], err);
    }
    if (rc == 0 && ppb_mkdirs(ch[0].dir, err))
        rc = -1;
    lum = malloc(PANEL_PIXELS * sizeof *lum);
    rgbf = malloc(3 * PANEL_PIXELS * sizeof *rgbf);
    rgb = malloc(3 * PANEL_PIXELS);
    if (rc == 0 && (!lum || !rgbf || !rgb))
        rc = ppb_fail(err, "images: out of memory");
    double white[2] = {1, 1};
    if (rc == 0) {
        int from = ref >= 0 && ref < n ? ref : 0;
        for (size_t k = 0; k < PANEL_PIXELS; k++)
            lum[k] =
                (float)(ppb_luma[0] * ch[0].value[from][k] + ppb_luma[1] * ch[1].value[from][k] +
                        ppb_luma[2] * ch[2].value[from][k]);
        for (int view = 0; view < 2; view++)
            white[view] = white_of(&ch[0], lum, view);
    }
    char primaries[160], luminance[96], exposure[256], seed[32] = "unknown",
                                                       photons[32] = "unknown";
    snprintf(primaries, sizeof primaries,
             "Rec. 709 / sRGB, linear (R, G, B: the material table's channels)");
    snprintf(luminance, sizeof luminance, "Y = %.4f R + %.4f G + %.4f B", ppb_luma[0], ppb_luma[1],
             ppb_luma[2]);
    snprintf(exposure, sizeof exposure,
             "PNG: each channel times 1 / L_white, L_white = %.6g (top view), %.6g (bottom view), "
             "the 99th percentile of the reference's luminance; shoulder on the luminance above "
             "0.75, clip to 1, sRGB OETF",
             white[0], white[1]);
    if (meta) {
        snprintf(seed, sizeof seed, "%lld", meta->seed);
        snprintf(photons, sizeof photons, "%lld", meta->photons);
    }
    for (int i = 0; i < n && rc == 0; i++) {
        for (size_t k = 0; k < PANEL_PIXELS; k++)
            for (int c = 0; c < 3; c++)
                rgbf[3 * k + c] = ch[c].value[i][k];
        const ppb_exr_attr attrs[] = {
            {"ppbench.method", res[0][i].method},
            {"ppbench.case", meta && meta->case_name ? meta->case_name : "unknown"},
            {"ppbench.material", material ? material : "unknown"},
            {"ppbench.primaries", primaries},
            {"ppbench.luminance", luminance},
            {"ppbench.units", unit ? unit : "unknown"},
            {"ppbench.exposure", exposure},
            {"ppbench.seed", seed},
            {"ppbench.photons", photons},
            {"ppbench.version", meta && meta->version ? meta->version : "unknown"},
            {"ppbench.shows", exr_shows_colour},
        };
        char path[1300];
        image_path(&ch[0], "", res[0][i].method, "exr", path, sizeof path);
        rc = ppb_exr_write_rgb(path, VIEW_NX, PANEL_NY, rgbf, attrs,
                               (int)(sizeof attrs / sizeof attrs[0]), err);
        if (rc)
            break;
        tone_map_colour(ch, i, white, rgb);
        draw_arrow(&ch[0], rgb, VIEW_NX);
        image_path(&ch[0], "", res[0][i].method, "png", path, sizeof path);
        rc = ppb_png_write_rgb(path, VIEW_NX, PANEL_NY, rgb, err);
    }
    free(lum);
    free(rgbf);
    free(rgb);
    for (int c = 0; c < 3; c++)
        free_ctx(&ch[c]);
    return rc;
}
