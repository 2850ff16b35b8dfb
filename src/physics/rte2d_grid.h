/* rte2d_grid.h: the host numerics of `rte2d` (reference: Methods): the source grid over the
 * cross-section, the direction cells it transports, the scattering that turns the cells' radiance
 * into the grid source, the starting field I_pp, and the energy the medium absorbs.
 *
 * Angles: the direction cells of the plane-parallel solver (directions.h, N per hemisphere) and
 * their cell-averaged HG phase matrix (phase.h, rows summing to 1, so scattering conserves
 * energy exactly and the slab limit is ppslab's own discrete-ordinates system). Why cells and not
 * Legendre moments: they are what ppslab and pp already use (slab mode then differs from
 * ppslab by the spatial discretisation alone), the same code serves every g in [-0.95, 0.95]
 * (the HG peak is integrated cell by cell, no truncation of its expansion), and the exit
 * radiance keeps angular detail finer than a cell through the cell integrals F_j(w) of
 * phase.h (source-function integration, as ppsolver.h). The set-up is symmetric in z, so a cell
 * and its z mirror (pp_dirs_zmirror) carry the same radiance and march the same planar ray: only
 * one cell of each mirror pair is transported (about N + sqrt(N) of the 2N cells) and the
 * phase matrix is folded over the pairs.
 *
 * Unknown: rad[c][node], the scattered radiance (cell average) of transported cell c at every
 * node. The grid source per unit scattering coefficient is J[c][node] = sum_b Pf[c][b] rad[b][node]
 * (Pf the folded phase matrix); the march multiplies by sigma_s at the exact position. */
#ifndef PPB_RTE2D_GRID_H
#define PPB_RTE2D_GRID_H

#include "base/err.h"
#include "kernels/rte2d_params.h"
#include "model/scene.h"
#include "physics/directions.h"

typedef struct ppb_rte_grid {
    ppb_rte_params P; /* the grid and medium fields (launch fields left to the caller) */
    int nnodes;
    pp_dirs dirs;  /* the solver's partition: antipodal for g < 0, as ppsolver.c builds it */
    int nc;        /* transported cells */
    int *rep;      /* [nc]: the cell of dirs each transported cell is */
    int *slot;     /* [2N]: transported index of every cell (its mirror's where not itself) */
    double *mult;  /* [nc]: 1 or 2, cells the transported one stands for */
    double *dir4;  /* [nc][4]: centre (x, y, z) and the cell average of p(w.w_L) */
    double *Pf;    /* [nc][nc] row-major: folded phase matrix */
    double *wnode; /* [nnodes]: trapezoid area weights (per unit z; slab: per unit area) */
    double *bnd;   /* n > 1: [nc][9] walls (rte2d_params.h, PPB_RTE_ARG_BND); NULL at n = 1 */
} ppb_rte_grid;

/* At n > 1 (reference: Medium) the partition has a collar edge at the critical cosine, as
 * ppsolver.c's, the light fields of P are the refracted beam's, and bnd holds each transported
 * cell's walls: the slot of its mirror in S1..S4 (the cell of the mirrored centre), its
 * reflectance there, flux-weighted over the cell (S1, S2: ppsolver.c's mean over the mu range;
 * S3, S4: over the cell's Gauss nodes, weight |w_x|), and the cell average of p(w . w_up) of
 * the beam reflected at S2. */

/* Builds the grid with node spacing about `spacing` mfp (each part of the x range, and y, get
 * ceil(length / spacing) cells), `directions` cells per hemisphere and march step hstep mfp. */
int ppb_rte_grid_make(const ppb_scene *sc, double spacing, int directions, double hstep,
                      ppb_rte_grid *G, ppb_err *err);
void ppb_rte_grid_free(ppb_rte_grid *G);

/* Bytes the grid's arrays and a solve with `restart` Krylov vectors take, before building. */
double ppb_rte_bytes(const ppb_scene *sc, double spacing, int directions, int restart);

/* J = Pf rad, both [nc][nnodes]. */
void ppb_rte_scatter(const ppb_rte_grid *G, const double *rad, double *J);

/* Folded cell integrals of the exit directions: F[d][c] = sum over the cells c stands for of
 * integral_{Omega_j} p(w_d . w') dw', for the ndir unit vectors w (rows of 3). */
int ppb_rte_exit_coeffs(ppb_rte_grid *G, double g, const double *w, int ndir, double *F,
                        ppb_err *err);

/* I_pp: at every lit node the cell field of its column's slab (sigma_t(x) H, alpha(x)) at
 * tau = D cos(theta_L) clamped to the slab (reference: Methods, pp), 0 where unlit. */
int ppb_rte_initial_pp(const ppb_rte_grid *G, const ppb_scene *sc, double *rad, ppb_err *err);

/* Scattered fluence at every node, phi[node] = sum over all 2N cells |Omega| I. */
void ppb_rte_fluence(const ppb_rte_grid *G, const double *rad, double *phi);

/* Scattered power leaving through each surface (PPB_S1..S4; per unit z, slab: per unit area):
 * the outgoing cells' flux |Omega| (w.n) I (n > 1: times 1 - F of the cell) at the boundary nodes
 * (w.n = the cell's exact mean cosine k_i on S1 and S2, its centre's on S3 and S4), trapezoid along
 * the surface. The totals come from it as ppslab's come from its cell field: the same discrete
 * field the absorption is taken from, so R + T + sides + absorbed + ballistic = 1 measures the
 * scheme's conservation, not the bins' quadrature. */
void ppb_rte_boundary_flux(const ppb_rte_grid *G, const double *rad, double flux[4]);

/* Power absorbed from the scattered light, integral of sigma_a(x) phi over the cross-section
 * (bilinear phi: the trapezoid weights; every grid cell lies on one side of the step). */
double ppb_rte_absorbed_scattered(const ppb_rte_grid *G, const double *phi);

/* Power absorbed from the unscattered beam, exact: along every entry point's path the
 * piecewise-constant (1 - alpha)(e^{-tau_a} - e^{-tau_b}), over the lit entry points by
 * Gauss-Legendre panels between the entry points where the path's pieces change; per unit z
 * (slab: per unit area), E_perp = 1. n > 1 (slab, or the tube at normal incidence): the
 * refracted beam's passes S1 -> S2 -> S1 .., (1 - F_L)(1 - alpha)(1 - a) / (1 - F_b a) per
 * column, a = e^{-sigma_t H / cos theta_t}; the oblique tube: each entry point's beam walked
 * through its reflections off all four faces, each leg split at the step plane (2e4 midpoints
 * over the lit part). */
double ppb_rte_absorbed_beam(const ppb_scene *sc);

#endif
