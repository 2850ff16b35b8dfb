/* images.c: the shaded tube images of an experiment (paper Fig. 6-7; reference: Outputs).
 *
 * Every method's picture is two views of the tube clipped along z (render_tube.h): on top the
 * view from above-left (S1 and S3), underneath the view from below-left (S2 and S3), as the
 * paper's rows are laid out. Each view is VIEW_NX x VIEW_NY pixels. Written under
 * <out_dir>/images/, every file atomically:
 *   <method>.exr        linear 32-bit float RGB, R = G = B = the radiance toward the camera
 *                       (1/sr per unit E_perp); 0 on the background and on the cut caps.
 *   <method>.png        tone-mapped: L / L_white clamped to [0, 1], sRGB-encoded, with ONE
 *                       L_white for all methods: the 99th percentile of the reference's
 *                       (Monte Carlo's) surface pixels, else of the first method's. Background
 *                       slate blue, cut caps brown.
 *   error_<method>.png  for every method but the reference, when there is one: false colour of
 *                       the relative error e = (L_m - L_ref) / L_ref, clamped to +-50%,
 *                       diverging map blue (-50%) .. light grey (0) .. red (+50%); black
 *                       where L_ref <= 0 or L_m is not finite (no relative error). A colour
 *                       bar under the views spans -50% (left edge) to +50% (right edge),
 *                       black ticks every 25%.
 *   all.png             every method's tone-mapped picture side by side, in the experiment's
 *                       order (the order of radiance.csv), same exposure; no labels.
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

#define VIEW_NX      320
#define VIEW_NY      240
#define PANEL_NY     (2 * VIEW_NY)
#define PANEL_PIXELS ((size_t)VIEW_NX * PANEL_NY)
#define SHEET_GAP    4    /* pixels between methods on all.png */
#define BAR_NY       16   /* height of the error colour bar */
#define ERR_CLAMP    0.5  /* relative error at the ends of the colour map */
#define WHITE_PCTL   0.99 /* percentile of the reference's surface pixels shown as white */

typedef unsigned char rgb8[3];

static const rgb8 background = {48, 56, 72};
static const rgb8 cap_colour = {120, 96, 64};
static const rgb8 no_reference = {0, 0, 0};
/* Diverging map end points and middle (Moreland's cool-warm), display-space sRGB. */
static const rgb8 cool = {59, 76, 192}, neutral = {221, 221, 221}, warm = {180, 4, 38};

/* Everything rendered once and shared by the writers. */
typedef struct img_ctx {
    const ppb_scene *scene;
    const ppb_result *res;
    int n;
    char dir[1100];
    unsigned char *kind; /* PPB_PIX_* per panel pixel, the same for every method */
    float **value;       /* per result, n of them */
    int ref;             /* index of the reference result, -1 if none */
    double white;        /* radiance shown as white on every PNG */
} img_ctx;

static void free_ctx(img_ctx *c)
{
    free(c->kind);
    for (int i = 0; c->value && i < c->n; i++)
        free(c->value[i]);
    free(c->value);
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
 * do not darken every picture. */
static double white_level(const img_ctx *c, int from)
{
    float *v = malloc(PANEL_PIXELS * sizeof *v);
    size_t n = 0;
    for (size_t k = 0; v && k < PANEL_PIXELS; k++)
        if (c->kind[k] == PPB_PIX_SURFACE && isfinite(c->value[from][k]))
            v[n++] = c->value[from][k];
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

/* The tone-mapped picture of result i into an RGB buffer of row stride `stride` pixels. */
static void tone_map(const img_ctx *c, int i, unsigned char *rgb, size_t stride)
{
    for (size_t j = 0; j < PANEL_NY; j++)
        for (size_t x = 0; x < VIEW_NX; x++) {
            size_t k = j * VIEW_NX + x;
            unsigned char *px = rgb + 3 * (j * stride + x);
            if (c->kind[k] == PPB_PIX_SURFACE)
                memset(px, srgb_byte(c->value[i][k] / c->white), 3);
            else
                put(px, c->kind[k] == PPB_PIX_CAP ? cap_colour : background);
        }
}

static void image_path(const img_ctx *c, const char *prefix, const char *method, const char *ext,
                       char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s%s.%s", c->dir, prefix, method, ext);
}

static int write_exr(const img_ctx *c, int i, ppb_err *err)
{
    float *rgb = malloc(3 * PANEL_PIXELS * sizeof *rgb);
    if (!rgb)
        return ppb_fail(err, "images: out of memory");
    for (size_t k = 0; k < PANEL_PIXELS; k++)
        rgb[3 * k] = rgb[3 * k + 1] = rgb[3 * k + 2] = c->value[i][k];
    char path[1300];
    image_path(c, "", c->res[i].method, "exr", path, sizeof path);
    int rc = ppb_exr_write_rgb(path, VIEW_NX, PANEL_NY, rgb, err);
    free(rgb);
    return rc;
}

static int write_png(const img_ctx *c, int i, ppb_err *err)
{
    unsigned char *rgb = malloc(3 * PANEL_PIXELS);
    if (!rgb)
        return ppb_fail(err, "images: out of memory");
    tone_map(c, i, rgb, VIEW_NX);
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

/* Ticks at -50, -25, 0, +25, +50 %: the pixel columns nearest each quarter of the bar. */
static int is_tick(int x)
{
    for (int q = 0; q <= 4; q++)
        if (x == q * (VIEW_NX - 1) / 4)
            return 1;
    return 0;
}

static void error_bar(unsigned char *rgb)
{
    for (int x = 0; x < VIEW_NX; x++) {
        double e = ERR_CLAMP * (2.0 * (x + 0.5) / VIEW_NX - 1.0);
        int tick = is_tick(x);
        for (int j = 0; j < BAR_NY; j++) {
            unsigned char *px = rgb + 3 * ((size_t)j * VIEW_NX + (size_t)x);
            if (tick && j < BAR_NY / 2)
                put(px, no_reference);
            else
                error_colour(e, px);
        }
    }
}

static int write_error(const img_ctx *c, int i, ppb_err *err)
{
    size_t ny = PANEL_NY + BAR_NY;
    unsigned char *rgb = malloc(3 * VIEW_NX * ny);
    if (!rgb)
        return ppb_fail(err, "images: out of memory");
    for (size_t k = 0; k < PANEL_PIXELS; k++) {
        unsigned char *px = rgb + 3 * k;
        double ref = c->value[c->ref][k];
        if (c->kind[k] != PPB_PIX_SURFACE)
            put(px, c->kind[k] == PPB_PIX_CAP ? cap_colour : background);
        else if (!(ref > 0) || !isfinite(c->value[i][k]))
            put(px, no_reference);
        else
            error_colour((c->value[i][k] - ref) / ref, px);
    }
    error_bar(rgb + 3 * PANEL_PIXELS);
    char path[1300];
    image_path(c, "error_", c->res[i].method, "png", path, sizeof path);
    int rc = ppb_png_write_rgb(path, VIEW_NX, (int)ny, rgb, err);
    free(rgb);
    return rc;
}

static int write_sheet(const img_ctx *c, ppb_err *err)
{
    int n = c->n;
    size_t nx = (size_t)n * VIEW_NX + (size_t)(n - 1) * SHEET_GAP;
    unsigned char *rgb = malloc(3 * nx * PANEL_NY);
    if (!rgb)
        return ppb_fail(err, "images: out of memory");
    for (size_t k = 0; k < nx * PANEL_NY; k++)
        put(rgb + 3 * k, background);
    for (int i = 0; i < n; i++)
        tone_map(c, i, rgb + 3 * (size_t)i * (VIEW_NX + SHEET_GAP), nx);
    char path[1300];
    snprintf(path, sizeof path, "%s/all.png", c->dir);
    int rc = ppb_png_write_rgb(path, (int)nx, PANEL_NY, rgb, err);
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
    return write_sheet(c, err);
}

int ppb_images_write(const char *out_dir, const ppb_scene *sc, const ppb_result *res, int n,
                     int ref, ppb_err *err)
{
    if (sc->geometry != PPB_GEOM_TUBE || n <= 0)
        return 0;
    img_ctx c = {.scene = sc, .res = res, .n = n, .ref = (ref >= 0 && ref < n) ? ref : -1};
    snprintf(c.dir, sizeof c.dir, "%s/images", out_dir);
    if (ppb_mkdirs(c.dir, err))
        return -1;
    int rc = render_panels(&c, err);
    if (rc == 0) {
        c.white = white_level(&c, c.ref >= 0 ? c.ref : 0);
        rc = write_all(&c, err);
    }
    free_ctx(&c);
    return rc;
}
