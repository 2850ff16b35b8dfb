/* map.c: the light's optical-depth map of an object (pp3d.h; paper Sec. 3.4). Every value is a
 * trace through the voxels, so each is exact for the voxel medium; the paper's alpha-blending
 * sums the same segments in the light's order. */
#include "methods/pp3d/pp3d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/pp3d/walk.h"

static double voxel_albedo(const ppb_object *o, size_t v)
{
    return o->albedo_tex ? (double)o->albedo_tex[v] : o->material[o->mat[v]].albedo;
}

/* From q, a point of voxel v0, along d: the contiguous medium run from q (optical depth *run,
 * albedo integral *alb, length *len) and what lies beyond it (*beyond, optical depth). */
static void trace_run(const ppb_object *o, size_t v0, const double q[3], const double d[3],
                      double *run, double *alb, double *len, double *beyond)
{
    ppb_walk w;
    size_t v;
    double ta, tb;
    int in_run = 1;
    *run = *alb = *len = *beyond = 0.0;
    if (!ppb_walk_init(&w, o, q, d, (long)v0))
        return;
    while (ppb_walk_next(&w, &v, &ta, &tb)) {
        if (!o->mat[v]) {
            in_run = 0;
            continue;
        }
        double dt = o->material[o->mat[v]].sigma_t * (tb - ta);
        if (in_run) {
            *run += dt;
            *alb += voxel_albedo(o, v) * (tb - ta);
            *len += tb - ta;
        } else {
            *beyond += dt;
        }
    }
}

double ppb_pp3d_map_bytes(const ppb_object *o)
{
    /* Dc and Pc (8 doubles each), tau0, abar, depth and a flag per voxel */
    return (double)o->nx * o->ny * o->nz * (19.0 * sizeof(double) + 1.0);
}

/* Whether eight corner values are those of one linear function (the trilinear form's cross
 * terms vanish): then the voxel's light paths enter through one plane, as far as its corners
 * tell, and D is linear inside. */
static int corners_linear(const double c[8])
{
    double big = 0.0;
    for (int k = 0; k < 8; k++)
        big = fmax(big, fabs(c[k]));
    double tol = 1e-9 * (1.0 + big);
    double cxy = c[3] - c[2] - c[1] + c[0], cxz = c[5] - c[4] - c[1] + c[0];
    double cyz = c[6] - c[4] - c[2] + c[0];
    double cxyz = c[7] - c[6] - c[5] + c[4] - c[3] + c[2] + c[1] - c[0];
    return fabs(cxy) <= tol && fabs(cxz) <= tol && fabs(cyz) <= tol && fabs(cxyz) <= tol;
}

/* Whether D and Dpre traced at the 19 other points of the voxel's 3 x 3 x 3 lattice (edge and
 * face midpoints, centre; nudged inside as the corners) equal the corners' interpolation: a
 * staircase edge whose light paths cross the voxel between its corners shows there. */
static int lattice_linear(const ppb_object *o, const ppb_pp3d_map *m, size_t v, const double *back)
{
    size_t s = v;
    int idx[3];
    idx[0] = (int)(s % (size_t)o->nx), s /= (size_t)o->nx;
    idx[1] = (int)(s % (size_t)o->ny), idx[2] = (int)(s / (size_t)o->ny);
    const double e = 1e-9, fr[3] = {e, 0.5, 1.0 - e};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            for (int c = 0; c < 3; c++) {
                if (a != 1 && b != 1 && c != 1)
                    continue; /* a corner */
                double f[3] = {fr[a], fr[b], fr[c]}, q[3], run, alb, len, pre;
                for (int k = 0; k < 3; k++)
                    q[k] = (idx[k] + f[k]) * o->voxel;
                trace_run(o, v, q, back, &run, &alb, &len, &pre);
                double D = ppb_pp3d_trilinear(m->Dc + 8 * v, f);
                double P = ppb_pp3d_trilinear(m->Pc + 8 * v, f);
                double tol = 1e-9 * (1.0 + fabs(D));
                if (fabs(run + pre - D) > tol || fabs(pre - P) > tol)
                    return 0;
            }
    return 1;
}

double ppb_pp3d_trace(const ppb_object *o, size_t v, const double x[3], double *pre)
{
    double back[3] = {-o->light_dir[0], -o->light_dir[1], -o->light_dir[2]};
    double run, alb, len;
    trace_run(o, v, x, back, &run, &alb, &len, pre);
    return run + *pre;
}

int ppb_pp3d_map_build(const ppb_object *o, ppb_pp3d_map *m, ppb_err *err)
{
    memset(m, 0, sizeof *m);
    m->nx = o->nx, m->ny = o->ny, m->nz = o->nz;
    size_t nvox = (size_t)o->nx * o->ny * o->nz;
    m->Dc = calloc(8 * nvox, sizeof *m->Dc);
    m->Pc = calloc(8 * nvox, sizeof *m->Pc);
    m->tau0 = calloc(nvox, sizeof *m->tau0);
    m->abar = calloc(nvox, sizeof *m->abar);
    m->depth = calloc(nvox, sizeof *m->depth);
    m->kinked = calloc(nvox, sizeof *m->kinked);
    if (!m->Dc || !m->Pc || !m->tau0 || !m->abar || !m->depth || !m->kinked) {
        ppb_pp3d_map_free(m);
        return ppb_fail(err, "%s: out of memory for the light map of %zu voxels", o->name, nvox);
    }
    double h = o->voxel, back[3], fwd[3];
    for (int a = 0; a < 3; a++)
        fwd[a] = o->light_dir[a], back[a] = -o->light_dir[a];
    /* Corners nudged into their voxel by 1e-9 of its edge: the limit from inside to 1e-9 h
     * sigma_t in D. */
    const double e = 1e-9;
    for (int k = 0; k < o->nz; k++)
        for (int j = 0; j < o->ny; j++)
            for (int i = 0; i < o->nx; i++) {
                size_t v = ppb_object_voxel(o, i, j, k);
                if (!o->mat[v])
                    continue;
                for (int c = 0; c < 8; c++) {
                    double q[3] = {(i + ((c & 1) ? 1.0 - e : e)) * h,
                                   (j + ((c & 2) ? 1.0 - e : e)) * h,
                                   (k + ((c & 4) ? 1.0 - e : e)) * h};
                    double run, alb, len, pre;
                    trace_run(o, v, q, back, &run, &alb, &len, &pre);
                    m->Dc[8 * v + c] = run + pre;
                    m->Pc[8 * v + c] = pre;
                }
                m->kinked[v] = !corners_linear(m->Dc + 8 * v) || !corners_linear(m->Pc + 8 * v) ||
                               !lattice_linear(o, m, v, back);
                double q[3] = {(i + 0.5) * h, (j + 0.5) * h, (k + 0.5) * h};
                double run_b, alb_b, len_b, pre, run_f, alb_f, len_f, after;
                trace_run(o, v, q, back, &run_b, &alb_b, &len_b, &pre);
                trace_run(o, v, q, fwd, &run_f, &alb_f, &len_f, &after);
                m->tau0[v] = run_b + run_f;
                m->abar[v] = len_b > 0.0 ? alb_b / len_b : voxel_albedo(o, v);
                m->depth[v] = len_b;
            }
    return 0;
}

void ppb_pp3d_map_free(ppb_pp3d_map *m)
{
    free(m->kinked), free(m->Dc), free(m->Pc), free(m->tau0), free(m->abar), free(m->depth);
    memset(m, 0, sizeof *m);
}

double ppb_pp3d_trilinear(const double c[8], const double f[3])
{
    double x00 = c[0] + f[0] * (c[1] - c[0]), x10 = c[2] + f[0] * (c[3] - c[2]);
    double x01 = c[4] + f[0] * (c[5] - c[4]), x11 = c[6] + f[0] * (c[7] - c[6]);
    double y0 = x00 + f[1] * (x10 - x00), y1 = x01 + f[1] * (x11 - x01);
    return y0 + f[2] * (y1 - y0);
}

double ppb_pp3d_map_depth(const ppb_object *o, const ppb_pp3d_map *m, size_t v, const double x[3],
                          double *pre)
{
    size_t s = v;
    int idx[3];
    idx[0] = (int)(s % (size_t)o->nx), s /= (size_t)o->nx;
    idx[1] = (int)(s % (size_t)o->ny), idx[2] = (int)(s / (size_t)o->ny);
    double f[3];
    for (int a = 0; a < 3; a++) {
        double t = x[a] / o->voxel - idx[a];
        f[a] = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    }
    if (pre)
        *pre = ppb_pp3d_trilinear(m->Pc + 8 * v, f);
    return ppb_pp3d_trilinear(m->Dc + 8 * v, f);
}
