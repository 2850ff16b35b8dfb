/* rte2d_grid.h: the host numerics of `rte2d` (reference: Methods): the source grid over the
 * cross-section, the direction cells it transports, the scattering that turns the cells' radiance
 * into the grid source, the starting field I_pp, and the energy the medium absorbs.
 *
 * Angles: the direction cells of the plane-parallel solver (directions.h, N per hemisphere; in
 * the tube at n > 1 without the split beside the critical angle, and graded polar rings round
 * the normal for a forward peak narrower than a cell: ppb_rte_partition) and
 * their cell-averaged HG phase matrix (phase.h, rows summing to 1, so scattering conserves
 * energy exactly and the slab limit is ppslab's own discrete-ordinates system). Why cells and not
 * Legendre moments: they are what ppslab and pp already use (slab mode then differs from
 * ppslab by the spatial discretisation alone), the same code serves every g in [-0.95, 0.95]
 * (the HG peak is integrated cell by cell, no truncation of its expansion; what of a peak
 * narrower than a cell the cells blur, delta-M takes out, ppb_rte_delta_m), and the exit
 * radiance keeps angular detail finer than a cell through the cell integrals F_j(w) of
 * phase.h (source-function integration, as ppsolver.h). The set-up is symmetric in z, so a cell
 * and its z mirror (pp_dirs_zmirror) carry the same radiance and march the same planar ray: only
 * one cell of each mirror pair is transported (about N + sqrt(N) of the 2N cells) and the
 * phase matrix is folded over the pairs.
 *
 * Space: the nodes of rte2d_params.h and their dual cells, the flat-source regions (FSRs) of
 * the conservative sweep (rte2d.cl, ppb_rte_moc); the solve's unknown is each transported cell's
 * average radiance over each FSR and the power it carries out through each boundary edge
 * (ppb_rte_nvec). The grid source per unit scattering coefficient is J[c][f] = sum_b Pf[c][b]
 * psi[b][f] (Pf the folded phase matrix), the FSR's emission alpha sigma_t J plus the beam's
 * (ppb_rte_beam_sources); the exit march reads J at the nodes (ppb_rte_to_nodes). */
#ifndef PPB_RTE2D_GRID_H
#define PPB_RTE2D_GRID_H

#include "base/err.h"
#include "methods/rte2d/rte2d_params.h"
#include "model/scene.h"
#include "physics/directions.h"
#include "physics/phase.h"

typedef struct ppb_rte_grid {
    ppb_rte_params P; /* the grid and medium fields (launch fields left to the caller) */
    int nnodes;
    pp_dirs dirs;      /* the solver's partition: antipodal for g < 0, as ppsolver.c builds it */
    int nc;            /* transported cells */
    int *rep;          /* [nc]: the cell of dirs each transported cell is */
    int *slot;         /* [2N]: transported index of every cell (its mirror's where not itself) */
    double *mult;      /* [nc]: 1 or 2, cells the transported one stands for */
    double *dir4;      /* [nc][4]: transport direction (the centre; in the tube x scaled so the
                          cells integrate w_x^2 exactly) and the cell average of p(w.w_L) */
    double *Pf;        /* [nc][nc] row-major: folded phase matrix */
    pp_phase_fn phase; /* what the cells integrate: HG(g), or delta-M's truncated series */
    double clipped;    /* series: the largest share of a row set to 0 (phase.h), else 0 */
    double moment_b;   /* the first-moment correction's mix b (0: none; ppb_rte_moment_fix) */
    double *bnd;       /* n > 1: [nc][9] walls (rte2d_params.h, PPB_RTE_ARG_BND); NULL at n = 1 */
    /* The flat-source regions (FSRs) of the conservative sweep: the nodes' dual cells, the
     * column of the node on the step split in two at step_x (so sigma_t and alpha are constant
     * in each); slab: one column of unit width. */
    int nfx, nf, nb; /* FSR columns, FSRs (nfx x ny, f = j nfx + k), boundary edges per cell */
    double *fedge;   /* fx [nfx + 1] ascending, then fy [ny + 1] from 0 down to -H */
    double *fsig;    /* [nfx] sigma_t of each column */
    double *falb;    /* [nfx] albedo of each column */
    int *fcol;       /* [nfx] the node column of each FSR column */
    double *farea;   /* [nf] areas (per unit z; slab: per unit area) */
    double dmin[2];  /* the least FSR width and height */
    double *ymp;     /* [ny][4]: the rows' mean-preserving solve, eliminated (ppb_rte_to_nodes) */
    /* n > 1: refl[f][b][c], the share of what cell b carries out through face f that the wall
     * reflects into cell c (rows sum to 1; the mirror image of b's directions, over the cells
     * whose centres enter through f); NULL at n = 1. */
    double *refl;
} ppb_rte_grid;

/* The solve's unknown, per transported cell a: psi[a][f], the FSRs' average radiance, then
 * bout[a][e], the power (per sr, per unit z) leaving through each boundary edge
 * (rte2d_params.h's edge order), nc (nf + nb) values; with the linear source (P.ls) after
 * them grad[a][f][2], each FSR's fitted radiance gradient in x and y, nc 2 nf more: the walls'
 * reflection at n > 1 is a linear map of bout, so the solve inverts it with the scattering. */
size_t ppb_rte_nvec(const ppb_rte_grid *G);

/* The node field rad[nc][nnodes] of the solve's unknown x, for the exit march's bilinear
 * source: each node column's values such that the field's average over every node's dual cell
 * (its FSRs) in y is that cell's average (mean-preserving; the boundary layers put the nodes off
 * their cells' centres), S3's and S4's nodes extrapolated to the face in x. */
void ppb_rte_to_nodes(const ppb_rte_grid *G, const double *x, double *rad);

/* The unknown of a node field (I_pp): every FSR its node's value, every edge the power that
 * value carries out through it (|w . n| times the edge's length, where w leaves), the linear
 * source's gradients 0. */
void ppb_rte_from_nodes(const ppb_rte_grid *G, const double *rad, double *x);

/* At n > 1 (reference: Medium) the partition has a collar edge at the critical cosine, as
 * ppsolver.c's, the light fields of P are the refracted beam's, and bnd holds each transported
 * cell's walls: the slot of its mirror in S1..S4 (the cell of the mirrored centre), its
 * reflectance there, flux-weighted over the cell (S1, S2: ppsolver.c's mean over the mu range;
 * S3, S4: over the cell's Gauss nodes, weight |w_x|), and the cell average of p(w . w_up) of
 * the beam reflected at S2. */

/* Builds the grid with node spacing about `spacing` mfp (each part of the x range, and y, get
 * ceil(length / spacing) cells), `directions` cells per hemisphere and march step hstep mfp;
 * the cells integrate ph (every phase integral of the grid: matrix, beam, walls, exit rows), or
 * HG(sc->g) where ph is NULL; moment: `[rte2d] moment`'s mode (ppb_rte_moment_applies). */
int ppb_rte_grid_make(const ppb_scene *sc, double spacing, int directions, double hstep, int moment,
                      const pp_phase_fn *ph, ppb_rte_grid *G, ppb_err *err);
void ppb_rte_grid_free(ppb_rte_grid *G);

/* Delta-M (Wiscombe 1977; reference: Methods, `rte2d`): the phase function p_g taken as
 * f delta + (1 - f) p_g* with g* = (g - f) / (1 - f), the HG the cells transport (the same first
 * moment, so the same sigma_s (1 - g)), f = g^L the part of the forward peak beyond the
 * Legendre order L = sqrt(2 directions) that 2 directions cells over the sphere resolve (as
 * DISORT's f = g^(2N) for 2N streams). *out = sc with g*, and in every medium of a step
 * sigma_t' = (1 - alpha f) sigma_t, alpha' = alpha (1 - f) / (1 - alpha f) (sigma_a kept, the
 * delta part counted as unscattered). Returns f; 0 with *out = sc where the scaled media cannot
 * be written as a scene (an albedo step: sigma_t' would step too) or f < 1e-12. order > 0
 * (`[rte2d] delta_m_order`): L = order instead. */
double ppb_rte_delta_m(const ppb_scene *sc, int directions, int order, ppb_scene *out);

/* Delta-M proper (Wiscombe 1977, as DISORT; `[rte2d] delta_m = legendre`): f = g^L and the
 * retained function the Legendre series truncated at order L with moments
 * chi*_l = (g^l - f) / (1 - f), l < L (*ph, pp_phase_fn; a polynomial in cos the cells hold,
 * unlike HG(g*)); *out scaled as ppb_rte_delta_m's, with out->g = chi*_1 = g*. L in
 * [2, PP_SERIES_MAX]. Returns f; 0 with *out = sc and ph an HG of sc->g where the scaling is not
 * done (ppb_rte_delta_m's conditions). */
double ppb_rte_delta_m_series(const ppb_scene *sc, int L, ppb_scene *out, pp_phase_fn *ph);

/* The first-moment correction of the full 2N x 2N cell phase matrix P (pp_phase_matrix's, of
 * HG g, on d; for g < 0 d must be the antipodal partition): P <- (1 - b) P + b A, A the identity
 * (g > 0) or the antipodal permutation (g < 0), b chosen so that the mean over the columns of
 * sum_i P_ij c_i . c_j (c the cells' centres) is g; rows and columns keep summing to 1 and S
 * stays symmetric. Returns b; 0 (P untouched) at g = 0 or where the matrix already reaches g.
 * `[rte2d] moment` (reference: Methods, `rte2d`). */
double ppb_rte_moment_fix(const pp_dirs *d, double g, double *P);

/* Whether the grid's matrix gets that correction (`[rte2d] moment`, PPB_RTE_MOMENT_*, for the
 * solved medium sc, on the cells d): always (on), never (off), or (auto) in the tube where
 * g > 0 on the near-square cells. Its measure, the mean cosine between the cells' unit
 * centres, is the transport's there, where light spreads in x and y; in the slab only mu
 * transports (ppslab's diffusion match is the measure there: on a g 0.9 slab it took R from
 * 1.8 % high to 6.2 % low), and on the polar rings' long cells the centre lies far from the
 * cell's mean direction (realistic_g09's S1 from 1.5 % high to 1.8 % low; reference: Methods,
 * `rte2d`). At g < 0 the antipodal mix made every measured case worse. */
int ppb_rte_moment_applies(int mode, const ppb_scene *sc, const pp_dirs *d);

/* The direction cells of a grid (reference: Methods, `rte2d`, the cells): at n > 1 a ring edge
 * at the critical cosine, in the tube without the split of the rings beside it (directions.h);
 * at normal light where the retained phase function ph (HG g*, or a series of first moment
 * chi*_1) has its forward peak's angular scale 1 - g* below the square cell's side
 * sqrt(2 pi / N), the graded polar rings with h_pole = 1 - g* (the peak sits round the normal
 * there; at oblique light it does not, and the rings' long cells would only cost azimuth). */
pp_dirs_spec ppb_rte_partition(const ppb_scene *sc, const pp_phase_fn *ph, int directions);

/* Nodes of the grid ppb_rte_grid_make builds at `spacing` (G->nnodes), before building. */
double ppb_rte_nodes(const ppb_scene *sc, double spacing);

/* Bytes the grid's arrays and a solve with `restart` Krylov vectors take, before building; ls:
 * with the linear source (ppb_rte_ls_applies). */
double ppb_rte_bytes(const ppb_scene *sc, double spacing, int directions, int restart, int ls);

/* Whether the sweep's source is linear in each region: `[rte2d] source = linear` (source, a
 * ppb_rte_source) in the tube; the slab keeps `ppslab`'s flat discrete-ordinates system. */
int ppb_rte_ls_applies(int source, const ppb_scene *sc);

/* J = Pf psi, the scattered light's source per unit sigma_s in every FSR: [nc][nf] from the
 * unknown x; with the linear source (P.ls) and Jg not NULL, its gradients Jg [nc][nf][2] from
 * the radiance's. */
void ppb_rte_scatter(const ppb_rte_grid *G, const double *x, double *J, double *Jg);

/* Folded cell integrals of the exit directions: F[d][c] = sum over the cells c stands for of
 * integral_{Omega_j} p(w_d . w') dw' (p the grid's phase), for the ndir unit vectors w (rows
 * of 3). */
int ppb_rte_exit_coeffs(ppb_rte_grid *G, const double *w, int ndir, double *F, ppb_err *err);

/* I_pp: at every lit node the cell field of its column's slab (sigma_t(x) H, alpha(x)) at
 * tau = D cos(theta_L) clamped to the slab (reference: Methods, pp), 0 where unlit. */
int ppb_rte_initial_pp(const ppb_rte_grid *G, const ppb_scene *sc, double *rad, ppb_err *err);

/* Scattered power leaving through each surface (PPB_S1..S4; per unit z, slab: per unit area)
 * of the unknown x: its outgoing edge powers times |Omega| (n > 1: times 1 - F of the cell at
 * that face, F being reflected back in): the same tracks the FSRs' balance is made of, so
 * R + T + sides + absorbed + ballistic = 1 to the solver's tolerance. */
void ppb_rte_boundary_flux(const ppb_rte_grid *G, const double *x, double flux[4]);

/* Power absorbed from the scattered light of x: sum over FSRs and cells of
 * (1 - alpha) sigma_t A |Omega| psi. */
double ppb_rte_absorbed_scattered(const ppb_rte_grid *G, const double *x);

/* The beam's first scattering as the FSRs' flat emission density, exact (rte2d_beam.h):
 * Qb[a][f] = alpha sum_k cb_a[k] (integral over f of sigma_t E_k) / A_f, cb_a the cell's phase
 * coefficients of the beam's directions; *absorbed = the (1 - alpha) part of the beam's
 * collisions over the cross-section (per unit z, slab: per unit area). With the linear source
 * (P.ls) and Qbg not NULL, Qbg[a][f][2] the gradient of the density's least-squares linear fit
 * over the FSR, its first moments from strips (rte2d_grid.c, beam_moments). */
int ppb_rte_beam_sources(const ppb_rte_grid *G, double *Qb, double *Qbg, double *absorbed,
                         ppb_err *err);

/* Power absorbed from the unscattered beam, exact: along every entry point's path the
 * piecewise-constant (1 - alpha)(e^{-tau_a} - e^{-tau_b}), over the lit entry points by
 * Gauss-Legendre panels between the entry points where the path's pieces change; per unit z
 * (slab: per unit area), E_perp = 1. n > 1 (slab, or the tube at normal incidence): the
 * refracted beam's passes S1 -> S2 -> S1 .., (1 - F_L)(1 - alpha)(1 - a) / (1 - F_b a) per
 * column, a = e^{-sigma_t H / cos theta_t}; the oblique tube: each entry point's beam walked
 * through its reflections off all four faces, each leg split at the step plane (2e4 midpoints
 * over the lit part). The solve takes its absorbed beam from ppb_rte_beam_sources' region
 * integrals instead; this walk, along the beam rather than over regions, is their independent
 * witness (tests/test_rte2d_beam.c: the two agree to 1e-14 where the walk is exact). */
double ppb_rte_absorbed_beam(const ppb_scene *sc);

#endif
