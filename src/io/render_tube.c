/* render_tube.c: orthographic camera and ray cast of the clipped tube (see render_tube.h). */
#include "io/render_tube.h"

#include <float.h>
#include <math.h>

#include "kernels/ppb_tube.h"

/* Directions toward the camera of the paper-style views, in world coordinates: from the left
 * (-x) and the front (+z) so the near cap and S3 show, and from above (+y, S1) or below (-y,
 * S2). Elevation ~44 deg, so S1/S2 and S3 are both seen at a useful slant. */
static const double view_above[3] = {-0.6, 0.7, 0.4};
static const double view_below[3] = {-0.6, -0.7, 0.4};

/* Image margin around the projected tube, as a fraction of the fitted extent. */
#define MARGIN 1.08

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static int normalize3(double a[3])
{
    double len = sqrt(dot3(a, a));
    if (!(len > 1e-12))
        return -1;
    for (int k = 0; k < 3; k++)
        a[k] /= len;
    return 0;
}

/* Box bounds per axis: [lo, hi] of x, y, z. */
static void box_bounds(const ppb_tube_view *v, double lo[3], double hi[3])
{
    lo[0] = ppb_face_line(PPB_S3, v->width, v->height);
    hi[0] = ppb_face_line(PPB_S4, v->width, v->height);
    lo[1] = ppb_face_line(PPB_S2, v->width, v->height);
    hi[1] = ppb_face_line(PPB_S1, v->width, v->height);
    lo[2] = -v->half_len;
    hi[2] = v->half_len;
}

/* Scales and centres the image so the projected box's eight corners fit with a margin, square
 * pixels. */
static void fit_image(ppb_tube_view *v)
{
    double lo[3], hi[3];
    box_bounds(v, lo, hi);
    double umin = DBL_MAX, umax = -DBL_MAX, vmin = DBL_MAX, vmax = -DBL_MAX;
    for (int c = 0; c < 8; c++) {
        double p[3] = {(c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1], (c & 4) ? hi[2] : lo[2]};
        double u = dot3(p, v->right), w = dot3(p, v->up);
        umin = fmin(umin, u);
        umax = fmax(umax, u);
        vmin = fmin(vmin, w);
        vmax = fmax(vmax, w);
    }
    v->pixel = MARGIN * fmax((umax - umin) / v->nx, (vmax - vmin) / v->ny);
    v->u0 = 0.5 * (umin + umax) - 0.5 * v->pixel * v->nx;
    v->v0 = 0.5 * (vmin + vmax) + 0.5 * v->pixel * v->ny;
}

int ppb_tube_view_init(ppb_tube_view *v, const ppb_scene *sc, double half_len,
                       const double to_cam[3], int nx, int ny, ppb_err *err)
{
    if (sc->geometry != PPB_GEOM_TUBE)
        return ppb_fail(err, "images: the camera views the tube only");
    if (nx <= 0 || ny <= 0 || !(half_len > 0))
        return ppb_fail(err, "images: bad view %dx%d, half length %g", nx, ny, half_len);
    v->width = sc->width;
    v->height = sc->height;
    v->half_len = half_len;
    v->nx = nx;
    v->ny = ny;
    v->ntheta = sc->ntheta;
    v->nphi = sc->nphi;
    for (int k = 0; k < 3; k++)
        v->to_cam[k] = to_cam[k];
    const double world_up[3] = {0.0, 1.0, 0.0};
    /* right = up x to_cam and up' = to_cam x right make (right, up', to_cam) right-handed. */
    cross3(world_up, to_cam, v->right);
    if (normalize3(v->to_cam) || normalize3(v->right))
        return ppb_fail(err, "images: view direction (%g, %g, %g) is zero or vertical", to_cam[0],
                        to_cam[1], to_cam[2]);
    cross3(v->to_cam, v->right, v->up);
    fit_image(v);
    return 0;
}

int ppb_tube_views_paper(ppb_tube_view views[2], const ppb_scene *sc, int nx, int ny, ppb_err *err)
{
    /* Clipped at 0.4 W each side of z = 0: as deep as the tube is wide, long enough to read as
     * a cut piece of an infinite tube, short enough to leave S1 and S3 large in the frame. */
    double half_len = 0.4 * sc->width;
    if (ppb_tube_view_init(&views[0], sc, half_len, view_above, nx, ny, err))
        return -1;
    return ppb_tube_view_init(&views[1], sc, half_len, view_below, nx, ny, err);
}

void ppb_tube_view_project(const ppb_tube_view *v, const double p[3], double *px, double *py)
{
    *px = (dot3(p, v->right) - v->u0) / v->pixel;
    *py = (v->v0 - dot3(p, v->up)) / v->pixel;
}

/* Which surface a face of the box is: axis 0 (x) lo/hi = S3/S4, axis 1 (y) lo/hi = S2/S1,
 * axis 2 (z) = a cap. */
static ppb_tube_hit face_hit(int axis, int hi_face)
{
    ppb_tube_hit h = {.kind = PPB_PIX_SURFACE, .surf = -1};
    if (axis == 0)
        h.surf = hi_face ? PPB_S4 : PPB_S3;
    else if (axis == 1)
        h.surf = hi_face ? PPB_S1 : PPB_S2;
    else
        h.kind = PPB_PIX_CAP;
    return h;
}

ppb_tube_hit ppb_tube_view_hit(const ppb_tube_view *v, double px, double py)
{
    double lo[3], hi[3];
    box_bounds(v, lo, hi);
    double u = v->u0 + px * v->pixel, w = v->v0 - py * v->pixel;
    /* Start in front of the whole box and travel along -to_cam (slab method). */
    double back = v->width + v->height + 2.0 * v->half_len;
    double o[3], d[3];
    for (int k = 0; k < 3; k++) {
        o[k] = u * v->right[k] + w * v->up[k] + back * v->to_cam[k];
        d[k] = -v->to_cam[k];
    }
    double t_in = -DBL_MAX, t_out = DBL_MAX;
    int in_axis = -1, in_hi = 0;
    for (int k = 0; k < 3; k++) {
        if (fabs(d[k]) < 1e-15) {
            if (o[k] < lo[k] || o[k] > hi[k])
                return (ppb_tube_hit){.kind = PPB_PIX_BACKGROUND, .surf = -1};
            continue;
        }
        double t_lo = (lo[k] - o[k]) / d[k], t_hi = (hi[k] - o[k]) / d[k];
        double t_near = fmin(t_lo, t_hi), t_far = fmax(t_lo, t_hi);
        if (t_near > t_in) {
            t_in = t_near;
            in_axis = k;
            in_hi = d[k] < 0; /* travelling toward -axis enters through the hi face */
        }
        t_out = fmin(t_out, t_far);
    }
    if (in_axis < 0 || t_in > t_out)
        return (ppb_tube_hit){.kind = PPB_PIX_BACKGROUND, .surf = -1};
    ppb_tube_hit h = face_hit(in_axis, in_hi);
    for (int k = 0; k < 3; k++)
        h.p[k] = o[k] + t_in * d[k];
    return h;
}

size_t ppb_tube_view_cell(const ppb_tube_view *v, const ppb_layout *lo, const ppb_tube_hit *h)
{
    int top = h->surf == PPB_S1 || h->surf == PPB_S2;
    /* s along the surface as the reference numbers segments (Geometry): x from -W/2, y from -H. */
    double s = top ? h->p[0] : h->p[1];
    int seg = ppb_segment_at(h->surf, s, lo->nseg[h->surf], v->width, v->height);
    /* The radiance a pixel shows leaves the surface toward the camera, along to_cam. */
    int bin = ppb_dir_bin(h->surf, v->to_cam[0], v->to_cam[1], v->to_cam[2], v->ntheta, v->nphi);
    return ppb_cell(lo, h->surf, seg, bin);
}

void ppb_tube_view_render(const ppb_tube_view *v, const ppb_result *r, float *value,
                          unsigned char *kind)
{
    for (int j = 0; j < v->ny; j++)
        for (int i = 0; i < v->nx; i++) {
            size_t at = (size_t)j * (size_t)v->nx + (size_t)i;
            ppb_tube_hit h = ppb_tube_view_hit(v, i + 0.5, j + 0.5);
            kind[at] = (unsigned char)h.kind;
            value[at] = h.kind == PPB_PIX_SURFACE
                            ? (float)r->radiance[ppb_tube_view_cell(v, &r->layout, &h)]
                            : 0.0f;
        }
}
