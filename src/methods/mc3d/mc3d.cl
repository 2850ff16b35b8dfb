/* mc3d.cl: the object Monte Carlo's photon transport through a voxel grid (docs/methods.md,
 * mc3d; docs/reference.md, Objects). One work-item traces one photon, in double precision.
 *
 * A photon starts on a plane upstream of the grid, uniformly over the grid box's projection
 * across the light's direction, and flies along it. Free paths are sampled in optical depth
 * tau = -ln u and spent voxel by voxel along the exact voxel traversal (Amanatides & Woo 1987,
 * "A fast voxel traversal algorithm"): sigma_t is constant in a voxel, so the path's optical
 * depth is a sum of sigma_t x chord, and the collision point is found exactly, with no majorant
 * and no null collisions; the same traversal gives the optical depth to the grid's edge that
 * the camera estimator needs. Outside voxels (material 0) are vacuum: a photon crosses them
 * free and may enter the medium again (a concave mesh). n = 1: no refraction, no reflection.
 * At a collision the weight loses w (1 - albedo) (implicit capture), the camera estimator adds
 * w p(w_in . c) exp(-tau(x, c)) to the pixel x projects to (next-event estimation toward the
 * camera direction c), Russian roulette as the tube's mc (mc3d_params.h), then a
 * Henyey-Greenstein direction. Every crossing of a boundary face from medium to vacuum by a
 * scattered photon adds its weight to its face's patch in the exit direction's bin.
 *
 * Random numbers: Philox4x32-10 (Random123) keyed by the seed; photon i's k-th collision uses
 * the counter (i mod 2^32, i / 2^32, k, 0) (free path, HG cosine, azimuth, roulette), its
 * entry point (i mod 2^32, i / 2^32, 0, 1): a photon's path depends on the seed and its index
 * only. Tallies are fixed-point integers (mc3d_params.h): sums independent of the order. */
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable

#include <Random123/philox.h>

#include "mc3d_params.h"
#include "ppb_object.h"

/* A 32-bit word to a uniform in (0, 1), never 0 (log) nor 1. */
inline double mc3d_uniform(uint r)
{
    return ((double)r + 0.5) * 0x1p-32;
}

inline void mc3d_add(__global ulong *p, double x, double scale)
{
    if (x > 0)
        atom_add(p, (ulong)(x * scale + 0.5));
}

/* Where a traversal stands: position, voxel, direction. */
typedef struct mc3d_ray {
    double p[3], d[3];
    int c[3];
} mc3d_ray;

/* Voxel of a point in (or on) the grid box, clamped into the grid. */
inline void mc3d_cell(const ppb_mc3d_params *P, mc3d_ray *r)
{
    int n[3] = {P->nx, P->ny, P->nz};
    for (int a = 0; a < 3; a++) {
        int c = (int)floor(r->p[a] / P->h);
        r->c[a] = c < 0 ? 0 : (c >= n[a] ? n[a] - 1 : c);
    }
}

inline long mc3d_voxel(const ppb_mc3d_params *P, const int *c)
{
    return ((long)c[2] * P->ny + c[1]) * P->nx + c[0];
}

/* Exit tallies of a traversal: the photon's batch, weight and scattering count. */
typedef struct mc3d_exit {
    __global ulong *cells;
    double w;
    int nscat, batch;
} mc3d_exit;

/* Spends optical depth *tau along the ray from its voxel. Returns 1 at a collision (the ray's
 * p and c are the collision's), 0 when the ray leaves the grid (*tau then holds what was left).
 * With ex non-NULL, each crossing out of the medium through a boundary face by a scattered
 * photon (nscat > 0) is tallied in that face's patch. *depth (non-NULL) gains the optical depth
 * crossed. *medium is set when a medium voxel is crossed over a positive length. */
int mc3d_march(const ppb_mc3d_params *P, __global const float *sig, __global const int *faces,
               mc3d_ray *r, double *tau, const mc3d_exit *ex, double *depth, int *medium)
{
    int n[3] = {P->nx, P->ny, P->nz}, step[3];
    double tmax[3], tdelta[3], t = 0.0, h = P->h;
    for (int a = 0; a < 3; a++) {
        if (r->d[a] > 0) {
            step[a] = 1;
            tmax[a] = ((r->c[a] + 1) * h - r->p[a]) / r->d[a];
            tdelta[a] = h / r->d[a];
        } else if (r->d[a] < 0) {
            step[a] = -1;
            tmax[a] = (r->c[a] * h - r->p[a]) / r->d[a];
            tdelta[a] = -h / r->d[a];
        } else {
            step[a] = 0;
            tmax[a] = INFINITY;
            tdelta[a] = INFINITY;
        }
    }
    for (;;) {
        int a = tmax[0] < tmax[1] ? (tmax[0] < tmax[2] ? 0 : 2) : (tmax[1] < tmax[2] ? 1 : 2);
        long v = mc3d_voxel(P, r->c);
        double st = sig[v], seg = fmax(tmax[a] - t, 0.0);
        if (st > 0 && seg > 0 && medium)
            *medium = 1;
        if (st > 0 && *tau < st * seg) {
            t += *tau / st;
            if (depth)
                *depth += *tau;
            *tau = 0;
            for (int k = 0; k < 3; k++)
                r->p[k] += t * r->d[k];
            return 1;
        }
        *tau -= st * seg;
        if (depth)
            *depth += st * seg;
        t = fmax(tmax[a], t);
        if (st > 0 && ex && ex->nscat > 0) {
            int q = faces[6 * v + ppb_obj_face(a, step[a])];
            if (q >= 0) {
                int bin = ppb_obj_bin(a, step[a], r->d[0], r->d[1], r->d[2], P->ntheta, P->nphi);
                size_t cell = (size_t)q * (size_t)(P->ntheta * P->nphi) + (size_t)bin;
                size_t base = (size_t)ex->batch * PPB_MC3D_NTALLY * P->ncells;
                mc3d_add(ex->cells + base + cell, ex->w, PPB_MC3D_SCALE);
                if (ex->nscat == 1)
                    mc3d_add(ex->cells + base + P->ncells + cell, ex->w, PPB_MC3D_SCALE);
            }
        }
        r->c[a] += step[a];
        if (r->c[a] < 0 || r->c[a] >= n[a]) {
            for (int k = 0; k < 3; k++)
                r->p[k] += t * r->d[k];
            return 0;
        }
        tmax[a] += tdelta[a];
    }
}

/* The distance at which the ray from p along d enters the box [0, n h]^3, or -1 if it misses
 * (slab test). */
inline double mc3d_enter_box(const ppb_mc3d_params *P, const double *p, const double *d)
{
    double lo = -INFINITY, hi = INFINITY, ext[3] = {P->nx * P->h, P->ny * P->h, P->nz * P->h};
    for (int a = 0; a < 3; a++) {
        if (d[a] == 0) {
            if (p[a] < 0 || p[a] > ext[a])
                return -1;
            continue;
        }
        double t0 = -p[a] / d[a], t1 = (ext[a] - p[a]) / d[a];
        lo = fmax(lo, fmin(t0, t1));
        hi = fmin(hi, fmax(t0, t1));
    }
    return lo <= hi && hi > 0 ? fmax(lo, 0.0) : -1;
}

/* New direction at cosine mu from d and azimuth with sine sp, cosine cp (MCML's rotation:
 * Wang, Jacques & Zheng 1995, Eq. 3.30-3.31). */
inline void mc3d_turn(double *d, double mu, double sp, double cp)
{
    double st = sqrt(fmax(0.0, 1.0 - mu * mu)), nd[3];
    if (fabs(d[2]) > 0.99999) {
        nd[0] = st * cp, nd[1] = st * sp, nd[2] = (d[2] > 0 ? mu : -mu);
    } else {
        double tmp = sqrt(1.0 - d[2] * d[2]);
        nd[0] = st * (d[0] * d[2] * cp - d[1] * sp) / tmp + d[0] * mu;
        nd[1] = st * (d[1] * d[2] * cp + d[0] * sp) / tmp + d[1] * mu;
        nd[2] = -st * cp * tmp + d[2] * mu;
    }
    double l = 1.0 / sqrt(nd[0] * nd[0] + nd[1] * nd[1] + nd[2] * nd[2]);
    for (int k = 0; k < 3; k++)
        d[k] = nd[k] * l;
}

/* Henyey-Greenstein cosine by inversion (MCML Eq. 3.28). */
inline double mc3d_hg_cos(double g, double u)
{
    if (fabs(g) < 1e-6)
        return 2.0 * u - 1.0;
    double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    return clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

__kernel void ppb_mc3d_kernel(const ppb_mc3d_params P, __global const float *sig,
                              __global const float *alb, __global const int *faces,
                              __global ulong *cells, __global ulong *pixels, __global ulong *totals)
{
    if (get_global_id(0) >= P.count)
        return;
    ulong i = P.first + get_global_id(0);
    philox4x32_key_t key = {{(uint)P.seed, (uint)(P.seed >> 32)}};
    philox4x32_ctr_t ctr = {{(uint)i, (uint)(i >> 32), 0u, 1u}};
    philox4x32_ctr_t rnd = philox4x32(ctr, key);
    mc3d_exit ex = {cells, 1.0, 0, (int)(i % (ulong)P.batches)};
    __global ulong *tot = totals + (size_t)ex.batch * PPB_MC3D_NTOT;
    __global ulong *pix = pixels + (size_t)ex.batch * PPB_MC3D_NTALLY * P.npix;
    mc3d_ray r;
    double u = mc3d_uniform(rnd.v[0]), v = mc3d_uniform(rnd.v[1]);
    for (int k = 0; k < 3; k++) {
        r.p[k] = P.org[k] + u * P.e1[k] + v * P.e2[k];
        r.d[k] = P.light[k];
    }
    double t0 = mc3d_enter_box(&P, r.p, r.d);
    if (t0 < 0)
        return;
    for (int k = 0; k < 3; k++)
        r.p[k] += t0 * r.d[k];
    mc3d_cell(&P, &r);
    ppb_obj_camera cam;
    for (int k = 0; k < 3; k++)
        cam.c[k] = P.cam_c[k], cam.r[k] = P.cam_r[k], cam.u[k] = P.cam_u[k];
    cam.r0 = P.cam_r0, cam.u1 = P.cam_u1, cam.pixel = P.cam_pixel, cam.w = P.img_w, cam.h = P.img_h;
    int hit = 0;
    /* A photon's absorbed weight and events, added to the totals once when it ends (fewer
     * atomic additions; still one rounding per photon, so still order-independent). */
    double absorbed = 0.0;
    ulong events = 0;
    for (uint k = 0;; k++) {
        ctr.v[2] = k, ctr.v[3] = 0u;
        rnd = philox4x32(ctr, key);
        double tau = -log(mc3d_uniform(rnd.v[0]));
        if (!mc3d_march(&P, sig, faces, &r, &tau, &ex, NULL, &hit)) {
            if (hit) {
                mc3d_add(tot + PPB_MC3D_T_ESCAPED, ex.w, PPB_MC3D_SCALE);
                if (ex.nscat == 0) {
                    mc3d_add(tot + PPB_MC3D_T_BALLISTIC, ex.w, PPB_MC3D_SCALE);
                    atom_add(tot + PPB_MC3D_T_HITS, 1UL); /* else counted at its collision */
                }
            }
            break;
        }
        if (ex.nscat == 0)
            atom_add(tot + PPB_MC3D_T_HITS, 1UL);
        long vox = mc3d_voxel(&P, r.c);
        double a = alb[vox];
        absorbed += ex.w * (1.0 - a);
        ex.w *= a;
        ex.nscat++;
        events++;
        /* Next-event estimate toward the camera: the scattered radiance leaving along c,
         * w p(d . c) exp(-tau to the grid's edge), per unit pixel area (applied by the host). */
        long px = ppb_obj_camera_pixel(&cam, r.p[0], r.p[1], r.p[2]);
        if (px >= 0 && ex.w > 0) {
            mc3d_ray cr = r;
            for (int q = 0; q < 3; q++)
                cr.d[q] = P.cam_c[q];
            double inf = INFINITY, depth = 0.0;
            mc3d_march(&P, sig, faces, &cr, &inf, NULL, &depth, NULL);
            double mu = r.d[0] * cr.d[0] + r.d[1] * cr.d[1] + r.d[2] * cr.d[2];
            double c = ex.w * ppb_hg_phase(P.g, mu) * exp(-depth);
            mc3d_add(pix + px, c, PPB_MC3D_PIX_SCALE);
            if (ex.nscat == 1)
                mc3d_add(pix + P.npix + px, c, PPB_MC3D_PIX_SCALE);
        }
        int capped = ex.nscat > PPB_MC3D_EVENT_CAP && ex.w < PPB_MC3D_CAP_WMAX;
        if (ex.w < PPB_MC3D_ROULETTE_W || capped) {
            if (capped)
                atom_add(tot + PPB_MC3D_T_CAPPED, 1UL);
            if (mc3d_uniform(rnd.v[3]) < 1.0 / PPB_MC3D_ROULETTE_M) {
                mc3d_add(tot + PPB_MC3D_T_RGAIN, ex.w * (PPB_MC3D_ROULETTE_M - 1.0),
                         PPB_MC3D_SCALE);
                ex.w *= PPB_MC3D_ROULETTE_M;
            } else {
                mc3d_add(tot + PPB_MC3D_T_RLOSS, ex.w, PPB_MC3D_SCALE);
                break;
            }
        }
        double mu = mc3d_hg_cos(P.g, mc3d_uniform(rnd.v[1]));
        double phi = 2.0 * PPB_PI * mc3d_uniform(rnd.v[2]);
        mc3d_turn(r.d, mu, sin(phi), cos(phi));
    }
    mc3d_add(tot + PPB_MC3D_T_ABSORBED, absorbed, PPB_MC3D_SCALE);
    if (events)
        atom_add(tot + PPB_MC3D_T_EVENTS, events);
}
