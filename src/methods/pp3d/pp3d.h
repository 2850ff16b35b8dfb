/* pp3d.h: the paper's methods on a voxel object (paper Sec. 3.4-3.5, Fig. 3 and 9; docs/methods.md,
 * "pp and ss in three dimensions"): `ss3d`, single scattering marched exactly voxel crossing by
 * voxel crossing, and `pp3d`, the plane-parallel ray marcher, whose source at a march point is
 * the slab solution (physics/ppsolver.h) of the local slab along the light.
 *
 * Owns the light's optical-depth map of an object (the paper's optical density map, average
 * albedo map and, per voxel, the local slab that its furthest-point buffer locates), the
 * direction-by-cosine integral tables of the local slabs, the voxel walk of a ray and the march
 * of the patches' and the camera's rays. Host code; n = 1 only (the paper's Fig. 9 setting). */
#ifndef PPB_PP3D_H
#define PPB_PP3D_H

#include "methods/object_method.h"
#include "model/config.h"

#include <math.h>

/* The two methods as registry entries, and their run functions for a registry that lists
 * entries by value (methods/object_method.h's ppb_object_method_fn). */
extern const ppb_object_method ppb_object_method_ss3d, ppb_object_method_pp3d;
int ppb_pp3d_run_ss3d(ppb_run_ctx *ctx, const ppb_object *o, const ppb_object_patches *p,
                      ppb_object_result *out, ppb_err *err);
int ppb_pp3d_run_pp3d(ppb_run_ctx *ctx, const ppb_object *o, const ppb_object_patches *p,
                      ppb_object_result *out, ppb_err *err);

/* The optical-depth map of one light (paper Sec. 3.4, pre-process steps 2-3 and 5), per medium
 * voxel v of the object (outside voxels hold zeros):
 * - Dc[8 v + c]: D, the optical depth from the surface to corner c (c = cx + 2 cy + 4 cz) along
 *   -w_L, as the limit from inside v (exact: traced through the voxels); inside v, D is their
 *   trilinear interpolation, exact wherever D is linear in v (any light along an axis);
 * - Pc[8 v + c]: the part of Dc in front of the corner's local slab (0 unless the light line
 *   left the medium and came back before it: a shadowing part of a non-convex object), also
 *   interpolated trilinearly, so that D - Dpre, the depth in the local slab, is the
 *   interpolation of the corners' own depths;
 * - tau0[v]: the local slab's optical thickness: the contiguous medium chord along the light line
 *   through v's centre (from where the light last entered to where it next leaves);
 * - abar[v]: the albedo averaged over length along the light from that entry to v's centre
 *   (paper Sec. 3.3);
 * - depth[v]: the geometric distance from that entry to v's centre (the furthest-point buffer's
 *   depth seen from the light);
 * - kinked[v]: 1 when its corners' D or Dpre are not one linear function: light paths through
 *   v enter through different planes (a staircase edge or a shadow edge crosses v), where the
 *   interpolation would smooth a kink; the march traces D exactly there (ppb_pp3d_trace). */
typedef struct ppb_pp3d_map {
    int nx, ny, nz;
    double *Dc, *Pc, *tau0, *abar, *depth;
    unsigned char *kinked;
} ppb_pp3d_map;

/* Bytes the map takes (estimated before it is built). */
double ppb_pp3d_map_bytes(const ppb_object *o);
int ppb_pp3d_map_build(const ppb_object *o, ppb_pp3d_map *m, ppb_err *err);
void ppb_pp3d_map_free(ppb_pp3d_map *m);
/* D (returned) and Dpre at point x of voxel v, traced exactly through the voxels. */
double ppb_pp3d_trace(const ppb_object *o, size_t v, const double x[3], double *pre);
/* The trilinear interpolation of corner values c (c[cx + 2 cy + 4 cz]) at f in the unit cube. */
double ppb_pp3d_trilinear(const double c[8], const double f[3]);
/* D and Dpre at point x inside voxel v (trilinear from its inside-limit corners); pre may be
 * NULL. Returns D. */
double ppb_pp3d_map_depth(const ppb_object *o, const ppb_pp3d_map *m, size_t v, const double x[3],
                          double *pre);

/* The local slabs' tables (paper Eq. 14-15): the slab is lit at normal incidence (its normal is
 * -w_L, mu0 = 1), so a direction enters only by its angle to the light. For every thickness
 * node t, albedo node a, angle node j (ppb_pp3d_angle_node) and tau node i:
 *     R[t][a][j][i] = sum_k A_k(theta_j) e_k(tau_i) + a_lin tau_i,  Cb[t][a][j] = b(theta_j),
 * both per unit albedo of the slab (the march multiplies by the local sigma_s). */
typedef struct ppb_pp3d_tables {
    int nthick, nalb, nang;
    double alb0, alb_h;
    double *thick;  /* [nthick] slab optical thicknesses */
    int *ntau;      /* [nthick] tau nodes, uniform on [0, thick] */
    size_t *off;    /* [nthick] where thickness node t's R block starts */
    double *R, *Cb; /* R as above; Cb [nthick][nalb][nang] */
    int *vox_thick; /* [nvox] the thickness node of each medium voxel */
    int modes, modes_kept;
} ppb_pp3d_tables;

/* Relative spacing of the thickness nodes: the voxels' local slab thicknesses are grouped into
 * runs spanning at most this ratio, each run one node at its geometric middle (a single
 * thickness, as in a box lit along an axis, is its own node, exactly). */
#define PPB_PP3D_THICK_RATIO 1.2
/* Angle nodes: psi, the angle between w and the light's travel w_L (theta = pi - psi), at
 * psi_j = pi (j / (nang - 1))^2, dense toward the forward direction where HG's peak lies
 * (width about 1 - g); linear interpolation in the node coordinate (ppb_pp3d_angle_pos). */
#define PPB_PP3D_NANG 513

static inline double ppb_pp3d_angle_node(int j, int nang)
{
    double v = (double)j / (nang - 1);
    return 3.14159265358979323846 * v * v;
}

/* The node coordinate, in [0, nang - 1], of a direction whose cosine with w_L is c. */
static inline double ppb_pp3d_angle_pos(double c, int nang)
{
    double psi = acos(c < -1.0 ? -1.0 : (c > 1.0 ? 1.0 : c));
    return sqrt(psi / 3.14159265358979323846) * (nang - 1);
}
/* Tau nodes per unit optical depth, as the tube's tables (methods/pp/march.h). */
#define PPB_PP3D_TAU_PER_MFP 64
/* The march's threads at most (it takes the CPUs online up to this). */
#define PPB_PP3D_MAX_THREADS 64
/* The optical distance where a march stops, as the tube's (march.c: d_cap). */
#define PPB_PP3D_D_CAP 40.0

/* Builds the tables; their size, known once the thickness nodes are planned, is checked
 * against memory_limit ([run] memory_limit, GB; base/memory.h) with `held` bytes already
 * held (the map) before they are allocated. */
int ppb_pp3d_tables_build(const ppb_object *o, const ppb_pp3d_map *m, const ppb_pp_settings *pp,
                          double memory_limit, double held, int quiet, ppb_pp3d_tables *t,
                          ppb_err *err);
void ppb_pp3d_tables_free(ppb_pp3d_tables *t);

/* The march of one object: every (patch face, bin, direction sample) ray and every pixel's ray.
 * tab NULL: ss3d (the direct beam's first scattering only). nsamp: direction samples per bin
 * axis (cfg samples_dir); nsub: rays per pixel axis (cfg samples_seg: a pixel is the mean over
 * its area); step: the R march's step (pp.step). */
int ppb_pp3d_render(const ppb_object *o, const ppb_object_patches *p, const ppb_pp3d_map *m,
                    const ppb_pp3d_tables *tab, int nsamp, int nsub, double step, int quiet,
                    ppb_object_result *out, ppb_err *err);

/* The camera's image alone (a frame: what the paper times), img [img_w * img_h]. The march
 * runs on the CPUs online (at most PPB_PP3D_MAX_THREADS threads), patches and image rows
 * shared out one at a time; every sum is one thread's, so results do not depend on them. */
int ppb_pp3d_image(const ppb_object *o, const ppb_pp3d_map *m, const ppb_pp3d_tables *tab, int nsub,
                   double step, double *img, ppb_err *err);

/* The radiance leaving the object at point p0 along w_out (unit), per unit E_perp, marched from
 * p0 along -w_out starting in voxel `start` (or, start < 0, from where the line enters the grid
 * box). The single ray of ppb_pp3d_render, for tests. */
double ppb_pp3d_ray(const ppb_object *o, const ppb_pp3d_map *m, const ppb_pp3d_tables *tab,
                    double step, const double p0[3], const double w_out[3], long start);

#endif
