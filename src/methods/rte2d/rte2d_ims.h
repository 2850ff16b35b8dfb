/* rte2d_ims.h: the intensity correction of rte2d's exit radiance under delta-M for the light
 * scattered only within the truncated forward peak (Nakajima and Tanaka 1988, IMS; reference:
 * Methods, `rte2d`, delta-M).
 *
 * Owns: the correction's source, added to the exit march's grid source J of every exit sample
 * direction, and the small-angle model it comes from. Delta-M writes p = f p'' + (1 - f) p*
 * and counts the residual peak p'' as no scattering, so the scaled beam carries the light
 * scattered only in the peak as if unscattered; the exit then gives the beam's first scattering
 * with the exact phase (TMS). Along the beam (optical path s from where it enters, a = f alpha,
 * x = a s), with the peak's scatterings taken as small-angle (the path length unchanged), the
 * Legendre moments of the peak-only light are, exactly,
 *     e^-s (e^{x gt_l} - 1),               gt_l the moments of p'',
 * while delta-M with TMS gives gt_l x e^{-s + x} (the once-scattered light on the scaled beam).
 * Their difference is the radiance a source of moments
 *     S_l = a e^-s [1 - gt_l e^x + (gt_l - 1) e^{gt_l x}]   per unit optical path
 * produces when attenuated with the scaled extinction, as the march attenuates (dC/ds +
 * (1 - a) C = S for C the difference). To second order S_l = a x (gt_l^2 - 2 gt_l) e^-s, the
 * (p'' * p'' - 2 p'') of Nakajima and Tanaka's Eq. (A13) as DISORT codes it; here every order is
 * kept (x reaches 0.55 at the top of the g 0.9 tube's S2). Expanded as a power series in x,
 *     S(node, w) = sum_k A_k(w . w_beam) B_k(node),  A_k = sum_l (2l + 1) / 4 pi P_l c_lk,
 * c_lk = gt_l^(k+1) - gt_l^k - gt_l, B_k = (x^k / k!) e^-s times the beam's irradiance: one matrix
 * product adds it to every exit direction's source plane. The passes: the refracted beam down,
 * and at n > 1 where the beam stays in its column (normal light, or the slab) its reflection off
 * S2 (the peak light reflects with it), the further round trips (F_b^2 e^-2tau of it) left out;
 * at oblique light in the tube at n > 1 the beam's wall images are left out too. */
#ifndef PPB_RTE2D_IMS_H
#define PPB_RTE2D_IMS_H

#include "base/err.h"
#include "methods/rte2d/rte2d_grid.h"

typedef struct ppb_rte_ims {
    int m;     /* columns: passes x series terms; 0 = no correction */
    double *A; /* [ndir][m]: the angular factors of each exit sample */
    double *B; /* [m][nnodes]: the depth factors at each node, per unit scattering coefficient */
} ppb_rte_ims;

/* The correction for the exit samples w ([ndir][3], inside directions) on the grid G of the
 * scaled medium (its P holds the scaled sigma_t and the refracted beam), the exact medium's g
 * and albedo, the truncation f (> 0) and the retained phase G->phase. */
int ppb_rte_ims_make(const ppb_rte_grid *G, double g, double albedo, double f, const double *w,
                     int ndir, ppb_rte_ims *m, ppb_err *err);
void ppb_rte_ims_free(ppb_rte_ims *m);

/* Jx [ndir][nnodes] += A B. */
void ppb_rte_ims_add(const ppb_rte_ims *m, int ndir, int nnodes, double *Jx);

/* The residual peak's Legendre moment gt_l = (g^l - (1 - f) chi*_l) / f, chi*_l the retained
 * function's (ph: its series, or HG of ph->g). */
double ppb_rte_ims_moment(double g, double f, const pp_phase_fn *ph, int l);

#endif
