#include "model/object.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ppb_object_result_init(ppb_object_result *r, const char *method, int npatch, int nbins,
                           int img_w, int img_h, ppb_err *err)
{
    memset(r, 0, sizeof *r);
    snprintf(r->method, sizeof r->method, "%s", method);
    r->npatch = npatch, r->nbins = nbins, r->img_w = img_w, r->img_h = img_h;
    size_t ncell = (size_t)npatch * (size_t)nbins, npix = (size_t)img_w * (size_t)img_h;
    r->patch_rad = calloc(ncell ? ncell : 1, sizeof *r->patch_rad);
    r->patch_se = calloc(ncell ? ncell : 1, sizeof *r->patch_se);
    r->img = calloc(npix ? npix : 1, sizeof *r->img);
    r->img_se = calloc(npix ? npix : 1, sizeof *r->img_se);
    if (!r->patch_rad || !r->patch_se || !r->img || !r->img_se) {
        ppb_object_result_free(r);
        return ppb_fail(err, "%s: out of memory for %zu patch cells and %zu pixels", method, ncell,
                        npix);
    }
    return 0;
}

void ppb_object_result_free(ppb_object_result *r)
{
    free(r->patch_rad), free(r->patch_se), free(r->img), free(r->img_se), free(r->totals_csv);
    r->patch_rad = r->patch_se = r->img = r->img_se = NULL;
    r->totals_csv = NULL;
}

/* Whether voxel (i, j, k), possibly beyond the grid, holds medium. */
static int inside(const ppb_object *o, int i, int j, int k)
{
    if (i < 0 || j < 0 || k < 0 || i >= o->nx || j >= o->ny || k >= o->nz)
        return 0;
    return o->mat[ppb_object_voxel(o, i, j, k)] != 0;
}

/* The grid's voxel counts along axis a, and along the two in-plane axes u = a + 1, v = a + 2
 * (mod 3), whose order makes (e_u, e_v, e_a) right-handed. */
static int extent(const ppb_object *o, int a)
{
    return a == 0 ? o->nx : a == 1 ? o->ny : o->nz;
}

/* One orientation's faces: for each plane, boundary faces grouped by (u / P, v / P) into
 * patches numbered in (plane, pu, pv) order from *np on. tmp holds one plane's patch ids. */
static int orientation_patches(const ppb_object *o, int a, int side, ppb_object_patches *p,
                               int *cap, int *tmp, ppb_err *err)
{
    int u = (a + 1) % 3, v = (a + 2) % 3, P = o->patch;
    int nu = extent(o, u), nv = extent(o, v), na = extent(o, a);
    int npu = (nu + P - 1) / P, npv = (nv + P - 1) / P;
    double h = o->voxel;
    for (int l = 0; l < na; l++) {
        for (int q = 0; q < npu * npv; q++)
            tmp[q] = -1;
        for (int iu = 0; iu < nu; iu++)
            for (int iv = 0; iv < nv; iv++) {
                int c[3], d[3];
                c[a] = l, c[u] = iu, c[v] = iv;
                d[0] = c[0], d[1] = c[1], d[2] = c[2];
                d[a] += side;
                if (!inside(o, c[0], c[1], c[2]) || inside(o, d[0], d[1], d[2]))
                    continue;
                int q = (iu / P) * npv + iv / P;
                if (tmp[q] < 0) {
                    if (p->npatch == *cap) {
                        int nc = *cap ? 2 * *cap : 256;
                        ppb_object_patch *np = realloc(p->patch, (size_t)nc * sizeof *np);
                        if (!np)
                            return ppb_fail(err, "%s: out of memory for its patches", o->name);
                        p->patch = np, *cap = nc;
                    }
                    tmp[q] = p->npatch++;
                    ppb_object_patch *pa = &p->patch[tmp[q]];
                    memset(pa, 0, sizeof *pa);
                    pa->axis = a, pa->side = side, pa->plane = side > 0 ? l + 1 : l;
                    pa->n[a] = side;
                    pa->t[u] = 1.0;
                }
                ppb_object_patch *pa = &p->patch[tmp[q]];
                pa->c[a] += pa->plane * h;
                pa->c[u] += (iu + 0.5) * h;
                pa->c[v] += (iv + 0.5) * h;
                pa->area += h * h;
                size_t vox = ppb_object_voxel(o, c[0], c[1], c[2]);
                p->face_patch[6 * vox + 2 * (size_t)a + (side > 0)] = tmp[q];
            }
    }
    return 0;
}

int ppb_object_patches_build(const ppb_object *o, ppb_object_patches *p, ppb_err *err)
{
    memset(p, 0, sizeof *p);
    if (o->patch < 1)
        return ppb_fail(err, "%s: patch = %d, at least 1 face", o->name, o->patch);
    size_t nvox = (size_t)o->nx * (size_t)o->ny * (size_t)o->nz;
    int most = o->nx > o->ny ? o->nx : o->ny;
    most = most > o->nz ? most : o->nz;
    int *tmp = malloc((size_t)(most + 1) * (size_t)(most + 1) * sizeof *tmp);
    p->face_patch = malloc(6 * nvox * sizeof *p->face_patch);
    if (!tmp || !p->face_patch) {
        free(tmp);
        ppb_object_patches_free(p);
        return ppb_fail(err, "%s: out of memory for its %zu voxels' faces", o->name, nvox);
    }
    for (size_t f = 0; f < 6 * nvox; f++)
        p->face_patch[f] = -1;
    int cap = 0;
    for (int a = 0; a < 3; a++)
        for (int side = -1; side <= 1; side += 2)
            if (orientation_patches(o, a, side, p, &cap, tmp, err)) {
                free(tmp);
                ppb_object_patches_free(p);
                return -1;
            }
    free(tmp);
    /* Sums of face centres to centroids: each face added h^2 to the area. */
    for (int i = 0; i < p->npatch; i++) {
        double nf = p->patch[i].area / (o->voxel * o->voxel);
        for (int k = 0; k < 3; k++)
            p->patch[i].c[k] /= nf;
    }
    return 0;
}

void ppb_object_patches_free(ppb_object_patches *p)
{
    free(p->patch);
    free(p->face_patch);
    memset(p, 0, sizeof *p);
}
