/* march.c: the march of ss3d and pp3d along a ray through the voxels (pp3d.h; paper Eq. 13 and
 * 15, Fig. 3's rendering process). Along the ray from the exit point p0 into the object, at
 * distance l, q = p0 - l w:
 *     L(p0, w) = integral exp(-d(l)) sigma_t alpha [ e^{-Dpre} R(tau; theta) + C(w) e^{-D} ] dl,
 *     C(w) = p(w.w_L) + b(theta)/abar,   tau = D - Dpre clamped to the local slab,
 * d the optical distance along the ray, theta the angle between w and -w_L (the local slab's
 * normal). ss3d keeps C = p(w.w_L) alone (paper Eq. 5 with n = 1). Each voxel crossing has
 * constant sigma_t and alpha; the direct beam's term is integrated in closed form on D linear
 * between the points where D is read (exact on a crossing where D is linear: any light along an
 * axis), the R term by the midpoint rule on steps of at most pp.step (the tube's R march). */
#include "methods/pp3d/pp3d.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <unistd.h>
#include <stdlib.h>
#include <string.h>

#include "kernels/ppb_bin_samples.h"
#include "base/progress.h"
#include "kernels/ppb_conventions.h"
#include "kernels/ppb_object.h"
#include "methods/pp3d/walk.h"

/* What one ray reads from the tables: its angle node pair and its fixed phase. */
typedef struct ray_dir {
    double p; /* p(w.w_L) */
    int j;    /* angle node below theta */
    double f; /* weight of node j + 1 */
} ray_dir;

static ray_dir ray_dir_of(const ppb_object *o, const ppb_pp3d_tables *tab, const double w[3])
{
    ray_dir r = {0};
    const double *wl = o->light_dir;
    double c = w[0] * wl[0] + w[1] * wl[1] + w[2] * wl[2];
    r.p = ppb_hg_phase(o->g, c);
    if (tab) {
        double th = ppb_pp3d_angle_pos(c, tab->nang);
        r.j = (int)floor(th);
        r.j = r.j < 0 ? 0 : (r.j > tab->nang - 2 ? tab->nang - 2 : r.j);
        r.f = th - r.j;
    }
    return r;
}

/* The albedo nodes' pair and weight at abar (paper Sec. 3.3, interpolated linearly). */
static void albedo_nodes(const ppb_pp3d_tables *t, double abar, int *i, double *f)
{
    *i = 0, *f = 0.0;
    if (t->nalb < 2)
        return;
    double x = (abar - t->alb0) / t->alb_h;
    int k = (int)floor(x);
    k = k < 0 ? 0 : (k > t->nalb - 2 ? t->nalb - 2 : k);
    *i = k;
    *f = fmin(1.0, fmax(0.0, x - k));
}

/* R of thickness node it at tau, bilinear in tau and theta, linear in the albedo nodes. */
static double table_r(const ppb_pp3d_tables *t, int it, int ia, double fa, const ray_dir *rd,
                      double tau)
{
    int ntau = t->ntau[it];
    double x = tau / t->thick[it] * (ntau - 1);
    int k = (int)floor(x);
    k = k < 0 ? 0 : (k > ntau - 2 ? ntau - 2 : k);
    double f = fmin(1.0, fmax(0.0, x - k)), v = 0.0;
    for (int da = 0; da < (fa > 0.0 ? 2 : 1); da++) {
        const double *r0 = t->R + t->off[it] + ((size_t)(ia + da) * t->nang + rd->j) * ntau + k;
        const double *r1 = r0 + ntau;
        double a0 = r0[0] + f * (r0[1] - r0[0]), a1 = r1[0] + f * (r1[1] - r1[0]);
        double a = a0 + rd->f * (a1 - a0);
        v += (da ? fa : 1.0 - fa) * a;
    }
    return v;
}

static double table_cb(const ppb_pp3d_tables *t, int it, int ia, double fa, const ray_dir *rd)
{
    double v = 0.0;
    for (int da = 0; da < (fa > 0.0 ? 2 : 1); da++) {
        const double *c = t->Cb + ((size_t)it * t->nalb + ia + da) * t->nang + rd->j;
        v += (da ? fa : 1.0 - fa) * (c[0] + rd->f * (c[1] - c[0]));
    }
    return v;
}

/* C sigma_t h e^{e_a} phi(z), phi(z) = (e^z - 1)/z: the direct beam's first scattering over a
 * step where both optical depths are linear; the scaled form below e_a = -700 (as
 * kernels/ppb_beam_images.h: ppb_beam_step, which is OpenCL C only). */
static double beam_step(double C, double sigma_t, double h, double e_a, double z)
{
    double phi = fabs(z) < 1e-300 ? 1.0 : expm1(z) / z;
    if (e_a < -700.0 && z > 0.0)
        return C * sigma_t * h * (exp(e_a + z) * (-expm1(-z) / z));
    return C * exp(e_a) * sigma_t * h * phi;
}

/* The map at distance l of a crossing: D and Dpre, by lookup or, on a crossing where both are
 * linear, from its ends. */
typedef struct cross_map {
    const ppb_object *o;
    size_t v;
    int exact;             /* a kinked voxel: D traced at every point */
    double xa[3];          /* the crossing's start */
    const double *Dc, *Pc; /* the voxel's corners */
    double fa[3], fd[3];   /* the crossing's start in the voxel's unit cube, and dir / h */
    double la, len;
    double Da, Db, Pa, Pb;
    int linear;
} cross_map;

static double cross_depth(const cross_map *c, double l, double *pre)
{
    if (c->linear) {
        double f = (l - c->la) / c->len;
        *pre = c->Pa + f * (c->Pb - c->Pa);
        return c->Da + f * (c->Db - c->Da);
    }
    if (c->exact) {
        double x[3];
        for (int a = 0; a < 3; a++)
            x[a] = c->xa[a] + (l - c->la) * c->fd[a] * c->o->voxel;
        return ppb_pp3d_trace(c->o, c->v, x, pre);
    }
    double f[3];
    for (int a = 0; a < 3; a++) {
        double t = c->fa[a] + (l - c->la) * c->fd[a];
        f[a] = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    }
    *pre = ppb_pp3d_trilinear(c->Pc, f);
    return ppb_pp3d_trilinear(c->Dc, f);
}

/* One voxel crossing [la, lb] of voxel v; *d is the optical distance at la, advanced. Per step:
 * the direct beam's first scattering p e^{-D} (and in pp3d the slab's particular part b/abar
 * e^{-D}) in closed form on linear D; pp3d's diffuse modes e^{-Dpre} R(tau) by the midpoint
 * rule, tau = D - Dpre. Where tau leaves the local slab's node [0, tau0] (the node's thickness
 * rounds the voxel's, and a voxel's corners see different chords) it is clamped, and the
 * particular part follows it, b/abar e^{-Dpre - tau}: the source stays the slab's own at a
 * depth it has (an unclamped step is the closed form above: Dpre + tau = D). */
static double crossing(const ppb_object *o, const ppb_pp3d_map *m, const ppb_pp3d_tables *tab,
                       const ray_dir *rd, double step, const double p0[3], const double dir[3],
                       size_t v, double la, double lb, double *d)
{
    double sigma = o->material[o->mat[v]].sigma_t;
    double alpha = o->albedo_tex ? (double)o->albedo_tex[v] : o->material[o->mat[v]].albedo;
    double len = lb - la, d0 = *d;
    *d = d0 + sigma * len;
    if (!(len > 0.0) || alpha <= 0.0)
        return 0.0;
    cross_map c = {.o = o,
                   .v = v,
                   .exact = m->kinked[v],
                   .Dc = m->Dc + 8 * v,
                   .Pc = m->Pc + 8 * v,
                   .la = la,
                   .len = len};
    size_t s = v;
    int idx[3];
    idx[0] = (int)(s % (size_t)o->nx), s /= (size_t)o->nx;
    idx[1] = (int)(s % (size_t)o->ny), idx[2] = (int)(s / (size_t)o->ny);
    for (int a = 0; a < 3; a++) {
        c.xa[a] = p0[a] + la * dir[a];
        c.fa[a] = c.xa[a] / o->voxel - idx[a];
        c.fd[a] = dir[a] / o->voxel;
    }
    double Pm, Dm = cross_depth(&c, la + 0.5 * len, &Pm);
    c.Da = cross_depth(&c, la, &c.Pa);
    c.Db = cross_depth(&c, lb, &c.Pb);
    double tol = 1e-12 * (1.0 + c.Da + c.Db);
    c.linear =
        !c.exact && fabs(Dm - 0.5 * (c.Da + c.Db)) <= tol && fabs(Pm - 0.5 * (c.Pa + c.Pb)) <= tol;
    int ia = 0, it = 0;
    double fa = 0.0, cb = 0.0, tau0 = 0.0;
    if (tab) {
        it = tab->vox_thick[v];
        tau0 = tab->thick[it];
        albedo_nodes(tab, m->abar[v], &ia, &fa);
        cb = table_cb(tab, it, ia, fa, rd);
    }
    /* Steps: one where D is linear over the crossing and no R term is marched, else pp.step. */
    int n = (c.linear && !tab) ? 1 : (int)ceil(len / step);
    n = n < 1 ? 1 : n;
    double h = len / n, sum = 0.0, P1 = c.Pa, D1 = c.Da;
    for (int i = 0; i < n; i++) {
        double d1 = d0 + sigma * h * i;
        if (d1 > PPB_PP3D_D_CAP)
            break;
        double P2 = c.Pb, D2 = i + 1 < n ? cross_depth(&c, la + (i + 1) * h, &P2) : c.Db;
        double t1 = D1 - P1, t2 = D2 - P2;
        int inside = t1 >= 0.0 && t1 <= tau0 && t2 >= 0.0 && t2 <= tau0;
        double C = rd->p + (inside ? cb : 0.0);
        sum += beam_step(C, sigma, h, -(d1 + D1), -(sigma * h + D2 - D1));
        if (tab) {
            double Pmid, Dmid = cross_depth(&c, la + (i + 0.5) * h, &Pmid);
            double tau = Dmid - Pmid;
            tau = tau < 0.0 ? 0.0 : (tau > tau0 ? tau0 : tau);
            double src = table_r(tab, it, ia, fa, rd, tau) + (inside ? 0.0 : cb * exp(-tau));
            sum += sigma * h * exp(-(d1 + 0.5 * sigma * h) - Pmid) * src;
        }
        D1 = D2, P1 = P2;
    }
    return alpha * sum;
}

double ppb_pp3d_ray(const ppb_object *o, const ppb_pp3d_map *m, const ppb_pp3d_tables *tab,
                    double step, const double p0[3], const double w_out[3], long start)
{
    double dir[3] = {-w_out[0], -w_out[1], -w_out[2]};
    ray_dir rd = ray_dir_of(o, tab, w_out);
    ppb_walk w;
    if (!ppb_walk_init(&w, o, p0, dir, start))
        return 0.0;
    size_t v;
    double ta, tb, d = 0.0, L = 0.0;
    while (d <= PPB_PP3D_D_CAP && ppb_walk_next(&w, &v, &ta, &tb))
        if (o->mat[v])
            L += crossing(o, m, tab, &rd, step, p0, dir, v, ta, tb, &d);
    return L;
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* The camera is kernels/ppb_object.h's, as mc3d's kernel and the driver's pixel regions use it
 * (docs/reference.md, Objects): c toward the camera is -view_dir. */
static int camera_make(const ppb_object *o, ppb_obj_camera *cam, ppb_err *err)
{
    double n = sqrt(dot3(o->view_dir, o->view_dir));
    if (!(n > 0.0) || o->img_w < 1 || o->img_h < 1)
        return ppb_fail(err, "%s: the camera needs a view direction and at least one pixel",
                        o->name);
    double c[3] = {-o->view_dir[0] / n, -o->view_dir[1] / n, -o->view_dir[2] / n};
    *cam = ppb_obj_camera_make(c, o->nx * o->voxel, o->ny * o->voxel, o->nz * o->voxel, o->img_w,
                               o->img_h);
    return 0;
}

/* One boundary face's rays, added into its patch's bins (row of nbins): face f = 2 axis +
 * (side > 0) of voxel v, nsamp x nsamp directions per bin in (sin^2 theta, phi) with their
 * weights (the tube's stratified samples, ppb_bin_sample_u: the first and last theta rows
 * graded toward the normal and the tangent plane; reference: Bins, with phi over [0, 2 pi) in
 * the patch's frame), each from its
 * own point of the face. A patch's bin is the mean over its faces and samples:
 * the radiance averaged over the patch's area and the bin (docs/reference.md, Objects). */
static void face_rays(const ppb_object *o, const ppb_object_patch *pa, const ppb_pp3d_map *m,
                      const ppb_pp3d_tables *tab, int nsamp, double step, size_t v, int f,
                      double *row)
{
    double h = o->voxel;
    size_t s = v;
    int idx[3];
    idx[0] = (int)(s % (size_t)o->nx), s /= (size_t)o->nx;
    idx[1] = (int)(s % (size_t)o->ny), idx[2] = (int)(s / (size_t)o->ny);
    int axis = f / 2, side = (f & 1) ? 1 : -1;
    double c[3], nrm[3] = {0.0, 0.0, 0.0}, b[3];
    for (int a = 0; a < 3; a++)
        c[a] = (idx[a] + 0.5) * h;
    c[axis] = (idx[axis] + (side > 0 ? 1.0 : 0.0)) * h;
    nrm[axis] = side;
    cross3(nrm, pa->t, b);
    double wgt = h * h / pa->area / (nsamp * nsamp);
    for (int bin = 0; bin < o->ntheta * o->nphi; bin++) {
        int ith = bin / o->nphi, iph = bin % o->nphi;
        double acc = 0.0;
        for (int sa = 0; sa < nsamp; sa++)
            for (int sb = 0; sb < nsamp; sb++) {
                double u, wk = ppb_bin_sample_u(ith, sa, nsamp, o->ntheta, &u);
                double s2 = (ith + u) / o->ntheta;
                double st = sqrt(s2), ct = sqrt(1.0 - s2);
                double phi = (iph + (sb + 0.5) / nsamp) * 2.0 * PPB_PI / o->nphi;
                double w[3];
                for (int a = 0; a < 3; a++)
                    w[a] = ct * nrm[a] + st * (cos(phi) * pa->t[a] + sin(phi) * b[a]);
                /* Sample (sa, sb) at sub-square (sa, (sa + sb) mod n) of the face's n x n
                 * grid (a Latin square): the face's area is sampled at no extra rays. */
                double q[3] = {c[0], c[1], c[2]};
                q[(axis + 1) % 3] += ((sa + 0.5) / nsamp - 0.5) * h;
                q[(axis + 2) % 3] += (((sa + sb) % nsamp + 0.5) / nsamp - 0.5) * h;
                acc += wk * ppb_pp3d_ray(o, m, tab, step, q, w, (long)v);
            }
        row[bin] += wgt * acc;
    }
}

/* The start of the ray through image point (x, y) (pixel units from the top-left corner):
 * beyond the grid box on the camera's side. */
static void pixel_ray(const ppb_object *o, const ppb_obj_camera *cam, double x, double y,
                      double p0[3])
{
    double pr = cam->r0 + x * cam->pixel, pu = cam->u1 - y * cam->pixel;
    /* along c: past the grid box's centre by the sum of its extents, beyond every corner */
    double ctr[3] = {0.5 * o->nx * o->voxel, 0.5 * o->ny * o->voxel, 0.5 * o->nz * o->voxel};
    double pc = dot3(ctr, cam->c) + o->voxel * (o->nx + o->ny + o->nz);
    for (int a = 0; a < 3; a++)
        p0[a] = pr * cam->r[a] + pu * cam->u[a] + pc * cam->c[a];
}

/* The work of one run, shared by its threads: items [0, npatch) are the patches (each one's
 * faces in voxel order, so a patch's sums do not depend on the threads), then the image's
 * rows. Each item is taken once, through the atomic counter. */
typedef struct render_job {
    const ppb_object *o;
    const ppb_object_patches *p;
    const ppb_pp3d_map *m;
    const ppb_pp3d_tables *tab;
    int nsamp, nsub, with_patches;
    double step;
    const size_t *face_off, *faces; /* patch q's faces: faces[face_off[q] .. face_off[q + 1]) */
    ppb_obj_camera cam;
    double *patch_rad, *img;
    int nitems;
    atomic_int next, done;
} render_job;

static void render_item(render_job *j, int item)
{
    const ppb_object *o = j->o;
    int nbins = o->ntheta * o->nphi, np = j->with_patches ? j->p->npatch : 0;
    if (item < np) {
        for (size_t k = j->face_off[item]; k < j->face_off[item + 1]; k++)
            face_rays(o, &j->p->patch[item], j->m, j->tab, j->nsamp, j->step, j->faces[k] / 6,
                      (int)(j->faces[k] % 6), j->patch_rad + (size_t)item * nbins);
        return;
    }
    /* A pixel: the mean of nsub x nsub rays at the centres of its sub-squares (the radiance
     * averaged over the pixel's area, docs/methods.md). */
    int y = item - np, ns = j->nsub;
    for (int x = 0; x < o->img_w; x++) {
        double acc = 0.0;
        for (int a = 0; a < ns; a++)
            for (int b = 0; b < ns; b++) {
                double p0[3];
                pixel_ray(o, &j->cam, x + (b + 0.5) / ns, y + (a + 0.5) / ns, p0);
                acc += ppb_pp3d_ray(o, j->m, j->tab, j->step, p0, j->cam.c, -1);
            }
        j->img[(size_t)y * o->img_w + x] = acc / (ns * ns);
    }
}

static void *render_worker(void *arg)
{
    render_job *j = arg;
    int item;
    while (!ppb_interrupted() && (item = atomic_fetch_add(&j->next, 1)) < j->nitems) {
        render_item(j, item);
        atomic_fetch_add(&j->done, 1);
    }
    return NULL;
}

/* The threads: the CPUs online, at most PPB_PP3D_MAX_THREADS. */
static int render_threads(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (n > PPB_PP3D_MAX_THREADS ? PPB_PP3D_MAX_THREADS : (int)n);
}

/* Runs the job on the threads, the calling one among them, with progress lines from it. */
static int render_run(render_job *j, const char *label, int quiet, ppb_err *err)
{
    int nt = render_threads();
    pthread_t th[PPB_PP3D_MAX_THREADS];
    int started = 0;
    for (int i = 1; i < nt; i++, started++)
        if (pthread_create(&th[i], NULL, render_worker, j))
            break;
    ppb_progress pr;
    ppb_progress_begin(&pr, label, "items", j->nitems, quiet);
    int item;
    while (!ppb_interrupted() && (item = atomic_fetch_add(&j->next, 1)) < j->nitems) {
        render_item(j, item);
        atomic_fetch_add(&j->done, 1);
        ppb_progress_update(&pr, atomic_load(&j->done));
    }
    for (int i = 1; i <= started; i++)
        pthread_join(th[i], NULL);
    ppb_progress_end(&pr, atomic_load(&j->done));
    if (atomic_load(&j->done) < j->nitems)
        return ppb_fail(err, "%s: %s: interrupted", j->o->name, label);
    return 0;
}

/* Each patch's faces, in voxel order. */
static int patch_faces(const ppb_object *o, const ppb_object_patches *p, size_t **off,
                       size_t **faces, ppb_err *err)
{
    size_t nvox = (size_t)o->nx * o->ny * o->nz, nf = 0;
    *off = calloc((size_t)p->npatch + 1, sizeof **off);
    if (!*off)
        return ppb_fail(err, "%s: out of memory for the patches' faces", o->name);
    for (size_t i = 0; i < 6 * nvox; i++)
        if (p->face_patch[i] >= 0)
            (*off)[p->face_patch[i] + 1]++, nf++;
    for (int q = 0; q < p->npatch; q++)
        (*off)[q + 1] += (*off)[q];
    *faces = malloc((nf ? nf : 1) * sizeof **faces);
    size_t *fill = calloc((size_t)p->npatch + 1, sizeof *fill);
    if (!*faces || !fill) {
        free(fill), free(*off), free(*faces);
        *off = *faces = NULL;
        return ppb_fail(err, "%s: out of memory for the patches' faces", o->name);
    }
    for (size_t i = 0; i < 6 * nvox; i++) {
        int q = p->face_patch[i];
        if (q >= 0)
            (*faces)[(*off)[q] + fill[q]++] = i;
    }
    free(fill);
    return 0;
}

static int render(const ppb_object *o, const ppb_object_patches *p, const ppb_pp3d_map *m,
                  const ppb_pp3d_tables *tab, int nsamp, int nsub, double step, int quiet,
                  const char *label, double *patch_rad, double *img, ppb_err *err)
{
    render_job j = {.o = o,
                    .p = p,
                    .m = m,
                    .tab = tab,
                    .nsamp = nsamp,
                    .nsub = nsub < 1 ? 1 : nsub,
                    .step = step,
                    .with_patches = p != NULL,
                    .patch_rad = patch_rad,
                    .img = img};
    size_t *off = NULL, *faces = NULL;
    if (camera_make(o, &j.cam, err) || (p && patch_faces(o, p, &off, &faces, err)))
        return -1;
    j.face_off = off, j.faces = faces;
    j.nitems = (p ? p->npatch : 0) + o->img_h;
    atomic_init(&j.next, 0);
    atomic_init(&j.done, 0);
    int rc = render_run(&j, label, quiet, err);
    free(off), free(faces);
    return rc;
}

int ppb_pp3d_image(const ppb_object *o, const ppb_pp3d_map *m, const ppb_pp3d_tables *tab, int nsub,
                   double step, double *img, ppb_err *err)
{
    return render(o, NULL, m, tab, 1, nsub, step, 1, "image", NULL, img, err);
}

int ppb_pp3d_render(const ppb_object *o, const ppb_object_patches *p, const ppb_pp3d_map *m,
                    const ppb_pp3d_tables *tab, int nsamp, int nsub, double step, int quiet,
                    ppb_object_result *out, ppb_err *err)
{
    if (render(o, p, m, tab, nsamp, nsub, step, quiet, out->method, out->patch_rad, out->img, err))
        return -1;
    size_t n = (size_t)out->npatch * out->nbins, npix = (size_t)o->img_w * o->img_h, nneg = 0;
    double worst = 0.0;
    for (size_t i = 0; i < n + npix; i++) {
        double *v = i < n ? &out->patch_rad[i] : &out->img[i - n];
        if (!isfinite(*v))
            return ppb_fail(err, "%s: %s: radiance %g at %s %zu", o->name, out->method, *v,
                            i < n ? "patch cell" : "pixel", i < n ? i : i - n);
        if (*v < 0.0) {
            worst = fmin(worst, *v);
            *v = 0.0;
            nneg++;
        }
    }
    /* The slab fields' discrete-ordinates ripples (g near 1) can leave a cell's sum below 0,
     * as in the tube (methods/result_check.h): clamped, and said. */
    if (nneg && !quiet)
        fprintf(stderr, "%s: %s: %zu negative radiance values clamped to 0 (most negative %g)\n",
                o->name, out->method, nneg, worst);
    return 0;
}
