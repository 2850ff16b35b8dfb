/* rte2d_params.h: the one definition of what the rte2d kernels (rte2d.cl) receive, shared by the
 * host (src/methods/method_rte2d.c, src/physics/rte2d_grid.c) and the kernels (reference:
 * Methods).
 *
 * Owns: the launch parameters passed by value, the kernel argument indices, the source grid over
 * the cross-section (node positions, the split of the x nodes at the step, the bilinear lookup of
 * a source plane) and the exact direct beam at a point (optical depth D along the light path and
 * whether S1's lit part is seen, reference: Light), which both the grid's first-scattering
 * source and the exit march use, so the beam's first scattering is exact (as in `ss`). At
 * n > 1 the light fields are the refracted beam's inside (rte2d_grid.h).
 *
 * Grid: nodes x_i, y_j (j = 0 on S1, ny - 1 on S2, y_j = -j hy without layers). In y, a
 * boundary layer under S1 and over S2 has nyl rows whose spacings double away from the face,
 * hyf, 2 hyf, .., 2^(nyl-1) hyf (depth dlay = hyf (2^nyl - 1)), the middle nym rows of hy
 * (nyl = 0: uniform; ppb_rte_node_y): the scattered light of a direction rises from 0 at a face
 * within about |mu| mfp, so the source has a boundary layer as thin as the most grazing cell's
 * |mu| (measured on the nodal scheme rte2d had before its flat-source regions: the
 * layers mattered, x much less). The flat-source regions of the sweep are the nodes' dual cells
 * (rte2d_grid.h), so the layers refine them too. In x the nodes are uniform on
 * [-W/2, step_x] (nl cells) and on [step_x, W/2] (nr cells), sharing the node at step_x, so the
 * step is a grid line (the source per unit scattering coefficient, J = sum_j P_ij I_j, is
 * continuous across it but kinked; sigma_s, which jumps, is applied at the exact position).
 * Without a step inside the tube nl = nx - 1, nr = 0. Slab mode has one column (nx = 1).
 *
 * Plain C that is also OpenCL C, like ppb_conventions.h. */
#ifndef PPB_RTE2D_PARAMS_H
#define PPB_RTE2D_PARAMS_H

#include "ppb_light.h"

#ifdef __OPENCL_VERSION__
#define PPB_RTE_GMEM __global
/* The lookup runs once per march step: inlined, its results stay in registers (PoCL kept it a
 * call, its row and fraction through the stack). */
#define PPB_RTE_HOT inline __attribute__((always_inline))
#else
#define PPB_RTE_GMEM
#define PPB_RTE_HOT static inline
#endif

/* Arguments of the exit march ppb_rte_exit (rte2d.cl), by index. */
enum {
    PPB_RTE_ARG_PARAMS = 0, /* ppb_rte_params by value */
    PPB_RTE_ARG_DIRS = 1,   /* [ndir][3]: each exit sample's direction (ppb_bin_sample_dir) */
    PPB_RTE_ARG_SRC = 2,    /* source planes J [ndir][nnodes], one per exit direction sample */
    PPB_RTE_ARG_OUT = 3,    /* radiance [rows][nbins] */
    PPB_RTE_ARG_RAD = 4,    /* n > 1: the converged field I [ncell][nnodes] the walls reflect */
    PPB_RTE_ARG_BND = 5,    /* n > 1: [ndir][4] = slot of the sample's mirror at S1..S4 */
    PPB_RTE_NARGS = 6
};

/* Arguments of the conservative sweep ppb_rte_moc (rte2d.cl), by index. The flat-source regions
 * (FSRs) are the grid nodes' dual cells (rte2d_grid.h): nfx columns (edges fx, ascending from
 * -W/2 to W/2; slab: one column) by ny rows (edges fy, descending from 0 to -H). A direction's
 * boundary edges: S1 [0, nfx), S2 [nfx, 2 nfx), S3 [2 nfx, 2 nfx + ny), S4 [.., 2 nfx + 2 ny). */
enum {
    PPB_MOC_ARG_PARAMS = 0, /* ppb_rte_params by value */
    PPB_MOC_ARG_DIRS = 1,   /* [ncell][4]: centre (x, y, z), unused */
    PPB_MOC_ARG_EDGES = 2,  /* fx [nfx + 1] then fy [ny + 1] */
    PPB_MOC_ARG_SIG = 3,    /* sigma_t of each FSR column [nfx] */
    PPB_MOC_ARG_SRC = 4,    /* flat emission density Q [ncell][nfsr], per sr */
    PPB_MOC_ARG_BIN = 5,    /* power entering through each boundary edge [ncell][nb] */
    PPB_MOC_ARG_OUT = 6,    /* [ncell][nfsr + nb]: the FSRs' average radiance, then the power
                               leaving through each boundary edge (the solve's unknown,
                               rte2d_grid.h) */
    PPB_MOC_ARG_SCR = 7,    /* scratch [ncell][nb] */
    PPB_MOC_ARG_NFX = 8,    /* int: FSR columns */
    PPB_MOC_ARG_DMIN = 9,   /* double2: the least FSR width and height (track spacing) */
    PPB_MOC_ARG_SRCG = 10,  /* linear source (P.ls): the emission's gradient in x and y about
                               each FSR's centre [ncell][nfsr][2]; the radiance's, fitted, goes
                               to OUT after the [ncell][nfsr + nb] block, [ncell][nfsr][2] */
    PPB_MOC_ARG_LSC = 11,   /* linear source: scratch [ncell][nfsr][PPB_MOC_LS_ACC] */
    PPB_MOC_NARGS = 12
};

/* Linear source (P.ls): the sums each FSR's tracks accumulate, per direction, for the fit of the
 * radiance's gradient (rte2d.cl, moc_fit): its integral, its two first moments, the tracks' area,
 * their two first moments and their three second moments about the FSR's centre. */
#define PPB_MOC_LS_ACC 9

/* Tracks a direction lays across its thinnest FSR (its projected width, perpendicular). */
#define PPB_MOC_TRACKS_PER_CELL 2

/* Boundary edges per direction. */
PPB_FN int ppb_moc_nb(int nfx, int ny)
{
    return 2 * nfx + 2 * ny;
}

/* The first boundary edge of face PPB_S1..S4 and the face's edge count (the order above). */
PPB_FN int ppb_moc_edge0(int nfx, int ny, int face)
{
    return face < 2 ? face * nfx : 2 * nfx + (face - 2) * ny;
}

PPB_FN int ppb_moc_nedge(int nfx, int ny, int face)
{
    return face < 2 ? nfx : ny;
}

/* Doubles per transported cell of the grid's walls (rte2d_grid.h, G->bnd): the slot of the
 * cell's mirror at S1..S4, its cell-averaged F there, the beam coefficients of (+sin, up),
 * (-sin, down), (-sin, up). */
#define PPB_RTE_BND 11

/* Parameters of one launch. The medium block, then all doubles, then an even number of ints
 * (host asserts). */
typedef struct ppb_rte_params {
    ppb_medium med;                               /* the cross-section and the medium */
    ppb_lit lit;                                  /* S1's lit part (ppb_light.h) */
    double sin_theta_l, cos_theta_l, tan_theta_l; /* light incidence (at n > 1 inside) */
    double hxl, hxr, hy;                          /* node spacings left/right of the step, in y */
    double hyf, dlay;                             /* y: boundary-layer spacing and depth */
    double hstep;                                 /* march step length in the x-y plane, mfp */
    double d_cap;                                 /* optical distance where a march stops */
    double beam_in; /* n > 1: perpendicular irradiance of the refracted beam (ppb_fresnel.h) */
    double beam_fb; /* n > 1: F the beam meets at S2 and S1 from inside */
    double beam_fs; /* n > 1: F the beam meets at S3 and S4 from inside (oblique light) */
    double ss_g;    /* exit: g of the beam's first scattering along the ray (the medium's own g
                       under delta-M, whose med.g is the truncated one: reference: Methods) */
    double ss_w;    /* exit: its weight, 1 / (1 - f) under delta-M (sigma_s' / (1 - f) = sigma_s) */
    int nx, ny, nl; /* nodes in x (nl cells left of the split) and y */
    int ncell;      /* sweep: direction cells marched */
    int beam;       /* 1: add the direct beam's first scattering */
    int diffuse;    /* 1: add the grid source J */
    int ntheta, nphi, nsamp, npts;
    int row0;      /* exit: first segment row of this launch */
    int nyl, nym;  /* y: rows per boundary layer (0: uniform), rows between the layers */
    int refl;      /* 1: a ray reaching a wall adds F x the mirror cell's radiance there (n > 1) */
    int ls;        /* sweep: 1 the source linear in each FSR (the tube), 0 flat */
    int ls_pad;    /* unused: keeps the count of ints even */
    int nseg[4];   /* exit: segments per surface (slab: 1, 1, 0, 0) */
    int offset[4]; /* exit: first row of each surface */
} ppb_rte_params;

PPB_FN int ppb_rte_nnodes(const ppb_rte_params *P)
{
    return P->nx * P->ny;
}

/* x of node column i. */
PPB_FN double ppb_rte_node_x(const ppb_rte_params *P, int i)
{
    if (!P->med.tube)
        return 0.0;
    return i <= P->nl ? -0.5 * P->med.width + i * P->hxl : P->med.step_x + (i - P->nl) * P->hxr;
}

/* Depth below S1 (or above S2) of a boundary-layer node k rows from the face: hyf (2^k - 1).
 * 2^k as (double)(1 << k), exact as ldexp(1, k) and cheaper in the march's inner loop. */
PPB_FN double ppb_rte_layer_t(const ppb_rte_params *P, int k)
{
    return P->hyf * ((double)(1 << k) - 1.0);
}

/* y of node row j (<= 0). */
PPB_FN double ppb_rte_node_y(const ppb_rte_params *P, int j)
{
    if (j <= P->nyl)
        return -ppb_rte_layer_t(P, j);
    if (j <= P->nyl + P->nym)
        return -(P->dlay + (j - P->nyl) * P->hy);
    return -(P->med.height - ppb_rte_layer_t(P, P->ny - 1 - j));
}

/* The layer row k = floor(log2(u)) of u = t / hyf + 1 >= 1, clamped to [0, nyl - 1]: by
 * comparison with the powers of two (exact), but within 1e-13 of one of them (a point on a
 * layer's row line, a node among them) by floor(log2(u)) itself, whose rounding chose the row
 * there before: either row gives the point's value to an ulp, and log2's keeps the marches bit
 * for bit as they were. log2 on every layer step cost a third of the sweep. */
PPB_RTE_HOT int ppb_rte_layer_row(const ppb_rte_params *P, double u)
{
    int k = 0;
    double p = 2.0; /* 2^(k + 1) */
    while (k < P->nyl - 1 && u >= p) {
        k++;
        p *= 2.0;
    }
    double near = 1e-13 * p;
    if ((k > 0 && u - 0.5 * p < near) || (k < P->nyl - 1 && p - u < near)) {
        k = (int)floor(log2(u));
        k = k < 0 ? 0 : (k > P->nyl - 1 ? P->nyl - 1 : k);
    }
    return k;
}

/* The grid row [j, j + 1] holding y and the fraction ty of the way from row j to j + 1 (linear
 * in y), both clamped to the grid. In a layer the row is k = floor(log2(t / hyf + 1)). */
PPB_RTE_HOT void ppb_rte_row(const ppb_rte_params *P, double y, int *j, double *ty)
{
    double t = -y;
    t = t < 0.0 ? 0.0 : (t > P->med.height ? P->med.height : t);
    if (P->nyl > 0 && t < P->dlay) {
        int k = ppb_rte_layer_row(P, t / P->hyf + 1.0);
        double t0 = ppb_rte_layer_t(P, k);
        *j = k;
        *ty = (t - t0) / (P->hyf * (double)(1 << k));
    } else if (P->nyl > 0 && t > P->med.height - P->dlay) {
        double u = P->med.height - t; /* height above S2 */
        int k = ppb_rte_layer_row(P, u / P->hyf + 1.0);
        double u1 = ppb_rte_layer_t(P, k + 1);
        *j = P->ny - 2 - k;
        *ty = (u1 - u) / (P->hyf * (double)(1 << k));
    } else {
        double f = (t - P->dlay) / P->hy;
        int m = (int)f;
        m = m < 0 ? 0 : (m > P->nym - 1 ? P->nym - 1 : m);
        *j = P->nyl + m;
        *ty = f - m;
    }
    *ty = *ty < 0.0 ? 0.0 : (*ty > 1.0 ? 1.0 : *ty);
}

/* Fractional node column of x (tube), clamped to the grid. */
PPB_RTE_HOT double ppb_rte_fx(const ppb_rte_params *P, double x)
{
    double f = (P->nl == P->nx - 1 || x < P->med.step_x) ? (x + 0.5 * P->med.width) / P->hxl
                                                         : P->nl + (x - P->med.step_x) / P->hxr;
    return f < 0.0 ? 0.0 : (f > P->nx - 1 ? P->nx - 1 : f);
}

/* Bilinear value of a source plane (nnodes values, node = j nx + i) at (x, y). */
PPB_RTE_HOT double ppb_rte_lookup(const ppb_rte_params *P, const PPB_RTE_GMEM double *plane,
                                  double x, double y)
{
    int j;
    double ty;
    ppb_rte_row(P, y, &j, &ty);
    if (P->nx == 1)
        return plane[j] + ty * (plane[j + 1] - plane[j]);
    double fx = ppb_rte_fx(P, x);
    int i = (int)fx;
    if (i > P->nx - 2)
        i = P->nx - 2;
    double tx = fx - i;
    const PPB_RTE_GMEM double *c = plane + (long)j * P->nx + i;
    double top = c[0] + tx * (c[1] - c[0]);
    double bot = c[P->nx] + tx * (c[P->nx + 1] - c[P->nx]);
    return top + ty * (bot - top);
}

/* Whether the refracted beam (n > 1) meets the side walls: in the tube at oblique light, where
 * it is unfolded over the cross-section's mirror images (ppb_beam_images.h); elsewhere it stays
 * in its column, with only its S2 -> S1 round trips (the slab, or the tube at normal light). */
PPB_FN int ppb_rte_beam_images(const ppb_rte_params *P)
{
    return P->med.n > 1.0 && P->med.tube && P->tan_theta_l > 0.0;
}

/* The exact direct beam at (x, y), y <= 0 (reference: Light): the ray toward the light meets
 * S1's plane at x' = x + y tan(theta_L); the point is lit when x' lies on S1's lit part
 * (ppb_lit_at: >= -W/2, left of a shadow step, or in a searchlight's strip). D = optical depth
 * of that path through the piecewise-constant medium, continued where unlit (the caller multiplies
 * by lit). Slab: sigma_t |y| / cos. */
PPB_FN void ppb_rte_light(const ppb_rte_params *P, double x, double y, double *D, int *lit)
{
    double t = -y < 0.0 ? 0.0 : -y, len = t / P->cos_theta_l;
    if (!P->med.tube) {
        *D = P->med.sigma_t * len;
        *lit = 1;
        return;
    }
    double xp = x - t * P->tan_theta_l;
    *lit = ppb_lit_at(&P->med, &P->lit, xp, 1e-12 * P->med.width);
    if (P->med.step != PPB_STEP_DENSITY) {
        *D = P->med.sigma_t * len;
        return;
    }
    /* The path's horizontal span is [xp, x]; the part left of the step has sigma_t. */
    double fl;
    if (x - xp <= 0.0)
        fl = x < P->med.step_x ? 1.0 : 0.0;
    else {
        double s = P->med.step_x < xp ? xp : (P->med.step_x > x ? x : P->med.step_x);
        fl = (s - xp) / (x - xp);
    }
    *D = len * (P->med.sigma_t * fl + P->med.sigma_t_right * (1.0 - fl));
}

#endif
