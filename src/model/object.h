/* object.h: a three-dimensional object as the object methods see it (docs/reference.md,
 * Objects): a voxel grid of materials inside a box, HG scattering of one g, a directional light,
 * an orthographic camera, the measured quantity per boundary patch and direction bin and per
 * camera pixel. It is the seam between the object's builders and readers (model/object.c), the
 * object methods (methods/object_method.h and their slices) and the `ppbench object` driver.
 *
 * Frame: x, y, z with the grid's corner at the origin; voxel (i, j, k) spans
 * [i h, (i + 1) h] x [j h, (j + 1) h] x [k h, (k + 1) h], h = voxel, and its flat index is
 * (k * ny + j) * nx + i. Lengths are mean free paths of sigma_t = 1 (or mm with unit = mm: then
 * sigma_t is per mm). Outside the medium is vacuum; n = 1 is the paper's Fig. 9 setting. */
#ifndef PPB_OBJECT_H
#define PPB_OBJECT_H

#include <stddef.h>

#include "base/err.h"

/* Materials per object, index 0 being the outside (no medium). */
#define PPB_OBJ_MAX_MAT 8

typedef struct ppb_object_material {
    double sigma_t; /* extinction (1/mfp, or 1/mm) */
    double albedo;
} ppb_object_material;

typedef struct ppb_object {
    char name[64];
    int nx, ny, nz;
    double voxel;       /* voxel edge length h */
    unsigned char *mat; /* [nx * ny * nz] material index, 0 = outside */
    float *albedo_tex;  /* [nx * ny * nz] albedo per voxel overriding the material's, or NULL */
    int nmat;           /* materials 1..nmat are used */
    ppb_object_material material[PPB_OBJ_MAX_MAT];
    double g;            /* Henyey-Greenstein g of the whole object */
    double n;            /* refractive index inside (1: no boundary) */
    double light_dir[3]; /* unit direction the light travels (into the object) */
    double view_dir[3];  /* unit direction the orthographic camera looks along */
    int img_w, img_h;    /* camera pixels; the image spans the grid box's projection */
    int ntheta, nphi;    /* direction bins per patch (phi over [0, 2 pi) in the patch frame) */
    int patch;           /* patch edge in voxel faces: a patch is patch x patch boundary faces */
} ppb_object;

/* A patch: patch x patch boundary faces of one plane and orientation (a boundary face is a face
 * of a medium voxel whose neighbour is outside or beyond the grid). Its frame: n the outward
 * normal (an axis), t the phi = 0 direction, b = n x t; direction bins are ppb_theta_bin's
 * theta bins about n and phi over [0, 2 pi) from t toward b (docs/reference.md, Objects). */
typedef struct ppb_object_patch {
    double c[3];       /* centroid of its faces */
    double n[3], t[3]; /* outward normal and phi = 0 tangent */
    double area;       /* faces x voxel^2 */
    int axis, side;    /* n = side * e_axis, side = +1 or -1 */
    int plane;         /* the face plane's grid index along axis (coordinate plane * voxel) */
    int region;        /* a ppb_object_region, set by whoever labels regions (0 until then) */
} ppb_object_patch;

/* The boundary faces' patches and, for the kernels, where each face's radiance goes. */
typedef struct ppb_object_patches {
    int npatch;
    ppb_object_patch *patch;
    /* face_patch[6 * voxel + f], f = 2 * axis + (side > 0): the patch of that face of that
     * voxel, -1 when it is no boundary face. */
    int *face_patch;
} ppb_object_patches;

/* Enumerates o's boundary faces into patches of o->patch x o->patch faces (patch >= 1), in a
 * fixed order (orientation, plane, then the patch's two in-plane indices), so runs agree. */
int ppb_object_patches_build(const ppb_object *o, ppb_object_patches *p, ppb_err *err);
void ppb_object_patches_free(ppb_object_patches *p);

static inline size_t ppb_object_voxel(const ppb_object *o, int i, int j, int k)
{
    return ((size_t)k * (size_t)o->ny + (size_t)j) * (size_t)o->nx + (size_t)i;
}

/* What every object method produces: radiance per (patch, bin) and per pixel, with standard
 * errors (0 for deterministic methods), scattered light only, per unit irradiance E_perp of
 * the light. Patches are numbered by model/object.c's patching (ppb_object_patches); pixels
 * row-major from the image's top-left corner. */
typedef struct ppb_object_result {
    char method[32];
    int npatch, nbins;
    double *patch_rad, *patch_se; /* [npatch * nbins] */
    int img_w, img_h;
    double *img, *img_se; /* [img_w * img_h]; pixels that see no medium hold 0 */
    double seconds;
    long long photons; /* Monte Carlo photons traced; 0 otherwise */
    /* A method's own totals, or NULL: one CSV header line and one row (malloc'd; the Monte
     * Carlo's photons and energy balance), which the driver writes as totals_<method>.csv. */
    char *totals_csv;
} ppb_object_result;

int ppb_object_result_init(ppb_object_result *r, const char *method, int npatch, int nbins,
                           int img_w, int img_h, ppb_err *err);
void ppb_object_result_free(ppb_object_result *r);

#endif
