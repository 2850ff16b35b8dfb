/* ppb_tube.h: the tube's frame and the rays through it (reference: Geometry, Light), for host
 * and kernels.
 *
 * Owns: the cross-section's bounds x in [-W/2, W/2], y in [-H, 0] and the line of each face
 * S1..S4 (their numbering and outward normals are ppb_conventions.h's), where a straight ray
 * leaves the cross-section (its length and face), the mirror reflection at a face, and the
 * lengths along a ray where the medium or the light change: the step plane x = step_x, the light
 * line through S1 at the step (a shadow step's edge, or where the beam's path crosses a density
 * or albedo step) and the light line through S1's lit edge x' = -W/2 (oblique light;
 * x' = x + |y| tan(theta_L) is where the path toward the light meets S1's plane). The lit part
 * of S1 is [-W/2, ppb_tube_lit_hi).
 *
 * Plain C that is also OpenCL C, like ppb_conventions.h. Every function keeps the operations
 * (and their order) the marchers and walks had written out, so their results are the same bits. */
#ifndef PPB_TUBE_H
#define PPB_TUBE_H

#include "ppb_medium.h"

/* The line of face `face`: y of S1 (0) and S2 (-H), x of S3 (-W/2) and S4 (W/2). */
PPB_FN double ppb_face_line(int face, double width, double height)
{
    return face == PPB_S1   ? 0.0
           : face == PPB_S2 ? -height
           : face == PPB_S3 ? -0.5 * width
                            : 0.5 * width;
}

/* Whether the face is a side wall (S3, S4: its normal along x). */
PPB_FN int ppb_face_is_side(int face)
{
    return face == PPB_S3 || face == PPB_S4;
}

/* A surface's segment coordinate s (reference: Geometry): x on S1 and S2 from -W/2 over W, y on
 * S3 and S4 from -H over H. Where it starts, the surface's length, and the segment holding s. */
PPB_FN double ppb_face_start(int surf, double width, double height)
{
    return ppb_face_line(ppb_face_is_side(surf) ? PPB_S2 : PPB_S3, width, height);
}
PPB_FN double ppb_face_length(int surf, double width, double height)
{
    return ppb_face_is_side(surf) ? height : width;
}
PPB_FN int ppb_segment_at(int surf, double s, int nseg, double width, double height)
{
    return ppb_segment_of(s, ppb_face_start(surf, width, height),
                          ppb_face_length(surf, width, height), nseg);
}

/* Segment centres (reference: Geometry): S1/S2 numbered along x from -W/2, S3/S4 along y from -H.
 * Returns the coordinate s along the surface; (x, y) is the point. Slab mode uses s = 0. */
PPB_FN double ppb_segment_centre(int surf, int seg, int nseg, double width, double height,
                                 double *x, double *y)
{
    if (!ppb_face_is_side(surf)) {
        double s = ppb_face_line(PPB_S3, width, height) + (seg + 0.5) * width / nseg;
        *x = s;
        *y = ppb_face_line(surf, width, height);
        return s;
    }
    double s = ppb_face_line(PPB_S2, width, height) + (seg + 0.5) * height / nseg;
    *x = ppb_face_line(surf, width, height);
    *y = s;
    return s;
}

/* Length of one segment of a tube surface: W / nseg on S1 and S2, H / nseg on S3 and S4. */
PPB_FN double ppb_segment_length(int surf, int nseg, double width, double height)
{
    return ppb_face_length(surf, width, height) / nseg;
}

/* Point ip of npts spread evenly along segment seg, where a deterministic method averages the
 * segment (reference: Bins); slab mode: the one point of the face (S1 or S2), at x = 0. */
PPB_FN void ppb_segment_sample(int tube, int surf, int seg, int nseg, double width, double height,
                               int ip, int npts, double *px, double *py)
{
    double cx = 0.0, cy = ppb_face_line(surf == PPB_S1 ? PPB_S1 : PPB_S2, width, height);
    double seglen = 0.0;
    int along_x = !ppb_face_is_side(surf);
    if (tube) {
        ppb_segment_centre(surf, seg, nseg, width, height, &cx, &cy);
        seglen = ppb_segment_length(surf, nseg, width, height);
    }
    double o = ((ip + 0.5) / npts - 0.5) * seglen;
    *px = cx + (along_x ? o : 0.0);
    *py = cy + (along_x ? 0.0 : o);
}

/* Length from (px, py) along (mx, my) to the line of S1 or S2 the ray moves toward, and to the
 * side wall it moves toward; INFINITY for a ray parallel to them. */
PPB_FN double ppb_tube_length_y(double height, double py, double my)
{
    return my > 0.0 ? -py / my : (my < 0.0 ? (-height - py) / my : INFINITY);
}
PPB_FN double ppb_tube_length_x(double width, double px, double mx)
{
    return mx > 0.0 ? (0.5 * width - px) / mx : (mx < 0.0 ? (-0.5 * width - px) / mx : INFINITY);
}

/* The face a ray along (mx, my) reaches first, from its lengths to the side walls (lx) and to
 * S1/S2 (ly): a side wall only when strictly nearer. */
PPB_FN int ppb_tube_face_of(double lx, double ly, double mx, double my)
{
    return lx < ly ? (mx > 0.0 ? PPB_S4 : PPB_S3) : (my > 0.0 ? PPB_S1 : PPB_S2);
}

/* Length of the ray from (px, py) along the in-plane direction (mx, my) (per unit 3-D length)
 * to where it leaves the cross-section: through S1 or S2, or a side wall in the tube. INFINITY
 * for a ray parallel to a slab's faces. */
PPB_FN double ppb_exit_length(int tube, double width, double height, double px, double py,
                              double mx, double my)
{
    double l = ppb_tube_length_y(height, py, my);
    return tube ? fmin(l, ppb_tube_length_x(width, px, mx)) : l;
}

/* The exit of that ray: the face it leaves through (S1/S2 only in a slab) and, in *l, its
 * length (INFINITY for a ray parallel to a slab's faces). */
PPB_FN int ppb_exit_face(int tube, double width, double height, double px, double py, double mx,
                         double my, double *l)
{
    double ly = ppb_tube_length_y(height, py, my);
    double lx = tube ? ppb_tube_length_x(width, px, mx) : INFINITY;
    *l = fmin(lx, ly);
    return ppb_tube_face_of(lx, ly, mx, my);
}

/* A smooth wall's mirror reflection (reference: Medium): moves (x, y) by length l along
 * (dx, dy) onto face, the coordinate across the face set to its line exactly (no drift over
 * many bounces), and mirrors (dx, dy) in the face. */
PPB_FN void ppb_tube_reflect(int face, double width, double height, double l, double *x, double *y,
                             double *dx, double *dy)
{
    if (ppb_face_is_side(face)) {
        *x = ppb_face_line(face, width, height);
        *y += l * *dy;
        *dx = -*dx;
    } else {
        *x += l * *dx;
        *y = ppb_face_line(face, width, height);
        *dy = -*dy;
    }
}

/* The upper end of S1's lit part: W/2, or a shadow step's x (reference: Light). */
PPB_FN double ppb_tube_lit_hi(const ppb_medium *M)
{
    double hi = 0.5 * M->width;
    return M->step == PPB_STEP_SHADOW ? fmin(hi, M->step_x) : hi;
}

/* Whether the light path that meets S1's plane at x' is lit: x' on S1 (x' >= -W/2, less the
 * caller's tolerance tol) and, with a shadow step, left of its edge (reference: Light). */
PPB_FN int ppb_tube_lit_at(const ppb_medium *M, double xp, double tol)
{
    return xp >= -0.5 * M->width - tol && (M->step != PPB_STEP_SHADOW || xp < M->step_x);
}

/* The medium of the piece [la, lb] of the ray from (px, py) along (mx, my), read at the piece's
 * middle x: one sigma_t and alpha hold along a piece, as pieces are cut at the step plane
 * (ppb_tube_breaks). */
PPB_FN void ppb_piece_medium(const ppb_medium *M, double px, double mx, double la, double lb,
                             double *sigma_t, double *alpha)
{
    double xm = px + 0.5 * (la + lb) * mx;
    *sigma_t = ppb_medium_sigma_t(M, xm);
    *alpha = ppb_medium_albedo(M, xm);
}

/* Where a ray from (px, py) along (mx, my) crosses the lines where the medium or the direct
 * light change (tube only): the step plane x = step_x (density or albedo step), the light line
 * through S1 at x' = step_x (any step) and the light line through S1's lit edge x' = -W/2
 * (oblique light, tan_l = tan(theta_L) inside). Appends the lengths that lie in (0, lfar),
 * 1e-12 clear of both ends, to brk[nb..] in that order and returns the new count (at most
 * nb + 3). */
PPB_FN int ppb_tube_breaks(const ppb_medium *M, double tan_l, double px, double py, double mx,
                           double my, double lfar, double *brk, int nb)
{
    double dxp = mx + my * tan_l, xp = px + py * tan_l;
    double cand[3] = {-1.0, -1.0, -1.0};
    if ((M->step == PPB_STEP_DENSITY || M->step == PPB_STEP_ALBEDO) && mx != 0.0)
        cand[0] = (M->step_x - px) / mx;
    if (M->step != PPB_STEP_NONE && dxp != 0.0)
        cand[1] = (M->step_x - xp) / dxp;
    if (tan_l > 0.0 && dxp != 0.0)
        cand[2] = (-0.5 * M->width - xp) / dxp;
    for (int k = 0; k < 3; k++)
        if (cand[k] > 1e-12 && cand[k] < lfar - 1e-12)
            brk[nb++] = cand[k];
    return nb;
}

#endif
