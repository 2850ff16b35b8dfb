/* rte2d.cl: the sweeps and the exit march of `rte2d` (reference: Methods; paper Sec. 3.1, Eq. 5).
 *
 * One refinement of Eq. 5, I_n = K I_(n-1) + I_0, is a sweep of every direction cell's tracks
 * through the flat-source regions (ppb_rte_moc, below: conservative by construction). The exit
 * radiance is a march from every segment point in every direction sample of every bin
 * (ppb_rte_exit), as `pp` averages its bins (reference: Bins; ppb_bin_sample_dir's samples and
 * weights, the first and last theta rows graded toward the normal and the tangent plane),
 * along q = p - l w:
 *     I(p, w) = integral_0^l_far exp(-d(l)) sigma_s(q) [J(q, w) + C(w) E(q)] dl,
 * where J is the converged scattered-light source per unit scattering coefficient (bilinear in
 * the nodes, whose values keep each dual region's average, ppb_rte_to_nodes) and C E the direct
 * beam's first scattering, exact: E = lit exp(-D) with D linear along each piece, C = p(w.w_L) (as
 * `ss`). Under delta-M (reference: Methods, `rte2d`) sigma_t, alpha and g are the scaled ones
 * and C = p_g(w.w_L) / (1 - f) with the medium's own g (P.ss_g, P.ss_w): the truncated phase's
 * first scattering replaced by the exact one's (Nakajima and Tanaka 1988, TMS).
 *
 * The ray is cut into pieces where sigma_t, alpha or D's slope change or the light is cut off
 * (the step plane x = step_x, the light lines x' = step_x and x' = -W/2), as march.cl cuts them.
 * In a piece (sigma_t, sigma_s, lit constant):
 *   beam: exactly  alpha C lit sigma_t len e^{-d_a - D_a} phi1(-(sigma_t len + D_b - D_a)),
 *   grid source: steps of planar length <= hstep, J linear between a step's ends and the
 *   exponential integrated exactly: alpha e^{-d_1} [J_1 a + (J_2 - J_1)(a / x - 1 + a)],
 *   x = sigma_t h, a = 1 - e^{-x}; exact for a source linear along the step whatever its
 *   optical length (directions close to z cross many mfp in a short planar distance). */
#include "ppb_beam_images.h"
#include "ppb_bin_samples.h"
#include "ppb_fresnel.h"
#include "ppb_sort.h"
#include "rte2d_ls.h"
#include "rte2d_params.h"

/* exp(e_a) phi1(z) with e_b = e_a + z <= 0, in the scaled form where exp(e_a) underflows (as
 * ppb_beam_step, ppb_beam_images.h, in another association). */
inline double rte_beam_factor(double e_a, double z)
{
    if (e_a < -700.0 && z > 0.0)
        return exp(e_a + z) * (-expm1(-z) / z);
    return exp(e_a) * ppb_phi1(z);
}

/* Weight of the slope term: (1 - e^{-x}) / x - e^{-x}, i.e. a / x - 1 + a, with its series where
 * the difference cancels. */
inline double rte_w1(double x, double a)
{
    if (x < 1e-4)
        return x * (0.5 - x * (1.0 / 3.0 - x * 0.125));
    return a / x - 1.0 + a;
}

/* n > 1, the tube at oblique incidence: the refracted beam meets the side walls too, unfolded
 * over the cross-section's mirror images as in `ss` (ppb_beam_images.h), through the step's
 * images with a density step. cb: the phase coefficients of (+sin, down), (+sin, up),
 * (-sin, down), (-sin, up). Returns the sum before the albedo; d0 is the optical distance at
 * la. */
inline double rte_beam_images(const ppb_rte_params *P, const double *cb, double px, double py,
                              double mx, double my, double la, double lb, double sigma_t, double d0)
{
    ppb_beam_tube B = PPB_BEAM_TUBE(P, sin_theta_l);
    return ppb_beam_images(&B, cb, px, py, mx, my, la, lb, sigma_t, d0);
}

/* n > 1: the radiance entering at the wall the ray from (px, py) along (mx, my) reaches after
 * length lfar and optical depth d, reflected: e^{-d} F I(mirror, q), I the converged field rad of
 * the cell holding the direction mirrored in that face at the wall point q (bilinear), F the
 * exact reflectance of the sample direction (wx, wy): the boundary condition I_in = F I_out(mirror)
 * of a smooth dielectric face (reference: Medium). */
inline double rte_wall(const ppb_rte_params *P, __global const double *rad,
                       __global const double *bnd, double px, double py, double mx, double my,
                       double wx, double wy, double lfar, double d)
{
    double l;
    int face = ppb_exit_face(P->med.tube, P->med.width, P->med.height, px, py, mx, my, &l);
    double F = ppb_fresnel(fabs(ppb_face_is_side(face) ? wx : wy), 1.0 / P->med.n);
    int slot = (int)bnd[face];
    double qx = px + lfar * mx, qy = py + lfar * my;
    return exp(-d) * F * ppb_rte_lookup(P, rad + (long)slot * ppb_rte_nnodes(P), qx, qy);
}

/* Radiance leaving (px, py) in direction w = (wx, wy, .) (3-D unit vector; the march advances
 * (-wx, -wy) in the plane per unit length): grid source from plane (if P->diffuse) plus the beam
 * term with coefficient C (if P->beam). */
inline double rte_ray_side(const ppb_rte_params *P, __global const double *plane, const double *cb,
                           __global const double *rad, __global const double *bnd, double px,
                           double py, double wx, double wy)
{
    double C = cb[0];
    double mx = -wx, my = -wy;
    /* A direction in a wall's plane must run along it: the cells centred at phi = pi/2 have
     * wx = cos(pi/2) ~ 6e-17, not 0, and that sign made lfar = 0 at the nodes of S3 alone, so
     * those cells carried no radiance there and S3 came out ~1 % below S4. A planar
     * component under 1e-12 moves the ray under 4e-11 mfp before d_cap stops it. */
    if (fabs(mx) < 1e-12)
        mx = 0.0;
    if (fabs(my) < 1e-12)
        my = 0.0;
    double lfar = ppb_exit_length(P->med.tube, P->med.width, P->med.height, px, py, mx, my);
    double sig_min = ppb_medium_sigma_min(&P->med);
    int wall = P->refl && !(lfar > P->d_cap / sig_min);
    lfar = fmax(0.0, fmin(lfar, P->d_cap / sig_min));
    if (lfar <= 0.0)
        return wall ? rte_wall(P, rad, bnd, px, py, mx, my, wx, wy, 0.0, 0.0) : 0.0;

    double brk[9]; /* 0, two layer lines, at most five breaks (ppb_lit_breaks), lfar */
    int nb = 0;
    brk[nb++] = 0.0;
    /* The boundary layers' lines: inside them the march steps shrink with the rows. */
    if (P->nyl > 0 && my != 0.0) {
        double ly[2] = {(-P->dlay - py) / my, (-(P->med.height - P->dlay) - py) / my};
        for (int k = 0; k < 2; k++)
            if (ly[k] > 1e-12 && ly[k] < lfar - 1e-12)
                brk[nb++] = ly[k];
    }
    /* The step plane and the light lines through S1's lit edges (ppb_light.h). */
    if (P->med.tube)
        nb = ppb_lit_breaks(&P->med, &P->lit, P->tan_theta_l, px, py, mx, my, lfar, brk, nb);
    ppb_sort_doubles(brk + 1, nb - 1); /* brk[0] = 0 stays first */
    brk[nb++] = lfar;

    double sperp = sqrt(mx * mx + my * my);
    double d = 0.0, L = 0.0;
    for (int k = 0; k + 1 < nb && d < P->d_cap; k++) {
        double la = brk[k], lb = brk[k + 1], len = lb - la;
        if (len <= 0.0)
            continue;
        double xm = px + 0.5 * (la + lb) * mx, ym = py + 0.5 * (la + lb) * my, sigma_t, alpha;
        ppb_piece_medium(&P->med, px, mx, la, lb, &sigma_t, &alpha);
        double sum = 0.0;
        if (P->beam && ppb_rte_beam_images(P)) {
            sum += rte_beam_images(P, cb, px, py, mx, my, la, lb, sigma_t, d);
        } else if (P->beam && C != 0.0) {
            double Dm, Da, Db;
            int lit, la_lit, lb_lit;
            ppb_rte_light(P, xm, ym, &Dm, &lit);
            if (lit) {
                /* D is linear along a piece, but not continuous at its ends: at normal incidence
                 * it jumps where the ray crosses a density step, and an end on the step plane
                 * took the other side's slope (S2 came out 2.5 % low left of the step and 5 %
                 * high right of it). So D at the ends is extrapolated from the piece's
                 * points at 1/4 and 3/4, exact for a linear D. */
                double l1 = la + 0.25 * len, l2 = la + 0.75 * len;
                ppb_rte_light(P, px + l1 * mx, py + l1 * my, &Da, &la_lit);
                ppb_rte_light(P, px + l2 * mx, py + l2 * my, &Db, &lb_lit);
                double slope = Db - Da;
                Da -= 0.5 * slope;
                Db += 0.5 * slope;
                if (P->med.n > 1.0) {
                    /* The refracted beam and its reflection off S2 (optical depth 2 D_b - D),
                     * every further round trip S2 -> S1 -> S2 summed: 1 / (1 - F_b^2 e^{-2 D_b})
                     * (as march.cl's ppb_piece_fresnel; D_b the column's: the slab, or the
                     * tube at normal incidence, where the beam stays in its column). */
                    double db = sigma_t * P->med.height / P->cos_theta_l;
                    double e = P->beam_in / (1.0 - P->beam_fb * P->beam_fb * exp(-2.0 * db));
                    sum += e * C * sigma_t * len *
                           rte_beam_factor(-(d + Da), -(sigma_t * len + Db - Da));
                    sum += e * P->beam_fb * cb[1] * sigma_t * len *
                           rte_beam_factor(-(d + 2.0 * db - Da), -(sigma_t * len - Db + Da));
                } else
                    sum +=
                        C * sigma_t * len * rte_beam_factor(-(d + Da), -(sigma_t * len + Db - Da));
            }
        }
        if (P->diffuse) {
            /* Steps of at most hstep in the plane and hstep dy / hy across the rows, dy the
             * piece's finest row spacing (a layer piece: hyf), so a step crosses no more of a
             * fine row than of a middle one. */
            double dy =
                (P->nyl > 0 && (-ym < P->dlay || -ym > P->med.height - P->dlay)) ? P->hyf : P->hy;
            double ns = fmax(len * sperp / P->hstep, len * fabs(my) * P->hy / (P->hstep * dy));
            int n = max(1, (int)ceil(ns));
            double h = len / n, x = sigma_t * h, a = -expm1(-x), w1 = rte_w1(x, a);
            double att = exp(-x), e = exp(-d);
            double J1 = ppb_rte_lookup(P, plane, px + la * mx, py + la * my);
            for (int i = 0; i < n && d + x * i < P->d_cap; i++, e *= att) {
                double l2 = la + h * (i + 1);
                double J2 = ppb_rte_lookup(P, plane, px + l2 * mx, py + l2 * my);
                sum += e * (J1 * a + (J2 - J1) * w1);
                J1 = J2;
            }
        }
        L += alpha * sum;
        d += sigma_t * len;
    }
    if (wall && d < P->d_cap)
        L += rte_wall(P, rad, bnd, px, py, mx, my, wx, wy, lfar, d);
    return L;
}

/* rte_ray, but a ray lying in the step plane itself (a node on the step line, in a cell with
 * wx = 0) would see one side's medium and light along its whole length, whichever the rounding
 * chose: it takes the mean of the two sides, as the node's bilinear hat straddles both. (Taking
 * the right side alone moved R_x0, at the step, by 0.1-0.2 % in albedo_step and shadow_step.) */
inline double rte_ray(const ppb_rte_params *P, __global const double *plane, const double *cb,
                      __global const double *rad, __global const double *bnd, double px, double py,
                      double wx, double wy)
{
    if (P->med.tube && P->med.step != PPB_STEP_NONE && px == P->med.step_x && fabs(wx) < 1e-12) {
        double e = 1e-9 * P->med.width;
        return 0.5 * (rte_ray_side(P, plane, cb, rad, bnd, px - e, py, wx, wy) +
                      rte_ray_side(P, plane, cb, rad, bnd, px + e, py, wx, wy));
    }
    return rte_ray_side(P, plane, cb, rad, bnd, px, py, wx, wy);
}

/* One work-item per (segment row, bin): the bin-averaged exit radiance over the segment's points
 * and the bin's direction samples (reference: Bins), as march.cl's ppb_march_kernel. */
__kernel void ppb_rte_exit(const ppb_rte_params P, __global const double *dirs,
                           __global const double *src, __global double *out,
                           __global const double *rad, __global const double *bnd)
{
    int nbins = ppb_bin_count(P.ntheta, P.nphi), seg, bin;
    int surf = ppb_exit_cell((int)get_global_id(0), P.row0, nbins, P.offset, P.nseg, &seg, &bin);
    if (surf < 0)
        return;
    int nn = ppb_rte_nnodes(&P);
    int ns = ppb_exit_nsamples(&P.med, P.npts, P.nsamp);
    double sum = 0.0;
    for (int k = 0; k < ns; k++) {
        double px, py, v[3], wk;
        int dir = ppb_exit_sample(&P.med, surf, seg, P.nseg[surf], bin, P.npts, P.nsamp, P.ntheta,
                                  P.nphi, k, &px, &py, v, &wk);
        /* The host's copy of that sample (method_rte2d.c, exit_setup: the same
         * ppb_bin_sample_dir), the direction its cell slots and mirrors were looked up for. */
        v[0] = dirs[3 * dir], v[1] = dirs[3 * dir + 1], v[2] = dirs[3 * dir + 2];
        if (P.med.n > 1.0) {
            /* Air-side sample w = v: inside along Snell's direction, (1 - F) / n^2 times the
             * inside radiance (the n^2 law, reference: Medium). */
            double ca = ppb_inside_dir(surf, P.med.n, v);
            double wt = (1.0 - ppb_fresnel(ca, P.med.n)) / (P.med.n * P.med.n);
            double cb[4];
            ppb_beam_phases(P.ss_g, P.sin_theta_l, P.cos_theta_l, v[0], v[1], cb);
            for (int c = 0; c < 4; c++)
                cb[c] *= P.ss_w;
            sum += wk * wt *
                   rte_ray(&P, src + (long)dir * nn, cb, rad, bnd + 4 * dir, px, py, v[0], v[1]);
            continue;
        }
        double cb[4] = {P.ss_w * ppb_hg_phase(P.ss_g, v[0] * P.sin_theta_l - v[1] * P.cos_theta_l),
                        0.0, 0.0, 0.0};
        sum += wk * rte_ray(&P, src + (long)dir * nn, cb, rad, bnd, px, py, v[0], v[1]);
    }
    out[ppb_cell_index(P.offset[surf], seg, nbins, bin)] = sum / ns;
}

/* ---- The conservative sweep: a flat-source method of characteristics (reference: Methods) ----
 *
 * The unknown of the solve is the average radiance of every transported direction cell over every
 * flat-source region (FSR, the grid nodes' dual cells, rte2d_params.h). A direction's parallel
 * tracks, spacing delta perpendicular to its planar direction u = (w_x, w_y) / s, cross the FSRs;
 * along a track segment of planar length l in an FSR of sigma_t with flat emission Q, the 3-D path
 * is L = l / s and the radiance leaves as
 *     psi_out = psi_in e^{-tau} + (Q / sigma_t)(1 - e^{-tau}),   tau = sigma_t L,
 * the exact solution for a flat source. Integrated over the segment, the transport equation reads
 * sigma_t psi_bar L = Q L + psi_in - psi_out; times the track's planar flux s delta and summed over
 * the segments in the FSR (area A), the FSR's balance is
 *     sigma_t psi_FSR A = Q A + s delta sum (psi_in - psi_out),
 * and psi_FSR is taken from it (the balance form): every FSR then conserves exactly for the
 * tracks laid, so the solve's R + T + sides + absorbed + ballistic = 1 holds to the solver's
 * tolerance whatever the grid (the tracks' quadrature moves the answer, not the balance). What a
 * track carries out through a boundary edge, s delta psi_out, is that edge's outgoing power per sr
 * and unit z; what enters (n > 1: the walls' reflection, host side) is shared among the tracks
 * entering through the edge so that their s delta psi_in sum to it exactly. */

typedef struct moc_grid {
    int nfx, ny;
    __global const double *fx, *fy;
} moc_grid;

/* The interval [e_k, e_(k+1)] of the n + 1 ascending (asc) or descending edges holding v,
 * clamped to [0, n - 1]. */
inline int moc_find(__global const double *e, int n, double v, int asc)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (asc ? v >= e[mid] : v <= e[mid])
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* The radiance leaving a segment of 3-D length L and optical length tau = sigma_t L that psi
 * entered, with flat emission q: exact for the flat source, its first order where e^{-tau}
 * would lose the difference. */
inline double moc_segment(double psi, double q, double st, double tau, double L)
{
    if (tau < 1e-8)
        return psi + (q - st * psi) * L;
    double e = exp(-tau);
    return psi * e + (q / st) * (1.0 - e);
}

/* One track: the line p0 + t u (planar), v_k its perpendicular offset. mode 0 counts it at its
 * entry edge (scr += 1); mode 1 transports psi_in = scr[entry edge] through the FSRs, adding each
 * segment's s delta (psi_in - psi_out) to tal and the exit's s delta psi to bout. */
inline void moc_track(const ppb_rte_params *P, const moc_grid *g, double ux, double uy, double s,
                      double delta, double vk, __global const double *sig, __global const double *Q,
                      __global const double *Qg, __global double *tal, __global double *bout,
                      __global double *scr, __global double *acc, int mode)
{
    double W = P->med.width, H = P->med.height, p0x = -uy * vk, p0y = ux * vk;
    /* Where the line crosses the lines of S3/S4 (tx) and S1/S2 (ty), ascending in t: it leaves
     * through the face u moves toward (ppb_tube.h) and came in through the opposite one. */
    double txa = -INFINITY, txb = INFINITY, tya = -INFINITY, tyb = INFINITY;
    if (ux != 0.0) {
        txa = -ppb_tube_length_x(W, p0x, -ux);
        txb = ppb_tube_length_x(W, p0x, ux);
    } else if (p0x <= ppb_face_line(PPB_S3, W, H) || p0x >= ppb_face_line(PPB_S4, W, H))
        return;
    if (uy != 0.0) {
        tya = -ppb_tube_length_y(H, p0y, -uy);
        tyb = ppb_tube_length_y(H, p0y, uy);
    } else if (p0y >= ppb_face_line(PPB_S1, W, H) || p0y <= ppb_face_line(PPB_S2, W, H))
        return;
    double tin = fmax(txa, tya), tout = fmin(txb, tyb);
    if (!(tout > tin))
        return;
    int i, j, edge;
    double xin = p0x + tin * ux, yin = p0y + tin * uy;
    if (txa > tya) { /* through S3 (moving +x) or S4 */
        i = ux > 0.0 ? 0 : g->nfx - 1;
        j = moc_find(g->fy, g->ny, yin, 0);
        edge = ppb_moc_edge0(g->nfx, g->ny, ux > 0.0 ? PPB_S3 : PPB_S4) + j;
    } else { /* through S1 (moving down) or S2 */
        j = uy < 0.0 ? 0 : g->ny - 1;
        i = moc_find(g->fx, g->nfx, xin, 1);
        edge = ppb_moc_edge0(g->nfx, g->ny, uy < 0.0 ? PPB_S1 : PPB_S2) + i;
    }
    if (mode == 0) {
        scr[edge] += 1.0;
        return;
    }
    double w = s * delta, psi = scr[edge], t = tin;
    int di = ux > 0.0 ? 1 : -1, dj = uy < 0.0 ? 1 : -1; /* j counts down the rows */
    for (;;) {
        double tnx = ux != 0.0 ? (g->fx[i + (ux > 0.0)] - p0x) / ux : INFINITY;
        double tny = uy != 0.0 ? (g->fy[j + (uy < 0.0)] - p0y) / uy : INFINITY;
        double tn = fmin(fmin(tnx, tny), tout), l = tn - t;
        if (l > 0.0) {
            int f = j * g->nfx + i;
            double st = sig[i], po;
            if (P->ls) {
                /* The source at the entry and its slope per 3-D length along the segment. */
                double dx = p0x + t * ux - 0.5 * (g->fx[i] + g->fx[i + 1]),
                       dy = p0y + t * uy - 0.5 * (g->fy[j] + g->fy[j + 1]), i0, i1;
                double b = Q[f] + Qg[2 * f] * dx + Qg[2 * f + 1] * dy,
                       c = (Qg[2 * f] * ux + Qg[2 * f + 1] * uy) * s;
                po = ppb_ls_segment(psi, b, c, st, st * l / s, l / s, &i0, &i1);
                ppb_ls_add(acc + PPB_MOC_LS_ACC * f, w, delta, dx, dy, ux, uy, s, l, i0, i1);
            } else
                po = moc_segment(psi, Q[f], st, st * l / s, l / s);
            tal[f] += w * (psi - po);
            psi = po;
            t = tn;
        }
        /* Advance; a tie (a corner) crosses both lines. */
        int ax = tnx <= tny, ay = tny <= tnx;
        int ni = ax ? i + di : i, nj = ay ? j + dj : j;
        int outx = ni < 0 || ni >= g->nfx, outy = nj < 0 || nj >= g->ny;
        if (tn >= tout || outx || outy) {
            /* The face left through: the line crossed out of the grid (x at a corner), or where
             * the track ends when rounding ended it a hair before its last crossing. */
            int xface = (outx || outy) ? outx : txb < tyb;
            int out = xface ? ppb_moc_edge0(g->nfx, g->ny, ux > 0.0 ? PPB_S4 : PPB_S3) + j
                            : ppb_moc_edge0(g->nfx, g->ny, uy < 0.0 ? PPB_S2 : PPB_S1) + i;
            bout[out] += w * psi;
            return;
        }
        i = ni;
        j = nj;
    }
}

/* n > 1: the power entering each edge, shared among the tracks entering there (scr holds their
 * count on entry, psi_in on return). An edge no track enters (a direction grazing the face)
 * hands its power to the face's next edge that has one (the last such edge takes the face's
 * tail), so none is lost. */
inline void moc_inflow(__global const double *bin, __global double *scr, int e0, int ne, double w)
{
    int last = -1;
    double tail = 0.0;
    for (int e = e0 + ne - 1; e >= e0 && last < 0; e--) {
        if (scr[e] > 0.0)
            last = e;
        else
            tail += bin[e];
    }
    double pend = 0.0;
    for (int e = e0; e <= last; e++) {
        pend += bin[e];
        if (scr[e] > 0.0) {
            scr[e] = (pend + (e == last ? tail : 0.0)) / (w * scr[e]);
            pend = 0.0;
        }
    }
}

/* The slab (rte2d_params.h: one column of unit width): one track per direction along y, planar
 * flux |w_y| per unit area. */
inline void moc_slab(const ppb_rte_params *P, const moc_grid *g, double wy,
                     __global const double *sig, __global const double *Q,
                     __global const double *bin, __global double *tal, __global double *bout)
{
    double w = fabs(wy), st = sig[0];
    if (w < 1e-12)
        return; /* z-invariant in x too: psi = Q / sigma_t, the balance form's answer */
    int down = wy < 0.0, j = down ? 0 : g->ny - 1, dj = down ? 1 : -1;
    int in = ppb_moc_edge0(g->nfx, g->ny, down ? PPB_S1 : PPB_S2);
    int out = ppb_moc_edge0(g->nfx, g->ny, down ? PPB_S2 : PPB_S1);
    double psi = P->refl ? bin[in] / w : 0.0;
    for (; j >= 0 && j < g->ny; j += dj) {
        double L = (g->fy[j] - g->fy[j + 1]) / w, po = moc_segment(psi, Q[j], st, st * L, L);
        tal[j] += w * (psi - po);
        psi = po;
    }
    bout[out] += w * psi;
}

/* One work-item per transported direction cell: all its tracks, in order, so the sums are the
 * same whatever the device or work-group size. */
__kernel void ppb_rte_moc(const ppb_rte_params P, __global const double *dirs,
                          __global const double *edges, __global const double *sig,
                          __global const double *Q, __global const double *bin,
                          __global double *out, __global double *scr, const int nfx,
                          const double2 dmin, __global const double *QG, __global double *lsc)
{
    int c = (int)get_global_id(0);
    if (c >= P.ncell)
        return;
    moc_grid g = {nfx, P.ny, edges, edges + nfx + 1};
    int nf = nfx * P.ny, nb = ppb_moc_nb(nfx, P.ny);
    __global const double *q = Q + (long)c * nf, *bi = bin + (long)c * nb;
    /* The cell's slice of the unknown: its FSRs' radiance, then its edges' outgoing power. */
    __global double *tal = out + (long)c * (nf + nb), *bo = tal + nf, *sc = scr + (long)c * nb;
    /* The linear source's slices: the emission's gradients, the tracks' sums, the fit. */
    __global const double *qg = QG + (P.ls ? 2L * c * nf : 0L);
    __global double *acc = lsc + (P.ls ? (long)PPB_MOC_LS_ACC * c * nf : 0L);
    __global double *grad = P.ls ? out + (long)P.ncell * (nf + nb) + 2L * c * nf : out;
    for (int f = 0; f < nf; f++)
        tal[f] = 0.0;
    for (long k = 0; P.ls && k < (long)PPB_MOC_LS_ACC * nf; k++)
        acc[k] = 0.0;
    for (int e = 0; e < nb; e++)
        bo[e] = sc[e] = 0.0;
    double wx = dirs[4 * c], wy = dirs[4 * c + 1], s = sqrt(wx * wx + wy * wy);
    if (!P.med.tube)
        moc_slab(&P, &g, wy, sig, q, bi, tal, bo);
    else if (s > 1e-12) {
        double ux = wx / s, uy = wy / s, hw = 0.5 * P.med.width;
        /* The tracks' offsets v = p . (-u_y, u_x) over the cross-section's corners. */
        double v1 = -uy * -hw, v2 = -uy * hw, v3 = v1 - ux * P.med.height,
               v4 = v2 - ux * P.med.height;
        double vmin = fmin(fmin(v1, v2), fmin(v3, v4)), vmax = fmax(fmax(v1, v2), fmax(v3, v4));
        double proj = dmin.x * fabs(uy) + dmin.y * fabs(ux);
        double delta = fmin(P.hstep, proj / PPB_MOC_TRACKS_PER_CELL);
        int ntr = max(1, (int)ceil((vmax - vmin) / delta));
        delta = (vmax - vmin) / ntr;
        if (P.refl) {
            for (int k = 0; k < ntr; k++)
                moc_track(&P, &g, ux, uy, s, delta, vmin + (k + 0.5) * delta, sig, q, qg, tal, bo,
                          sc, acc, 0);
            for (int face = PPB_S1; face <= PPB_S4; face++)
                moc_inflow(bi, sc, ppb_moc_edge0(nfx, P.ny, face), ppb_moc_nedge(nfx, P.ny, face),
                           s * delta);
        }
        for (int k = 0; k < ntr; k++)
            moc_track(&P, &g, ux, uy, s, delta, vmin + (k + 0.5) * delta, sig, q, qg, tal, bo, sc,
                      acc, 1);
    }
    /* The balance form: sigma_t psi A = Q A + the tracks' net inflow. */
    for (int f = 0; f < nf; f++) {
        int i = f % nfx, j = f / nfx;
        double A = (g.fx[i + 1] - g.fx[i]) * (g.fy[j] - g.fy[j + 1]);
        tal[f] = (q[f] * A + tal[f]) / (sig[i] * A);
        if (P.ls) {
            /* A direction along z has no tracks: its field is z-invariant, psi = Q / sigma_t,
             * gradient and all (the balance form's answer for the average). */
            double gx = qg[2 * f] / sig[i], gy = qg[2 * f + 1] / sig[i];
            if (s > 1e-12)
                ppb_ls_fit(acc + PPB_MOC_LS_ACC * f, &gx, &gy);
            grad[2 * f] = gx;
            grad[2 * f + 1] = gy;
        }
    }
}
