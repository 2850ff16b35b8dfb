/* march_tables.h: the integral tables of the ray march (paper Sec. 3.2-3.3, Eq. 15-17) and the
 * per-direction coefficient of the attenuated beam, for every direction sample of every bin.
 *
 * The marched source at a point with light-path optical depth D, tau = D cos(theta_L), average
 * albedo abar, local albedo alpha and extinction sigma_t is (reference: Methods)
 *     sigma_t alpha [ R(tau; w) + C(w) exp(-D) ],
 * R(tau; w) = sum_k A_k(w) e_k(tau)  (paper Eq. 15: A_k = the slab's a_k / abar, its modes'
 *             angular integral P_Vj c_j; the slab solution at abar, Sec. 3.3),
 * C(w)      = p(w.w_L) + b(w) / abar  (the direct beam's single scattering and the particular
 *             part of the diffuse field; the beam is handled analytically, not tabulated).
 * The S table (Eq. 16-17, derived afresh, reference: Corrections) integrates R along a step where
 * tau = tau1 + r0 sigma_t l, r0 = w_y being the slab's slope:
 *     integral_0^h e^{-sigma_t l} sigma_t R(tau1 + r0 sigma_t l) dl = e^{-sigma_t h} S(tau2) -
 * S(tau1), S(tau) = sum_k A_k e_k(tau) / (lambda_k r0 - 1)  + any multiple of e^{tau / r0}, and the
 * table stores the well-conditioned member that vanishes at the far face of the slab (tau* = tau0
 * when r0 > 0, 0 when r0 < 0): S(tau) = -(delta/r0) sum_k A_k e_k(tau) phi((lambda_k - 1/r0)
 * delta),  delta = tau* - tau, phi(z) = (e^z - 1)/z, which has no pole where lambda_k r0 = 1 and
 * equals minus the slab's radiance from the modes: the march of a whole slab returns the slab's own
 * field.
 *
 * Column slabs (paper Sec. 3.1, Eq. 13-14): I_pp at a point is the solution of the slab the
 * point sits in. The media (reference: Medium) are piecewise constant with their only jump on
 * the vertical plane x = step_x, so every vertical column of the tube is a homogeneous slab of
 * optical thickness tau0(x) = sigma_t(x) H; a point at light-path optical depth D reads its
 * column's slab at tau = D cos(theta_L), clamped to [0, tau0(x)]. The tables hold one slab
 * solution per distinct column thickness (one, or two with a density step: exact, no
 * interpolation between thicknesses), each at every albedo node.
 * Layout: [column][albedo node][direction][tau node], tau nodes uniform on [0, tau0 of the
 * column], albedo nodes uniform on the range of albedos the medium holds (one node for a uniform
 * albedo); C is [column][albedo node][direction]. */
#ifndef PPB_MARCH_TABLES_H
#define PPB_MARCH_TABLES_H

#include "kernels/march_params.h"
#include "model/config.h"
#include "base/err.h"
#include "model/scene.h"

/* One column slab of the tables (march_params.h: column 0 left, 1 right of a density step). */
typedef struct ppb_march_col {
    double sigma_t; /* the column's extinction: the kernel selects the column by it */
    double tau0;    /* its optical thickness sigma_t H */
    double tau_h;   /* tau node spacing, tau0 / (ntau - 1) */
    int ntau;       /* tau nodes */
} ppb_march_col;

typedef struct ppb_march_tables {
    int nsamp; /* direction samples per bin axis */
    int ndir;  /* nvar x nsurf x nbins x nsamp^2, ordered by ppb_bin_sample_index per variant */
    int nvar;  /* direction variants: 1; at n > 1 in pp's tables 2 (slab) or 4 (tube): the
                * inside direction and its mirrors in y, x, both (march_tables.c) */
    int nalb;  /* albedo nodes */
    double alb0, alb_h;
    int ncols; /* column slabs, 1 or 2 (ss: 1) */
    ppb_march_col col[PPB_MARCH_MAX_COLS];
    int ntau;   /* tau nodes summed over the columns: R and S hold nalb x ndir x ntau values */
    int nmodes; /* modes of the slab solution, and how many the tables keep (n_e) */
    int modes_kept;
    double *R; /* [ncols][nalb][ndir][col.ntau], NULL for ss */
    double *S; /* same layout, NULL unless the S table was asked for */
    double *C; /* [ncols][nalb][ndir]; at nvar > 1 followed by as many for the upward beam */
} ppb_march_tables;

/* Single scattering: C = p(w.w_L), no tables. */
int ppb_march_tables_ss(const ppb_scene *sc, int nsamp, ppb_march_tables *t, ppb_err *err);

/* The plane-parallel tables: a slab solution (src/physics/ppsolver.h) of optical thickness
 * sigma_t H for every column and albedo node; the R table always (the S march falls back to it
 * on steps whose slope is not the slab's), the S table when pp->table asks for it. tau_per_mfp
 * sets the tau resolution. */
int ppb_march_tables_pp(const ppb_scene *sc, const ppb_pp_settings *pp, int nsamp, int tau_per_mfp,
                        ppb_march_tables *t, ppb_err *err);

void ppb_march_tables_free(ppb_march_tables *t);

/* Bytes a build of those tables (pp when with_modes, else ss) takes at its peak, estimated
 * before anything is allocated: the tables themselves (*tables, what the march uploads) plus
 * the build's scratch and the slab solver's matrices (about 24 of M/2 x M/2 doubles: phase
 * blocks, eigenproblem, boundary system, and the first solution kept for sharing). */
/* pp's table build in multiply-adds, estimated as the build does it: per column and albedo node
 * (pp.albedos nodes over an albedo step's range, one for one albedo) a slab solve of m = 2
 * directions cells (about 10 m^3), the mode coefficients of every table direction (ndir m^2) and
 * the R and S rows (ndir x ntau x m each); ndir counts the direction variants (4 in the tube at
 * n > 1, 2 in the slab). *solves gets the slab solves, *ndir the table directions. An albedo
 * step at n > 1 builds 9 x 4 = 36 times the tables of one albedo at n = 1. */
double ppb_march_tables_work(const ppb_scene *sc, const ppb_pp_settings *pp, int nsamp,
                             int tau_per_mfp, double *solves, double *ndir);

double ppb_march_tables_bytes(const ppb_scene *sc, const ppb_pp_settings *pp, int nsamp,
                              int tau_per_mfp, int with_modes, double *tables);

/* Cache of built tables for runs that follow each other (a sweep's grid points): it keeps the
 * last tables of each kind (pp, ss) with the parameters that shaped them (geometry, bins,
 * direction samples, g, theta_L, H, the columns' sigma_t, the albedo nodes, the solver's
 * directions and modes, the tau resolution, whether S is built) and hands them out again when a
 * later run asks with the same ones; anything else is rebuilt. The tables are deterministic,
 * so a hit is byte-identical to a fresh build. Owned by the caller (ppb_run_ctx.march_cache);
 * not thread-safe. */
typedef struct ppb_march_cache ppb_march_cache;

ppb_march_cache *ppb_march_cache_new(void);
void ppb_march_cache_free(ppb_march_cache *c);

/* The tables (pp when with_modes, else ss; pp may be NULL for ss), built or reused. *out stays
 * owned by the cache and valid until the next call of the same kind or ppb_march_cache_free. */
int ppb_march_cache_tables(ppb_march_cache *c, const ppb_scene *sc, const ppb_pp_settings *pp,
                           int nsamp, int tau_per_mfp, int with_modes, const ppb_march_tables **out,
                           ppb_err *err);

/* Calls answered from the cache, and builds. */
void ppb_march_cache_stats(const ppb_march_cache *c, long *hits, long *builds);

#endif
