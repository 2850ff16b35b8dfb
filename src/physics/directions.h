/* directions.h: the direction cells Omega_i of the plane-parallel solver (paper Sec. 2.2.1).
 *
 * Owns the partition of the unit sphere into 2N cells, N per hemisphere, their exact solid
 * angles |Omega_i| and mean cosines k_i (reference: Corrections; k_i = |Omega_i|^-1 integral of
 * mu over the cell), and quadrature nodes inside each cell.
 *
 * Partition: equal-area zonal ("EQSP"-like). Each hemisphere is a polar cap (one cell) and
 * collars of equal polar-angle width, each cut into equal azimuth sectors; the collar counts,
 * rounded from the collars' areas, are even except the first one when N is even. The collar
 * edges are then moved to mu = 1 - C/N (C = cells above the edge), so every cell has exactly
 * the solid angle 2 pi / N, and since dOmega = dmu dphi, k_i = (mu_top + mu_bottom) / 2
 * exactly. Why: cells of one size and nearly square shape resolve every direction alike (no
 * crowding at the pole as with a mu x phi grid), any N is allowed, and the (mu, phi) rectangles
 * make solid angles and k_i exact. Even counts give nearly every ring pair a half-turn symmetry
 * (phase.c integrates each orbit once).
 * The antipodal variant (pp_dirs_make_antipodal, used for g < 0) is closed under w -> -w
 * (pp_dirs_antipode: the y mirror times a half turn), which turns the g < 0 phase matrix into
 * a column permutation of the |g| one (phase.h). It needs every ring even or a single cell: for
 * odd N it is the same partition; for even N the polar ring is four quarter-cap wedges (two for
 * N = 2). It is not the default because a split polar ring changes the marcher's S-table sums
 * (tests/test_march.c: stepped against telescoped 1.4e-8 at N = 32, over its 1e-9 tolerance;
 * every tried partition with a one-cell cap passes, every one with two or four polar cells
 * fails; the cause is not found).
 * pp_dirs_make_collars with collars > 0 builds the polar-ring partition instead (below): rings
 * of equal polar width, cells of unequal area (area[]), for the slab's totals.
 * Sector 0 of every ring is centred on phi = 0 (the beam's azimuth +x), so the partition is
 * mirror symmetric in z (phi -> -phi); cell N + i is the mirror (y -> -y) of cell i.
 *
 * Frame (reference: Bins, tube frame): y up, mu = w.y, phi measured from +x toward +z:
 * w = (sin(theta) cos(phi), mu, sin(theta) sin(phi)). Cells 0..N-1 are up (mu > 0). */
#ifndef PPB_DIRECTIONS_H
#define PPB_DIRECTIONS_H

#include "base/err.h"

#define PP_DIRS_MAX 8192 /* cells per hemisphere accepted */
#define PP_QMAX     16   /* largest Gauss order per cell axis */

typedef struct pp_dirs {
    int n;                   /* cells per hemisphere N */
    int nrings;              /* cap + collars */
    int *ring_first;         /* [nrings + 1]: first up cell of each ring */
    double *mu_edge;         /* [nrings + 1]: 1 = mu_edge[0] > ... > mu_edge[nrings] = 0 */
    int *ring;               /* [N]: ring of up cell i */
    double *phi_lo, *phi_hi; /* [N]: azimuth range of up cell i (radians) */
    double solid;            /* 2 pi / N, the mean |Omega_i| (every cell's but in polar rings) */
    double *area;            /* [N]: |Omega_i| of up cell i and of its mirror N + i */
    int polar;               /* polar rings (collars > 0, or graded: pp_dirs_make_spec) */
    double *k;               /* [2N]: mean cosine, k[N + i] = -k[i] */
    double *centre;          /* [2N x 3]: unit vector at the cell's (mu, phi) centre */
    double *radius; /* [N]: angle from the centre to the farthest corner (both hemispheres) */
    double *half;   /* [N]: largest half-length of the cell along theta or phi, in radians of
                       arc (sets the Gauss order; the cap's phi span is wide in arc) */
    double *nodes[PP_QMAX + 1]; /* lazily built q x q Gauss nodes: [2N][q*q][4] = x, y, z, weight */
} pp_dirs;

/* Builds the partition with n cells per hemisphere (1 <= n <= PP_DIRS_MAX). */
int pp_dirs_make(int n, pp_dirs *d, ppb_err *err);

/* The same, closed under w -> -w for every n (a different partition only for even n). */
int pp_dirs_make_antipodal(int n, pp_dirs *d, ppb_err *err);

/* pp_dirs_make (antipodal 0) or pp_dirs_make_antipodal (1) with a collar edge moved to mu_snap in
 * (0, 1) up to the rounding of the cell counts (|mu error| <= 1/n): the solver's Fresnel
 * boundaries put it at the critical cosine, where the radiance is discontinuous (ppsolver.h). */
int pp_dirs_make_snap(int n, int antipodal, double mu_snap, pp_dirs *d, ppb_err *err);
/* The general form: collars > 0 gives the polar-ring partition, 0 the near-square cells above;
 * mu_snap outside (0, 1) snaps nothing. Polar rings: collars + 1 rings per hemisphere of equal
 * polar-angle width, the cap one of them (up to the snap and its split), each cut into sectors
 * in proportion to its area (the cap one cell, every other ring two at least), so the cells'
 * areas differ (area[]). More rings than square cells trade azimuthal for polar resolution,
 * which is what a slab's totals depend on (ppsolver.h: [pp] collars); a cap as narrow as the
 * collars resolves the forward peak round the normal, where an equal-area cap (0.077 rad
 * across at 334 cells) blurs it. Fails beyond pp_dirs_max_collars(n). */
int pp_dirs_make_collars(int n, int antipodal, double mu_snap, int collars, pp_dirs *d,
                         ppb_err *err);
/* How a partition is built; zero in every field is pp_dirs_make's. */
typedef struct pp_dirs_spec {
    int antipodal;  /* closed under w -> -w (pp_dirs_make_antipodal) */
    double mu_snap; /* in (0, 1): a ring edge at this cosine (pp_dirs_make_snap) */
    int whole_snap; /* the near-square cells: the rings beside mu_snap not split in four */
    int collars;    /* > 0: the polar rings of equal width (pp_dirs_make_collars) */
    double h_pole;  /* in (0, sqrt(2 pi / N)) and collars = 0: the graded polar rings */
} pp_dirs_spec;
/* The partition spec asks for. The graded polar rings (h_pole): a cap of radius
 * h_pole / sqrt(pi) (one near-square cell of that side), then rings whose polar widths grow
 * geometrically from h_pole to the square cell's side at the equator, each cut into cells in
 * proportion to its area (area[]); mu_snap moves the edge nearest it onto it and rescales the
 * others on either side. Fine near the pole for a forward peak narrower than the square cells
 * round the normal (rte2d_grid.c chooses h_pole), the near-square cells' azimuthal resolution
 * kept toward the equator. whole_snap: the split beside the snap (ppsolver.h: it pays in a slab,
 * where the radiance has no azimuth) is left out; in the tube the split's thin rings cost the
 * azimuth the walls need (reference: Methods, `rte2d`). */
int pp_dirs_make_spec(int n, const pp_dirs_spec *spec, pp_dirs *d, ppb_err *err);
/* The most collars n cells per hemisphere allow (two cells each at least): (n - 4) / 2. */
int pp_dirs_max_collars(int n);
void pp_dirs_free(pp_dirs *d);

/* Cell in [0, 2N) holding direction w (unit vector); w.y = 0 counts as up. */
int pp_dirs_cell_of(const pp_dirs *d, const double w[3]);

/* The mirror image of a cell under z -> -z (phi -> -phi), in the same hemisphere. */
int pp_dirs_zmirror(const pp_dirs *d, int cell);

/* The antipodal cell, holding -w for every w of the cell (the up/down mirror of the cell half a
 * turn round in azimuth); -1 where the partition is not closed under w -> -w (the default
 * partition with even n). */
int pp_dirs_antipode(const pp_dirs *d, int cell);

/* The cell's mu range and azimuth range (for down cells mu_lo < mu_hi < 0). */
void pp_dirs_bounds(const pp_dirs *d, int cell, double *mu_lo, double *mu_hi, double *phi_lo,
                    double *phi_hi);

/* q x q product Gauss nodes of a cell, q in [1, PP_QMAX]: rows of (x, y, z, weight), weights
 * summing to |Omega| exactly up to rounding. Built on first use for that q (for all cells). */
const double *pp_dirs_nodes(pp_dirs *d, int cell, int q, ppb_err *err);

#endif
