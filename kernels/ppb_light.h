/* ppb_light.h: S1's lit part as the marchers read it (reference: Light), for host and kernels.
 *
 * Owns: a searchlight's strip (ppb_lit: [lo, hi], filled by the host's ppb_lit_of from
 * ppb_scene_lit_range, the one definition) on top of the whole face and the shadow step, which
 * stay ppb_tube.h's (ppb_tube_lit_hi, ppb_tube_lit_at, ppb_tube_breaks): the lit part's ends,
 * whether the light path meeting S1's plane at x' is lit, and the light lines through the
 * strip's edges where a ray's pieces are cut. Without a strip every function here is ppb_tube.h's,
 * bit for bit. The Monte Carlo reads none of it (its photons enter over the strip, set by
 * method_mc.c), so mc.cl's source, and the shipped references keyed by it, are unchanged.
 *
 * Plain C that is also OpenCL C, like ppb_conventions.h. Two doubles, then two ints. */
#ifndef PPB_LIGHT_H
#define PPB_LIGHT_H

#include "ppb_tube.h"

typedef struct ppb_lit {
    double lo, hi; /* the strip [lo, hi] (lo == hi: a line), read only when strip is 1 */
    int strip;     /* 1: [light] lit = strip; 0: the whole face (left of a shadow step) */
    int pad;
} ppb_lit;

/* The ends of S1's lit part: the strip's, else -W/2 and ppb_tube_lit_hi. */
PPB_FN double ppb_lit_lo(const ppb_medium *M, const ppb_lit *L)
{
    return L->strip ? L->lo : -0.5 * M->width;
}
PPB_FN double ppb_lit_hi(const ppb_medium *M, const ppb_lit *L)
{
    return L->strip ? L->hi : ppb_tube_lit_hi(M);
}

/* Whether the light path that meets S1's plane at x' is lit: in the strip, lo - tol <= x' < hi
 * (at hi = W/2 the caller bounds x' by S4, as for the whole face; a line lights no path: its
 * methods take it apart), else ppb_tube_lit_at. */
PPB_FN int ppb_lit_at(const ppb_medium *M, const ppb_lit *L, double xp, double tol)
{
    if (!L->strip)
        return ppb_tube_lit_at(M, xp, tol);
    return xp >= L->lo - tol && (!(L->hi < 0.5 * M->width) || xp < L->hi);
}

/* ppb_tube_breaks, then the light lines through the strip's edges inside S1 (x' = lo > -W/2,
 * x' = hi < W/2), appended on the same terms (in (0, lfar), 1e-12 clear of both ends): at most
 * nb + 5 in all (a strip is never cut by a shadow step: config.c refuses the two together). */
PPB_FN int ppb_lit_breaks(const ppb_medium *M, const ppb_lit *L, double tan_l, double px, double py,
                          double mx, double my, double lfar, double *brk, int nb)
{
    nb = ppb_tube_breaks(M, tan_l, px, py, mx, my, lfar, brk, nb);
    double dxp = mx + my * tan_l, xp = px + py * tan_l;
    if (!L->strip || dxp == 0.0)
        return nb;
    double cand[2] = {L->lo > -0.5 * M->width ? (L->lo - xp) / dxp : -1.0,
                      L->hi < 0.5 * M->width ? (L->hi - xp) / dxp : -1.0};
    for (int k = 0; k < 2; k++)
        if (cand[k] > 1e-12 && cand[k] < lfar - 1e-12)
            brk[nb++] = cand[k];
    return nb;
}

#endif
