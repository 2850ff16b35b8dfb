#include "drivers/object.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/atomic_file.h"
#include "base/clock.h"
#include "drivers/experiment.h"
#include "drivers/provenance.h"
#include "io/image_exr.h"
#include "io/image_png.h"
#include "kernels/ppb_object.h"
#include "methods/object_registry.h"
#include "model/object_build.h"

#define MAX_RES (2 * PPB_MAX_METHODS)

typedef struct obj_run {
    const ppb_config *cfg;
    const char *version;
    ppb_object o;
    ppb_object_patches p;
    int n;
    ppb_object_result res[MAX_RES];
    double seconds[MAX_RES];
    unsigned char *pix_region; /* per pixel: PPB_REGION_INCLUSION where the view meets it */
    char device[512];
    ppb_ocl_versions ocl_versions;
} obj_run;

/* Material at a point of the grid box (0 outside it). */
static int mat_at(const ppb_object *o, const double *x)
{
    int c[3], n[3] = {o->nx, o->ny, o->nz};
    for (int a = 0; a < 3; a++) {
        double f = floor(x[a] / o->voxel);
        if (f < 0 || f >= n[a])
            return -1;
        c[a] = (int)f;
    }
    return o->mat[ppb_object_voxel(o, c[0], c[1], c[2])];
}

/* Whether a ray from x0 along d meets material want (want 0: any medium) inside the grid,
 * sampled every quarter voxel (a region label, not a transport quantity). */
static int ray_meets(const ppb_object *o, const double *x0, const double *d, int want)
{
    double span = o->voxel * (o->nx + o->ny + o->nz), step = 0.25 * o->voxel;
    for (double t = step; t < span; t += step) {
        double x[3] = {x0[0] + t * d[0], x0[1] + t * d[1], x0[2] + t * d[2]};
        int m = mat_at(o, x);
        if (want ? m == want : m > 0)
            return 1;
    }
    return 0;
}

/* The patch a view ray from x (outside the grid) along d first enters the medium through, or
 * -1: an exact voxel traversal (Amanatides & Woo 1987) from the grid box's entry; the face
 * entered is the one crossed by the last step, or the box's face when the ray's first voxel
 * is medium. */
static int visible_patch(const ppb_object *o, const ppb_object_patches *p, const double *x0,
                         const double *d)
{
    int n[3] = {o->nx, o->ny, o->nz}, c[3], step[3], axis = 0;
    double h = o->voxel, lo = -INFINITY, hi = INFINITY, tmax[3], tdelta[3];
    for (int a = 0; a < 3; a++) {
        if (d[a] == 0) {
            if (x0[a] < 0 || x0[a] > n[a] * h)
                return -1;
            continue;
        }
        double t0 = -x0[a] / d[a], t1 = (n[a] * h - x0[a]) / d[a];
        if (fmin(t0, t1) > lo)
            lo = fmin(t0, t1), axis = a;
        hi = fmin(hi, fmax(t0, t1));
    }
    if (!(lo <= hi) || hi <= 0)
        return -1;
    double t = fmax(lo, 0.0);
    for (int a = 0; a < 3; a++) {
        int ci = (int)floor((x0[a] + t * d[a]) / h);
        c[a] = ci < 0 ? 0 : ci >= n[a] ? n[a] - 1 : ci;
        step[a] = d[a] > 0 ? 1 : -1;
        tmax[a] = d[a] == 0 ? INFINITY : ((c[a] + (d[a] > 0)) * h - x0[a]) / d[a];
        tdelta[a] = d[a] == 0 ? INFINITY : h / fabs(d[a]);
    }
    for (;;) {
        size_t v = ppb_object_voxel(o, c[0], c[1], c[2]);
        if (o->mat[v])
            return p->face_patch[6 * v + (size_t)ppb_obj_face(axis, -step[axis])];
        int a = tmax[0] < tmax[1] ? (tmax[0] < tmax[2] ? 0 : 2) : (tmax[1] < tmax[2] ? 1 : 2);
        c[a] += step[a];
        if (c[a] < 0 || c[a] >= n[a])
            return -1;
        tmax[a] += tdelta[a];
        axis = a;
    }
}

/* Regions of every patch (object.h, PPB_REGION_*) and of every pixel: a pixel takes the
 * face, edge, corner and shadow labels of the patch its view ray first enters (through the
 * pixel's centre), and the inclusion's when the ray crosses material 2 anywhere. */
static int label_regions(obj_run *r, ppb_err *err)
{
    const ppb_object *o = &r->o;
    ppb_object_patches *p = &r->p;
    size_t nvox = (size_t)o->nx * o->ny * o->nz;
    for (int i = 0; i < p->npatch; i++)
        p->patch[i].region = 0;
    for (size_t v = 0; v < nvox; v++) {
        int axes = 0;
        for (int a = 0; a < 3; a++)
            axes += p->face_patch[6 * v + 2 * a] >= 0 || p->face_patch[6 * v + 2 * a + 1] >= 0;
        int kind = axes == 1 ? PPB_REGION_FACE : axes == 2 ? PPB_REGION_EDGE : PPB_REGION_CORNER;
        for (int f = 0; f < 6; f++) {
            int q = p->face_patch[6 * v + f];
            if (q >= 0)
                p->patch[q].region |= kind;
        }
    }
    double tl[3] = {-o->light_dir[0], -o->light_dir[1], -o->light_dir[2]};
    for (int i = 0; i < p->npatch; i++) {
        ppb_object_patch *pa = &p->patch[i];
        /* Corner wins over edge over face: a patch is as singular as its worst voxel. */
        if (pa->region & PPB_REGION_CORNER)
            pa->region &= ~(PPB_REGION_EDGE | PPB_REGION_FACE);
        else if (pa->region & PPB_REGION_EDGE)
            pa->region &= ~PPB_REGION_FACE;
        double x[3], in[3] = {-pa->n[0], -pa->n[1], -pa->n[2]};
        for (int k = 0; k < 3; k++)
            x[k] = pa->c[k] + 1e-3 * o->voxel * pa->n[k];
        double cosl = pa->n[0] * tl[0] + pa->n[1] * tl[1] + pa->n[2] * tl[2];
        if (cosl <= 0 || ray_meets(o, x, tl, 0))
            pa->region |= PPB_REGION_SHADOW;
        for (int k = 0; k < 3; k++)
            x[k] = pa->c[k] - 1e-3 * o->voxel * pa->n[k];
        if (o->nmat >= 2 && ray_meets(o, x, in, 2))
            pa->region |= PPB_REGION_INCLUSION;
    }
    size_t npix = (size_t)o->img_w * o->img_h;
    r->pix_region = calloc(npix, 1);
    if (!r->pix_region)
        return ppb_fail(err, "%s: out of memory for the pixels' regions", o->name);
    double c[3] = {-o->view_dir[0], -o->view_dir[1], -o->view_dir[2]};
    ppb_obj_camera cam = ppb_obj_camera_make(c, o->nx * o->voxel, o->ny * o->voxel,
                                             o->nz * o->voxel, o->img_w, o->img_h);
    double far = 2.0 * o->voxel * (o->nx + o->ny + o->nz);
    for (int row = 0; row < o->img_h; row++)
        for (int col = 0; col < o->img_w; col++) {
            double pr = cam.r0 + (col + 0.5) * cam.pixel, pu = cam.u1 - (row + 0.5) * cam.pixel;
            double x[3];
            for (int k = 0; k < 3; k++)
                x[k] = pr * cam.r[k] + pu * cam.u[k] + far * c[k];
            /* every medium voxel along the view ray: does it cross the inclusion? */
            double span = 2 * far, step = 0.25 * o->voxel;
            int hit = 0;
            for (double t = 0; t < span && !hit; t += step) {
                double y[3] = {x[0] + t * o->view_dir[0], x[1] + t * o->view_dir[1],
                               x[2] + t * o->view_dir[2]};
                hit = mat_at(o, y) == 2;
            }
            int q = visible_patch(o, p, x, o->view_dir);
            r->pix_region[(size_t)row * o->img_w + col] =
                (unsigned char)((q >= 0 ? p->patch[q].region & ~PPB_REGION_INCLUSION : 0) |
                                (hit ? PPB_REGION_INCLUSION : 0));
        }
    return 0;
}

static void out_path(const char *dir, const char *file, char *buf, size_t n)
{
    snprintf(buf, n, "%s/%s", dir, file);
}

/* Opens dir/file for writing under its temporary name (base/atomic_file.h). */
static int open_in(const char *dir, const char *file, ppb_afile *af, ppb_err *err)
{
    char path[PPB_PATH_MAX + 128];
    out_path(dir, file, path, sizeof path);
    return ppb_afile_open(af, path, err);
}

/* radiance.csv: one row per (method, patch, bin). */
static int write_radiance(const obj_run *r, const char *dir, ppb_err *err)
{
    ppb_afile af;
    if (open_in(dir, "radiance.csv", &af, err))
        return -1;
    fprintf(af.f,
            "method,patch,axis,side,cx,cy,cz,area,region,bin,theta_bin,phi_bin,radiance,se\n");
    int nb = r->o.ntheta * r->o.nphi;
    for (int m = 0; m < r->n; m++)
        for (int i = 0; i < r->p.npatch; i++) {
            const ppb_object_patch *pa = &r->p.patch[i];
            for (int b = 0; b < nb; b++) {
                size_t c = (size_t)i * nb + b;
                fprintf(af.f, "%s,%d,%d,%d,%.9g,%.9g,%.9g,%.9g,%d,%d,%d,%d,%.9g,%.9g\n",
                        r->res[m].method, i, pa->axis, pa->side, pa->c[0], pa->c[1], pa->c[2],
                        pa->area, pa->region, b, b / r->o.nphi, b % r->o.nphi,
                        r->res[m].patch_rad[c], r->res[m].patch_se[c]);
            }
        }
    return ppb_afile_commit(&af, err);
}

/* RMS of a method against the reference over the cells (patch cells or pixels) of a region:
 * rms = sqrt(mean (x - ref)^2), rel = rms / mean ref, and the reference's mean standard error. */
typedef struct region_stat {
    long count;
    double sq, ref, ref_se;
} region_stat;

static void stat_add(region_stat *s, double x, double ref, double se)
{
    s->count++, s->sq += (x - ref) * (x - ref), s->ref += ref, s->ref_se += se;
}

static void stat_row(FILE *f, const char *method, const char *what, const char *region,
                     const region_stat *s)
{
    double n = s->count ? (double)s->count : 1, rms = sqrt(s->sq / n), mean = s->ref / n;
    fprintf(f, "%s,%s,%s,%ld,%.6g,%.6g,%.6g,%.6g\n", method, what, region, s->count, rms,
            mean > 0 ? rms / mean : 0.0, mean, s->ref_se / n);
}

static const struct {
    const char *name;
    int bit; /* 0: every cell */
} regions[] = {{"all", 0},
               {"faces", PPB_REGION_FACE},
               {"edges", PPB_REGION_EDGE},
               {"corners", PPB_REGION_CORNER},
               {"shadowed", PPB_REGION_SHADOW},
               {"inclusion", PPB_REGION_INCLUSION}};
enum { NREGIONS = sizeof regions / sizeof regions[0] };

/* regions.csv: every method (the reference too, against itself: its noise floor is ref_se)
 * per region, over patch cells and over pixels. */
static int write_regions(const obj_run *r, int ref, const char *dir, ppb_err *err)
{
    ppb_afile af;
    if (open_in(dir, "regions.csv", &af, err))
        return -1;
    fprintf(af.f, "method,over,region,count,rms,rms_rel,ref_mean,ref_se_mean\n");
    int nb = r->o.ntheta * r->o.nphi;
    size_t npix = (size_t)r->o.img_w * r->o.img_h;
    const ppb_object_result *R = &r->res[ref];
    for (int m = 0; m < r->n; m++) {
        const ppb_object_result *X = &r->res[m];
        for (int g = 0; g < NREGIONS; g++) {
            region_stat sp = {0}, sx = {0};
            for (int i = 0; i < r->p.npatch; i++)
                if (!regions[g].bit || (r->p.patch[i].region & regions[g].bit))
                    for (int b = 0; b < nb; b++) {
                        size_t c = (size_t)i * nb + b;
                        stat_add(&sp, X->patch_rad[c], R->patch_rad[c], R->patch_se[c]);
                    }
            stat_row(af.f, X->method, "patches", regions[g].name, &sp);
            for (size_t q = 0; q < npix; q++)
                if ((R->img[q] > 0 || X->img[q] > 0) &&
                    (!regions[g].bit || (r->pix_region[q] & regions[g].bit)))
                    stat_add(&sx, X->img[q], R->img[q], R->img_se[q]);
            stat_row(af.f, X->method, "pixels", regions[g].name, &sx);
        }
    }
    return ppb_afile_commit(&af, err);
}

static int write_small(const obj_run *r, const char *dir, ppb_err *err)
{
    ppb_afile af;
    if (open_in(dir, "timings.csv", &af, err))
        return -1;
    fprintf(af.f, "method,seconds,photons\n");
    for (int m = 0; m < r->n; m++)
        fprintf(af.f, "%s,%.4f,%lld\n", r->res[m].method, r->seconds[m], r->res[m].photons);
    if (ppb_afile_commit(&af, err))
        return -1;
    for (int m = 0; m < r->n; m++)
        if (r->res[m].totals_csv) {
            char name[64];
            snprintf(name, sizeof name, "totals_%s.csv", r->res[m].method);
            if (open_in(dir, name, &af, err))
                return -1;
            fputs(r->res[m].totals_csv, af.f);
            if (ppb_afile_commit(&af, err))
                return -1;
        }
    if (open_in(dir, "config.ini", &af, err))
        return -1;
    ppb_config_write_ini(r->cfg, af.f);
    if (ppb_afile_commit(&af, err))
        return -1;
    if (open_in(dir, "provenance.txt", &af, err))
        return -1;
    char when[64];
    time_t now = time(NULL);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    fprintf(af.f, "%s: what produced the files beside this one\n", ppb_provenance_mark);
    fprintf(af.f, "ppbench.version = %s\nconfig.path = %s\ndate = %s\ncommand = object\n",
            r->version, r->cfg->path, when);
    fprintf(af.f, "device = %s\n", r->device[0] ? r->device : "(none)");
    ppb_provenance_write_build(af.f, r->device[0] ? &r->ocl_versions : NULL);
    fprintf(af.f,
            "object.voxels_total = %d x %d x %d\nobject.materials = %d\nobject.patches = %d\n",
            r->o.nx, r->o.ny, r->o.nz, r->o.nmat, r->p.npatch);
    for (int m = 0; m < r->n; m++) {
        if (r->res[m].photons)
            fprintf(af.f, "%s.photons_traced = %lld\n", r->res[m].method, r->res[m].photons);
        fprintf(af.f, "%s.seconds = %.4f\n", r->res[m].method, r->seconds[m]);
    }
    ppb_config_write_readable(r->cfg, af.f);
    return ppb_afile_commit(&af, err);
}

/* One grey image: linear EXR (R = G = B = the value) and an sRGB PNG of value / scale. */
static int write_image(const char *dir, const char *name, const double *img, int w, int h,
                       double scale, int signed_map, const ppb_exr_attr *attrs, int nattrs,
                       ppb_err *err)
{
    size_t n = (size_t)w * h;
    float *rgb = malloc(3 * n * sizeof *rgb);
    unsigned char *png = malloc(3 * n);
    if (!rgb || !png) {
        free(rgb), free(png);
        return ppb_fail(err, "images: out of memory");
    }
    for (size_t i = 0; i < n; i++) {
        double v = img[i], x = scale > 0 ? v / scale : 0;
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = (float)v;
        if (signed_map) { /* red where above the reference, blue below, white = 0 */
            double a = fmin(fabs(x), 1.0);
            unsigned char lo = (unsigned char)lround(255 * (1 - a));
            png[3 * i] = x > 0 ? 255 : lo, png[3 * i + 1] = lo, png[3 * i + 2] = x < 0 ? 255 : lo;
        } else {
            double s = fmin(fmax(x, 0.0), 1.0);
            s = s <= 0.0031308 ? 12.92 * s : 1.055 * pow(s, 1 / 2.4) - 0.055;
            png[3 * i] = png[3 * i + 1] = png[3 * i + 2] = (unsigned char)lround(255 * s);
        }
    }
    char path[PPB_PATH_MAX + 128];
    snprintf(path, sizeof path, "%s/images/%s.exr", dir, name);
    int rc = ppb_exr_write_rgb(path, w, h, rgb, attrs, nattrs, err);
    snprintf(path, sizeof path, "%s/images/%s.png", dir, name);
    if (rc == 0)
        rc = ppb_png_write_rgb(path, w, h, png, err);
    free(rgb), free(png);
    return rc;
}

static int write_images(const obj_run *r, int ref, const char *dir, ppb_err *err)
{
    char path[PPB_PATH_MAX + 64];
    out_path(dir, "images", path, sizeof path);
    if (ppb_mkdirs(path, err))
        return -1;
    int w = r->o.img_w, h = r->o.img_h;
    size_t n = (size_t)w * h;
    /* One exposure for every method: the reference's brightest pixel maps to white. */
    double peak = 0;
    for (size_t q = 0; q < n; q++)
        peak = fmax(peak, r->res[ref].img[q]);
    double *diff = malloc(n * sizeof *diff);
    if (!diff)
        return ppb_fail(err, "images: out of memory");
    int rc = 0;
    for (int m = 0; m < r->n && rc == 0; m++) {
        ppb_exr_attr at[3] = {{"ppbench.method", r->res[m].method},
                              {"ppbench.case", r->cfg->name},
                              {"ppbench.version", r->version}};
        rc = write_image(dir, r->res[m].method, r->res[m].img, w, h, peak, 0, at, 3, err);
        if (rc || m == ref)
            continue;
        char name[64];
        snprintf(name, sizeof name, "%s_error", r->res[m].method);
        for (size_t q = 0; q < n; q++)
            diff[q] = r->res[m].img[q] - r->res[ref].img[q];
        at[0].value = name;
        /* Error images: signed, method - reference, the PNG at +-10 % of the peak. */
        rc = write_image(dir, name, diff, w, h, 0.1 * peak, 1, at, 3, err);
    }
    free(diff);
    return rc;
}

static int write_set(const obj_run *r, const ppb_adir *ad, ppb_err *err)
{
    int ref = 0;
    const ppb_object_method *rm = ppb_object_method_reference();
    for (int m = 0; m < r->n; m++)
        if (rm && strcmp(r->res[m].method, rm->id) == 0)
            ref = m;
    char path[PPB_PATH_MAX + 64];
    out_path(ad->tmp, "object.vox", path, sizeof path);
    if (write_radiance(r, ad->tmp, err) || write_regions(r, ref, ad->tmp, err) ||
        write_small(r, ad->tmp, err) || ppb_object_write_voxels(&r->o, path, err) ||
        write_images(r, ref, ad->tmp, err))
        return -1;
    return 0;
}

/* A result must hold no NaN, inf or negative radiance (docs/reference.md, Objects). */
static int check_result(const ppb_object_result *x, ppb_err *err)
{
    size_t nc = (size_t)x->npatch * x->nbins, np = (size_t)x->img_w * x->img_h;
    for (size_t i = 0; i < nc; i++)
        if (!isfinite(x->patch_rad[i]) || x->patch_rad[i] < 0 || !isfinite(x->patch_se[i]))
            return ppb_fail(err, "%s: patch cell %zu holds %g (+- %g): not written", x->method, i,
                            x->patch_rad[i], x->patch_se[i]);
    for (size_t i = 0; i < np; i++)
        if (!isfinite(x->img[i]) || x->img[i] < 0 || !isfinite(x->img_se[i]))
            return ppb_fail(err, "%s: pixel %zu holds %g: not written", x->method, i, x->img[i]);
    return 0;
}

int ppb_object_command(const ppb_config *cfg, const char *device, int quiet, const char *version,
                       ppb_err *err)
{
    if (ppb_object_methods_check(cfg, err))
        return 2;
    if (cfg->scene.n != 1.0) {
        ppb_config_key_fail(cfg, "medium", "n", err,
                            "objects take n = 1 only (the paper's Fig. 9 setting; "
                            "docs/reference.md, Objects), not %g",
                            cfg->scene.n);
        return 2;
    }
    ppb_adir ad;
    if (ppb_out_claim(cfg->out_dir, ppb_provenance_mark, &ad, err))
        return 2;
    static obj_run r;
    memset(&r, 0, sizeof r);
    r.cfg = cfg, r.version = version;
    if (ppb_object_build(cfg, &r.o, err))
        return 2;
    int code = 1;
    ppb_run_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.cfg = cfg, ctx.device_selector = device, ctx.quiet = quiet;
    if (ppb_object_patches_build(&r.o, &r.p, err) || label_regions(&r, err))
        goto out;
    /* The reference first, whatever the list's order: the others are scored against it. */
    const ppb_object_method *order[PPB_MAX_METHODS];
    int nm = 0;
    const ppb_object_method *rm = ppb_object_method_reference();
    for (int i = 0; i < cfg->nmethods; i++)
        if (ppb_object_method_find(cfg->methods[i]) == rm)
            order[nm++] = rm;
    if (nm == 0) {
        ppb_config_key_fail(cfg, "experiment", "methods", err,
                            "objects are scored against %s: name it among the methods", rm->id);
        code = 2;
        goto out;
    }
    for (int i = 0; i < cfg->nmethods; i++)
        if (ppb_object_method_find(cfg->methods[i]) != rm)
            order[nm++] = ppb_object_method_find(cfg->methods[i]);
    int nb = r.o.ntheta * r.o.nphi;
    for (int i = 0; i < nm; i++) {
        const ppb_object_method *m = order[i];
        int k = m->also ? 2 : 1;
        for (int j = 0; j < k; j++)
            if (ppb_object_result_init(&r.res[r.n + j], j ? m->also : m->id, r.p.npatch, nb,
                                       r.o.img_w, r.o.img_h, err))
                goto out;
        double t0 = ppb_now();
        int st = m->run(&ctx, &r.o, &r.p, &r.res[r.n], err);
        if (st) {
            r.n += k;
            goto out;
        }
        for (int j = 0; j < k; j++) {
            r.seconds[r.n + j] = ppb_now() - t0;
            if (check_result(&r.res[r.n + j], err)) {
                r.n += k;
                goto out;
            }
        }
        r.n += k;
        if (!quiet)
            fprintf(stderr, "%s: %s: %.2f s\n", cfg->name, m->id, ppb_now() - t0);
    }
    if (ctx.ocl_open) {
        snprintf(r.device, sizeof r.device, "%s", ctx.ocl.name);
        ppb_ocl_versions_get(&ctx.ocl, &r.ocl_versions);
    }
    if (ppb_adir_begin(&ad, err))
        goto out;
    if (write_set(&r, &ad, err)) {
        ppb_adir_abort(&ad);
        goto out;
    }
    if (ppb_adir_commit(&ad, err))
        goto out;
    code = 0;
out:
    for (int i = 0; i < r.n; i++)
        ppb_object_result_free(&r.res[i]);
    free(r.pix_region);
    ppb_object_patches_free(&r.p);
    ppb_object_free(&r.o);
    ppb_ctx_close(&ctx);
    return code;
}
