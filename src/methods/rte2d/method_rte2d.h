/* method_rte2d.h: `rte2d`, the tube's radiative transfer solved by iterating the paper's
 * refinement (reference: Methods; paper Sec. 3.1, Eq. 5) on a grid over the cross-section.
 *
 * Pipeline: the grid and direction cells (physics/rte2d_grid.h); I_1, the once-scattered
 * radiance of every cell at every node, by one march of the exact direct beam's first
 * scattering; the scattered field I from (I - T S) I = I_1 (T the march of kernels/rte2d.cl, S
 * the folded phase matrix) by GMRES (physics/gmres.h) from I_pp, or K - 1 plain refinements
 * I <- T S I + I_1 from I_pp when `[rte2d] refinements = K` > 0; then the exit march: from
 * every segment point along every direction sample of every bin, the grid source for that
 * exact direction (the cell integrals F_j(w) of phase.h) plus the exact first scattering, as
 * `pp` averages its bins. So K = 1 is the paper's method (one march from I_pp) on the grid.
 * Totals: R, T, sides from the converged cell field at the faces (the balance's), ballistic
 * exact, and absorbed tracked: the beam's exact and sigma_a times the converged scattered
 * fluence. Under delta-M the light the scaled beam carries beyond the exact one leaves through
 * the faces as scattered light (finish_result).
 * n > 1 (reference: Medium): I_1 is the refracted beam's with its S2 -> S1 round trips (in
 * the oblique tube, off all four faces by the mirror images, as ss), T includes the walls'
 * reflection (a march reaching a face adds F times the mirror cell's radiance there, so GMRES
 * iterates it with the scattering), and the exit march maps each air-side sample inside by Snell,
 * (1 - F) / n^2.
 * Delta-M (`[rte2d] delta_m`, rte2d_grid.h's ppb_rte_delta_m, or ppb_rte_delta_m_series for
 * `legendre`, whose cells integrate the truncated Legendre series): all of this on the scaled
 * medium, the exit rays' first scattering with the exact phase (TMS). */
#ifndef PPB_METHOD_RTE2D_H
#define PPB_METHOD_RTE2D_H

#include "methods/method.h"
#include "model/metrics.h"

/* What a solve took (for `make perf` and tests). */
typedef struct ppb_rte2d_stats {
    int nodes, cells;     /* grid nodes, direction cells transported */
    int sweeps;           /* marches over the grid (I_1 included) */
    double resid;         /* final relative residual of (I - T S) I = I_1 (0 when K > 0) */
    int converged;        /* K = 0: the tolerance was reached */
    double t_total;       /* seconds, the whole method */
    double t_sweeps;      /* seconds in the grid marches */
    double t_exit;        /* seconds in the exit march and its source */
    double absorbed_beam; /* fractions of the power entering (totals.absorbed = their sum) */
    double absorbed_scattered;
    int record_rungs;  /* K = 0: rungs of the refinement study (rte2d_refinements.csv) */
    int record_sweeps; /* its sweeps (not in sweeps) */
    double t_record;   /* seconds it took (in t_total) */
    double delta_f;    /* delta-M's truncated fraction f (0: off, or not applied) */
    double clipped;    /* delta_m = legendre: the largest share of a phase row whose negative
                          cell integrals were set to 0 (physics/phase.h), else 0 */
} ppb_rte2d_stats;

/* The refinement study of a converged run (reference: rte2d_refinements.csv): run where the
 * context asks for extra outputs (ppb_run_ctx.extras: `ppbench run` does, and writes it with
 * the output set; a sweep point, which writes no table, does not), and carried by the result
 * (ppb_result.extra.data). */
#define PPB_RTE2D_RUNGS 10
typedef struct ppb_rte2d_study {
    int n;                                   /* rungs recorded; 0: none */
    int K[PPB_RTE2D_RUNGS];                  /* refinements */
    double rms[PPB_RTE2D_RUNGS][PPB_NCELLS]; /* rms_rel against the converged; NAN: no points */
} ppb_rte2d_study;

int ppb_method_rte2d(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Refuses what the solver cannot take before any work: a line searchlight (its first-scatter
 * source is a delta on a light plane, which the cells' beam integrals do not hold), and a grid
 * whose arrays, host and device together, exceed [run] memory_limit (the exit source of
 * surfaces x bins x bins.samples_dir^2 planes by the nodes of rte2d.spacing the largest), the
 * message naming the keys and the nearest settings that fit. */
int ppb_rte2d_check(const ppb_config *cfg, ppb_err *err);

/* The device's bound, known once it is open (the run checks it there, before the grid is
 * built): fails, naming device, the keys and what fits, when cfg's largest buffer (the exit
 * source) exceeds max_alloc bytes (its CL_DEVICE_MAX_MEM_ALLOC_SIZE). */
int ppb_rte2d_device_check(const ppb_config *cfg, double max_alloc, const char *device,
                           ppb_err *err);

/* The method, reporting what it took (tests, `make perf`; stats may be NULL): the refinement
 * study runs after a converged solve where ctx->extras is set. */
int ppb_rte2d_run(ppb_run_ctx *ctx, ppb_result *out, ppb_rte2d_stats *stats, ppb_err *err);

/* Writes dir/rte2d_refinements.csv (reference: Outputs) from study; nothing when study is NULL
 * or holds no rung. */
int ppb_rte2d_write_refinements(const ppb_rte2d_study *study, const char *dir, ppb_err *err);

/* plots/rte2d_refinements.{png,pdf} from dir's rte2d_refinements.csv, when the set has one (the
 * registry's draw hook). */
void ppb_rte2d_draw(const char *dir, const char *name, ppb_figures *fig);

#endif
