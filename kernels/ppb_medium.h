/* ppb_medium.h: the medium block every kernel receives (reference: Medium, Geometry), for host
 * and kernels.
 *
 * Owns: the one struct that carries the cross-section's size and the piecewise-constant medium
 * (the step's kind and position, both sides' sigma_t and albedo, n, g) into the launch
 * parameters of march.cl, rte2d.cl and mc.cl (embedded as their `med` member), and the medium's
 * values at a point. The host fills it in one place, ppb_medium_of (src/physics/medium.h).
 * `step` here is always the density/albedo/shadow step's kind (PPB_STEP_*); a march's step
 * length is its params' `ds`.
 *
 * Plain C that is also OpenCL C, like ppb_conventions.h. Doubles first, then an even number of
 * ints, so host and device agree on the layout (80 bytes) without packing attributes. */
#ifndef PPB_MEDIUM_H
#define PPB_MEDIUM_H

#include "ppb_conventions.h"

typedef struct ppb_medium {
    double width, height;          /* W (tube only), H, mfp */
    double sigma_t, sigma_t_right; /* left of the step (everywhere but a density step's right) */
    double albedo, albedo_right;   /* left of the step (everywhere but an albedo step's right) */
    double step_x;                 /* the step plane x = step_x (reference: Medium) */
    double n;                      /* refractive index inside (<= 1: no boundary) */
    double g;                      /* Henyey-Greenstein asymmetry */
    int step;                      /* PPB_STEP_*: the step's kind; PPB_STEP_NONE in slab mode */
    int tube;                      /* 1 tube, 0 slab */
} ppb_medium;

/* sigma_t and alpha at x (the right value for x >= step_x, ppb_sigma_t_at). */
PPB_FN double ppb_medium_sigma_t(const ppb_medium *M, double x)
{
    return ppb_sigma_t_at(x, M->step, M->step_x, M->sigma_t, M->sigma_t_right);
}
PPB_FN double ppb_medium_albedo(const ppb_medium *M, double x)
{
    return ppb_albedo_at(x, M->step, M->step_x, M->albedo, M->albedo_right);
}

/* The least sigma_t anywhere: the marches' optical cap d_cap / sigma_min bounds a ray's length. */
PPB_FN double ppb_medium_sigma_min(const ppb_medium *M)
{
    return M->step == PPB_STEP_DENSITY ? fmin(M->sigma_t, M->sigma_t_right) : M->sigma_t;
}

#endif
