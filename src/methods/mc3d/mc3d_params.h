/* mc3d_params.h: what the object Monte Carlo's kernel (mc3d.cl) receives, shared by the host
 * (method_mc3d.c) and the kernel: the parameter block passed by value, the kernel's arguments,
 * the layout of the integer tallies and their fixed-point scale, and the roulette rule
 * (docs/methods.md, mc3d).
 *
 * Tallies are integers (round(x 2^32) per addition), so that their sums do not depend on the
 * order of the atomic additions: a run is bit-identical whatever the work-group size and the
 * photons per launch, as the tube's mc (docs/reference.md, Corrections). */
#ifndef PPB_MC3D_PARAMS_H
#define PPB_MC3D_PARAMS_H

#ifdef __OPENCL_VERSION__
typedef ulong ppb_u64;
#else
#include <stdint.h>
typedef uint64_t ppb_u64;
#endif

#define PPB_MC3D_KERNEL "src/methods/mc3d/mc3d.cl"

/* An exit weight w is tallied as round(w 2^32), an image contribution c (a weight times the
 * phase function, whose peak is (1 + |g|) / (4 pi (1 - |g|)^2) <= 62 at |g| <= 0.95, times a
 * transmittance) as round(c 2^24). Exit weights are below 1 but for roulette survivors, so a
 * batch's cells stay below 2^64 while it holds fewer than 2^31 photons (checked before the
 * trace); its pixels while its events times the largest weight times the phase function's peak
 * stay below 2^40 (checked on each batch's event count after the trace: about 1.8e10 events a
 * batch at g = 0.95). Resolution: 2^-24 = 6e-8 per contribution. */
#define PPB_MC3D_SCALE     4294967296.0
#define PPB_MC3D_PIX_SCALE 16777216.0

/* Russian roulette as the tube's mc (kernels of methods/mc): below PPB_MC3D_ROULETTE_W a photon
 * survives with probability 1 / PPB_MC3D_ROULETTE_M, its weight multiplied by it; past
 * PPB_MC3D_EVENT_CAP scatterings every event is such a roulette until the weight reaches
 * PPB_MC3D_CAP_WMAX, so no photon runs for ever (unbiased either way). */
#define PPB_MC3D_ROULETTE_W 1e-3
#define PPB_MC3D_ROULETTE_M 8.0
#define PPB_MC3D_EVENT_CAP  10000
#define PPB_MC3D_CAP_WMAX   512.0

/* Per-batch totals: weight sums (fixed point) unless noted. Energy: every photon that reaches
 * the medium brings weight 1, so HITS = ESCAPED + ABSORBED + RLOSS - RGAIN up to the
 * fixed-point rounding (docs/methods.md, mc3d). */
enum {
    PPB_MC3D_T_HITS = 0,      /* photons that reached the medium (a plain count) */
    PPB_MC3D_T_ESCAPED = 1,   /* weight that left the grid, scattered or not */
    PPB_MC3D_T_BALLISTIC = 2, /* of it, unscattered */
    PPB_MC3D_T_ABSORBED = 3,  /* weight removed by implicit capture, w (1 - albedo) */
    PPB_MC3D_T_RGAIN = 4,     /* weight added by roulette survivors */
    PPB_MC3D_T_RLOSS = 5,     /* weight of photons ended by roulette */
    PPB_MC3D_T_EVENTS = 6,    /* scattering events (a plain count) */
    PPB_MC3D_T_CAPPED = 7,    /* roulettes forced by the event cap (a plain count) */
    PPB_MC3D_NTOT = 8
};

/* Two tallies each, all scattered light (mc) and the once-scattered part (mc1):
 * patch cells[(batch * 2 + tally) * npatch nbins + patch nbins + bin],
 * pixels[(batch * 2 + tally) * npix + pixel]. */
enum { PPB_MC3D_ALL = 0, PPB_MC3D_ONCE = 1, PPB_MC3D_NTALLY = 2 };

enum {
    PPB_MC3D_ARG_PARAMS = 0,
    PPB_MC3D_ARG_SIGMA = 1,  /* float[nvox]: sigma_t, 0 outside */
    PPB_MC3D_ARG_ALBEDO = 2, /* float[nvox] */
    PPB_MC3D_ARG_FACES = 3,  /* int[6 nvox]: ppb_object_patches.face_patch */
    PPB_MC3D_ARG_CELLS = 4,
    PPB_MC3D_ARG_PIXELS = 5,
    PPB_MC3D_ARG_TOTALS = 6
};

/* One launch's parameters, by value: doubles first, then ints (an even count), so host and
 * device agree on the layout; the host asserts the size. */
typedef struct ppb_mc3d_params {
    ppb_u64 seed, first, count;          /* Philox key, photon index of work-item 0, photons */
    ppb_u64 ncells, npix;                /* npatch nbins, img_w img_h */
    double h, g;                         /* voxel edge, HG g */
    double light[3];                     /* the direction the light travels */
    double org[3], e1[3], e2[3];         /* entry: org + u e1 + v e2, u, v uniform in [0, 1) */
    double cam_c[3], cam_r[3], cam_u[3]; /* kernels/ppb_object.h's camera */
    double cam_r0, cam_u1, cam_pixel;
    int nx, ny, nz, batches;
    int ntheta, nphi, img_w, img_h;
} ppb_mc3d_params;

#endif
