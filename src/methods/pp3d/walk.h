/* walk.h: a straight line's voxels in order (Amanatides and Woo 1987, "A fast voxel traversal
 * algorithm"), for the light map's traces and the marches (pp3d.h). Each step yields one voxel of
 * the grid and the line's parameter range [ta, tb] inside it; the line is p + t d, t >= 0. */
#ifndef PPB_PP3D_WALK_H
#define PPB_PP3D_WALK_H

#include <math.h>

#include "model/object.h"

typedef struct ppb_walk {
    const ppb_object *o;
    int i[3], step[3];
    double tmax[3], tdelta[3], t;
} ppb_walk;

/* Starts the walk where the line enters the grid box (t >= 0), in voxel `start` when start >= 0
 * (a point on one of its faces, the line going into it). Returns 0 when the line misses the box. */
static inline int ppb_walk_init(ppb_walk *w, const ppb_object *o, const double p[3],
                                const double d[3], long start)
{
    int n[3] = {o->nx, o->ny, o->nz};
    double h = o->voxel, t0 = 0.0, t1 = INFINITY;
    w->o = o;
    for (int a = 0; a < 3; a++) {
        double lo = 0.0, hi = n[a] * h;
        if (d[a] == 0.0) {
            if (start < 0 && (p[a] < lo || p[a] > hi))
                return 0;
            continue;
        }
        double ta = (lo - p[a]) / d[a], tb = (hi - p[a]) / d[a];
        if (ta > tb) {
            double s = ta;
            ta = tb, tb = s;
        }
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
    }
    if (start >= 0) {
        t0 = 0.0;
        long s = start;
        w->i[0] = (int)(s % o->nx), s /= o->nx;
        w->i[1] = (int)(s % o->ny), w->i[2] = (int)(s / o->ny);
    } else {
        if (!(t0 < t1))
            return 0;
        /* The voxel holding the entry point, nudged along the line past the face it lies on. */
        double tm = t0 + 1e-9 * (t1 - t0);
        for (int a = 0; a < 3; a++) {
            int k = (int)floor((p[a] + tm * d[a]) / h);
            w->i[a] = k < 0 ? 0 : (k >= n[a] ? n[a] - 1 : k);
        }
    }
    w->t = t0;
    for (int a = 0; a < 3; a++) {
        if (d[a] > 0.0) {
            w->step[a] = 1;
            w->tmax[a] = ((w->i[a] + 1) * h - p[a]) / d[a];
            w->tdelta[a] = h / d[a];
        } else if (d[a] < 0.0) {
            w->step[a] = -1;
            w->tmax[a] = (w->i[a] * h - p[a]) / d[a];
            w->tdelta[a] = -h / d[a];
        } else {
            w->step[a] = 0;
            w->tmax[a] = INFINITY;
            w->tdelta[a] = INFINITY;
        }
    }
    return 1;
}

/* The current voxel's flat index and range [ta, tb]; advances. Returns 0 once past the grid. */
static inline int ppb_walk_next(ppb_walk *w, size_t *vox, double *ta, double *tb)
{
    const ppb_object *o = w->o;
    if (w->i[0] < 0 || w->i[1] < 0 || w->i[2] < 0 || w->i[0] >= o->nx || w->i[1] >= o->ny ||
        w->i[2] >= o->nz)
        return 0;
    int a = w->tmax[0] < w->tmax[1] ? (w->tmax[0] < w->tmax[2] ? 0 : 2)
                                    : (w->tmax[1] < w->tmax[2] ? 1 : 2);
    *vox = ppb_object_voxel(o, w->i[0], w->i[1], w->i[2]);
    *ta = w->t;
    *tb = w->tmax[a] > w->t ? w->tmax[a] : w->t;
    w->t = *tb;
    w->i[a] += w->step[a];
    w->tmax[a] += w->tdelta[a];
    return 1;
}

#endif
