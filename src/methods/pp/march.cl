/* march.cl: the ray marcher of `pp` and `ss` (paper Sec. 3, Eq. 13-17; reference: Methods).
 *
 * One work-item owns one (segment, direction bin) cell: for every point of the segment and every
 * direction sample of the bin it marches from the exit point p into the medium along -w to the
 * far boundary and accumulates
 *     L(p, w) = integral_0^l_far exp(-d(l)) sigma_s(q) J(q, w) dl,   q = p - l w,
 * with J = [table part at tau = D cos(theta_L), average albedo abar] + C(w, abar) exp(-D) from
 * the light maps (D, abar, lit). `ss` has C = p(w.w_L) and no table part (paper Eq. 5, n = 1).
 * The table part is I_pp of the slab the point sits in (Eq. 13-14): the point's vertical column
 * is a homogeneous slab of thickness sigma_t(x) H, and tau is clamped to it; with a density step
 * the two columns have their own tables (march_params.h), selected by the piece's sigma_t.
 *
 * The ray is cut into pieces at every line where the medium or the maps have a jump or a kink
 * (the step plane x = step_x, the light lines x' = step_x and x' = -W/2). Within a piece sigma_t
 * and alpha are constant and, where the maps say so, D is linear in l with the slab's slope, lit
 * and abar are constant: a "regular" piece. Per step of length h:
 *   direct beam, exact for linear D:  alpha C lit e^{-d1-D1} sigma_t h phi(-(sigma_t h + D2 - D1))
 *   R table (Eq. 15 with its step length, midpoint rule):  alpha lit sigma_t h e^{-d_mid}
 * R(tau_mid) S table (Eq. 16-17 corrected, exact for linear tau):   alpha lit e^{-d1} [e^{-sigma_t
 * h} S(tau2)
 *                                                                                 - S(tau1)]
 * with phi(z) = (e^z - 1)/z. Over the steps of a regular piece the S terms telescope, since
 * d2 = d1 + sigma_t h: their sum is alpha lit [e^{-d_b} S(tau_b) - e^{-d_a} S(tau_a)], and the
 * direct terms likewise sum to one phi term; the kernel evaluates those identical closed forms
 * (P.telescope) and steps only through irregular pieces. Where a step's slope differs from the
 * slab's, the S formula does not hold and that step uses the R rule. */
#include "march_params.h"
#include "ppb_beam_images.h"
#include "ppb_bin_samples.h"
#include "ppb_fresnel.h"
#include "ppb_sort.h"

/* One column slab's tables: its tau grid and where its blocks start in the R, S and C arrays. */
typedef struct ppb_mcol {
    double tau0, tau_h;
    int ntau;
    long tab_off, coef_off;
} ppb_mcol;

/* Column c of the tables (layout: march_params.h); the offsets are of its albedo node 0. */
inline ppb_mcol ppb_column(const ppb_march_params *P, int ndir, int c)
{
    ppb_mcol m = {P->tau0[c], P->tau_h[c], P->ntau[c],
                  ppb_march_table_offset(P->ntau, c, 0, P->nalb, ndir),
                  ppb_march_coef_offset(c, 0, P->nalb, ndir)};
    return m;
}

/* The maps at distance l along the march, tau = D cos(theta_L) clamped to the column's slab. */
typedef struct ppb_msample {
    double D, tau, abar, lit;
} ppb_msample;

inline ppb_msample ppb_sample(const ppb_march_params *P, __global const double *map, double tau0,
                              double px, double py, double mx, double my, double l)
{
    ppb_msample s;
    ppb_map_lookup(map, P->map_xp0, P->map_h, P->map_i0, P->map_nx, P->map_ny, P->tan_theta_l,
                   px + l * mx, py + l * my, &s.D, &s.abar, &s.lit);
    s.tau = clamp(s.D * P->cos_theta_l, 0.0, tau0);
    return s;
}

/* Step i of a piece [la, lb] marched in n steps of length h, whose optical distance at la is
 * d0: the optical distance d1 at the step's start and the maps at its end (s2: the piece's own
 * end sample b at the last step) and midpoint (sm). Returns 0, sampling nothing, once d1 is past
 * d_cap: the march stops there. */
inline int ppb_step(const ppb_march_params *P, __global const double *map, double tau0, double px,
                    double py, double mx, double my, double la, double h, int i, int n, double d0,
                    double sigma_t, ppb_msample b, double *d1, ppb_msample *s2, ppb_msample *sm)
{
    *d1 = d0 + sigma_t * h * i;
    if (*d1 > P->d_cap)
        return 0;
    double l1 = la + h * i;
    *s2 = i + 1 == n ? b : ppb_sample(P, map, tau0, px, py, mx, my, l1 + h);
    *sm = ppb_sample(P, map, tau0, px, py, mx, my, l1 + 0.5 * h);
    return 1;
}

/* Albedo node weights (paper Sec. 3.3: tables at several albedos, interpolated linearly). */
typedef struct ppb_anodes {
    int i;
    double f;
} ppb_anodes;

inline ppb_anodes ppb_albedo_nodes(const ppb_march_params *P, double abar)
{
    ppb_anodes a = {0, 0.0};
    if (P->nalb > 1) {
        double t = (abar - P->alb0) / P->alb_h;
        a.i = clamp((int)floor(t), 0, P->nalb - 2);
        a.f = clamp(t - a.i, 0.0, 1.0);
    }
    return a;
}

/* Table value of column col at tau, linear in tau and in the albedo nodes. */
inline double ppb_table(__global const double *tab, ppb_mcol col, int ndir, int dir, ppb_anodes an,
                        double tau)
{
    double t = tau / col.tau_h;
    int k = clamp((int)floor(t), 0, col.ntau - 2);
    double f = clamp(t - k, 0.0, 1.0);
    __global const double *c = tab + col.tab_off + ((long)an.i * ndir + dir) * col.ntau + k;
    double v = c[0] + f * (c[1] - c[0]);
    if (an.f > 0.0) {
        c += (long)ndir * col.ntau;
        v += an.f * (c[0] + f * (c[1] - c[0]) - v);
    }
    return v;
}

inline double ppb_coef(__global const double *coef, int ndir, int dir, ppb_anodes an)
{
    double v = coef[(long)an.i * ndir + dir];
    return an.f > 0.0 ? v + an.f * (coef[(long)(an.i + 1) * ndir + dir] - v) : v;
}

/* Whether the S formula holds between two samples h apart: tau moves with the slab's slope. */
inline int ppb_slope_ok(double tau1, double tau2, double r0, double sigma_t, double h)
{
    return fabs(tau2 - tau1 - r0 * sigma_t * h) <= 1e-9 * (1.0 + fabs(tau1) + fabs(tau2));
}

/* Marches one piece [la, lb] of constant sigma_t, alpha inside column col; returns its radiance
 * and advances *d. */
inline double ppb_piece(const ppb_march_params *P, __global const double *map,
                        __global const double *tabR, __global const double *tabS,
                        __global const double *coefC, ppb_mcol col, int ndir, int dir, double r0,
                        double px, double py, double mx, double my, double la, double lb,
                        double sigma_t, double alpha, double *d)
{
    double len = lb - la, eps = 1e-9 * len;
    coefC += col.coef_off;
    ppb_msample a = ppb_sample(P, map, col.tau0, px, py, mx, my, la + eps);
    ppb_msample b = ppb_sample(P, map, col.tau0, px, py, mx, my, lb - eps);
    ppb_msample m = ppb_sample(P, map, col.tau0, px, py, mx, my, 0.5 * (la + lb));
    double tolD = 1e-9 * (1.0 + a.D + b.D);
    /* Bilinear weights sum to 1 only to an ulp, hence the tolerances. */
    int regular = P->telescope && fabs(a.lit - b.lit) <= 1e-12 && fabs(a.lit - m.lit) <= 1e-12 &&
                  fabs(a.abar - b.abar) <= 1e-12 && fabs(a.abar - m.abar) <= 1e-12 &&
                  fabs(m.D - 0.5 * (a.D + b.D)) <= tolD &&
                  fabs(m.tau - 0.5 * (a.tau + b.tau)) <= tolD;
    double sum = 0.0, d0 = *d;
    *d = d0 + sigma_t * len;
    if (regular) {
        if (a.lit <= 0.0)
            return 0.0;
        ppb_anodes an = ppb_albedo_nodes(P, a.abar);
        double C = ppb_coef(coefC, ndir, dir, an);
        /* The direct beam's steps summed: one exponential over the piece. */
        double e_a = -(d0 + a.D), z = -(sigma_t * len + b.D - a.D);
        sum = ppb_beam_step(C, sigma_t, len, e_a, z);
        if (P->with_modes && P->table == PPB_TABLE_S &&
            ppb_slope_ok(a.tau, b.tau, r0, sigma_t, len - 2.0 * eps)) {
            sum += exp(-*d) * ppb_table(tabS, col, ndir, dir, an, b.tau) -
                   exp(-d0) * ppb_table(tabS, col, ndir, dir, an, a.tau);
        } else if (P->with_modes) {
            /* R rule on a linear tau: the midpoints need no map lookups. */
            int n = max(1, (int)ceil(len / P->ds));
            double h = len / n, att = exp(-sigma_t * h), e = exp(-(d0 + 0.5 * sigma_t * h));
            for (int i = 0; i < n && d0 + sigma_t * h * i < P->d_cap; i++, e *= att)
                sum += sigma_t * h * e *
                       ppb_table(tabR, col, ndir, dir, an, a.tau + (b.tau - a.tau) * (i + 0.5) / n);
        }
        return alpha * a.lit * sum;
    }
    /* Irregular piece: step by step, maps sampled at every step's ends and midpoint. */
    int n = max(1, (int)ceil(len / P->ds));
    double h = len / n, d1;
    ppb_msample s1 = a, s2, sm;
    for (int i = 0; i < n && ppb_step(P, map, col.tau0, px, py, mx, my, la, h, i, n, d0, sigma_t, b,
                                      &d1, &s2, &sm);
         i++) {
        if (sm.lit > 0.0) {
            ppb_anodes an = ppb_albedo_nodes(P, sm.abar);
            double C = ppb_coef(coefC, ndir, dir, an);
            double e_a = -(d1 + s1.D), z = -(sigma_t * h + s2.D - s1.D);
            double v = ppb_beam_step(C, sigma_t, h, e_a, z);
            if (P->with_modes) {
                double hs = (i == 0 ? h - eps : h) - (i + 1 == n ? eps : 0.0);
                if (P->table == PPB_TABLE_S && ppb_slope_ok(s1.tau, s2.tau, r0, sigma_t, hs))
                    v += exp(-(d1 + sigma_t * h)) * ppb_table(tabS, col, ndir, dir, an, s2.tau) -
                         exp(-d1) * ppb_table(tabS, col, ndir, dir, an, s1.tau);
                else
                    v += sigma_t * h * exp(-(d1 + 0.5 * sigma_t * h)) *
                         ppb_table(tabR, col, ndir, dir, an, sm.tau);
            }
            sum += sm.lit * v;
        }
        s1 = s2;
    }
    return alpha * sum;
}

/* Radiance leaving p = (px, py) in direction w (w.n > 0), per unit E_perp. */
inline double ppb_march_ray(const ppb_march_params *P, __global const double *map,
                            __global const double *tabR, __global const double *tabS,
                            __global const double *coefC, int ndir, int dir, double px, double py,
                            double wx, double wy)
{
    double mx = -wx, my = -wy; /* the march direction, per unit length along the 3-D ray */
    double lfar = ppb_exit_length(P->med.tube, P->med.width, P->med.height, px, py, mx, my);
    /* Beyond optical distance d_cap nothing counts (e^-d_cap is below double resolution of the
     * sum); capping l keeps grazing rays finite. */
    lfar = fmax(0.0, fmin(lfar, P->d_cap / ppb_medium_sigma_min(&P->med)));

    /* Piece ends: the step plane and the light lines through S1's lit edges (ppb_tube.h). */
    double brk[7];
    int nb = 0;
    brk[nb++] = 0.0;
    if (P->med.tube)
        nb = ppb_lit_breaks(&P->med, &P->lit, P->tan_theta_l, px, py, mx, my, lfar, brk, nb);
    ppb_sort_doubles(brk + 1, nb - 1); /* brk[0] = 0 stays first; at most five breaks */
    brk[nb++] = lfar;

    double r0 = wy; /* d tau / (sigma_t dl) in a slab: tau = sigma_t depth, depth grows as wy l */
    double d = 0.0, L = 0.0;
    for (int k = 0; k + 1 < nb && d < P->d_cap; k++) {
        double la = brk[k], lb = brk[k + 1];
        if (lb <= la)
            continue;
        double sigma_t, alpha;
        ppb_piece_medium(&P->med, px, mx, la, lb, &sigma_t, &alpha);
        /* The piece lies in one column (pieces are cut at x = step_x): the right column's slab
         * when its extinction is the right medium's and the tables have that column. */
        int c = P->ncols > 1 && sigma_t != P->med.sigma_t;
        L += ppb_piece(P, map, tabR, tabS, coefC, ppb_column(P, ndir, c), ndir, dir, r0, px, py, mx,
                       my, la, lb, sigma_t, alpha, &d);
    }
    return L;
}

/* ---- refractive boundaries (n > 1; reference: Methods, `ss`) ----
 * `ss` only (with_modes = 0). Inside, the once-scattered source is the refracted beam and its
 * unscattered reflections: down the beam D (direction w_t, optical depth D from the maps), up
 * the beam reflected at S2 (direction w_t mirrored in y, optical depth 2 D_b - D with D_b the
 * beam's depth at S2), and every further round trip S2 -> S1 -> S2 multiplies both by
 * F_b^2 e^{-2 D_b}: the geometric series 1 / (1 - F_b^2 e^{-2 D_b}). So per unit length
 *     J(q, v) = alpha sigma_t E_in / (1 - F_b^2 e^{-2 D_b})
 *               [p(v . w_t) e^{-D(q)} + F_b p(v . w_u) e^{-(2 D_b - D(q))}] lit(q),
 * E_in = beam_in, F_b = beam_fb. D_b = sigma_t H / cos theta_t: the slab, or the tube at normal
 * incidence, where a vertical beam stays in its column (its D_b that column's). Oblique light in
 * the tube also meets the side walls: ppb_piece_images below. */

/* The once-scattered beam over one piece [la, lb] of constant sigma_t, alpha, marched along
 * (mx, my) with the light travelling along v; advances *d. As ppb_piece's direct beam: one
 * closed form over a regular piece (D linear, lit constant), else step by step. */
inline double ppb_piece_fresnel(const ppb_march_params *P, __global const double *map, double px,
                                double py, double mx, double my, double la, double lb,
                                double sigma_t, double alpha, double c_down, double c_up,
                                double db2, double *d)
{
    double len = lb - la, eps = 1e-9 * len, tau0 = P->tau0[0];
    ppb_msample a = ppb_sample(P, map, tau0, px, py, mx, my, la + eps);
    ppb_msample b = ppb_sample(P, map, tau0, px, py, mx, my, lb - eps);
    ppb_msample m = ppb_sample(P, map, tau0, px, py, mx, my, 0.5 * (la + lb));
    double tolD = 1e-9 * (1.0 + a.D + b.D);
    int regular = fabs(a.lit - b.lit) <= 1e-12 && fabs(a.lit - m.lit) <= 1e-12 &&
                  fabs(m.D - 0.5 * (a.D + b.D)) <= tolD;
    double d0 = *d;
    *d = d0 + sigma_t * len;
    if (regular) {
        if (a.lit <= 0.0)
            return 0.0;
        double zl = sigma_t * len;
        double v = ppb_beam_step(c_down, sigma_t, len, -(d0 + a.D), -(zl + b.D - a.D)) +
                   ppb_beam_step(c_up, sigma_t, len, -(d0 + db2 - a.D), -(zl - b.D + a.D));
        return alpha * a.lit * v;
    }
    int n = max(1, (int)ceil(len / P->ds));
    double h = len / n, sum = 0.0, d1;
    ppb_msample s1 = a, s2, sm;
    for (int i = 0; i < n && ppb_step(P, map, tau0, px, py, mx, my, la, h, i, n, d0, sigma_t, b,
                                      &d1, &s2, &sm);
         i++) {
        if (sm.lit > 0.0) {
            double zl = sigma_t * h;
            double v = ppb_beam_step(c_down, sigma_t, h, -(d1 + s1.D), -(zl + s2.D - s1.D)) +
                       ppb_beam_step(c_up, sigma_t, h, -(d1 + db2 - s1.D), -(zl - s2.D + s1.D));
            sum += sm.lit * v;
        }
        s1 = s2;
    }
    return alpha * sum;
}

/* pp at n > 1: the S2-reflected beam of the column's slab solution over one piece [la, lb],
 * cup e^{-(D_b - D)} with cup interpolated in the albedo nodes at abar (ppb_coef, as ppb_piece
 * reads the downward beam's C), D_b = db the column's sigma_t H / cos theta_t and D clamped to
 * [0, D_b]: the point reads its own column's slab at tau = D cos theta_L clamped to that slab, as
 * the tables do (Eq. 13-14). Where a density step lies across the light path D can exceed the
 * column's D_b; unclamped, e^{-(D_b - D)} would exceed the slab's own value at its floor. One
 * closed form over a regular piece (clamped D linear, lit and abar constant), else step by step;
 * advances *d. Without a step this is ppb_piece_fresnel's upward term (D <= D_b there). */
inline double ppb_piece_up(const ppb_march_params *P, __global const double *map, ppb_mcol col,
                           __global const double *cup, int ndir, int dir, double px, double py,
                           double mx, double my, double la, double lb, double sigma_t, double alpha,
                           double db, double *d)
{
    double len = lb - la, eps = 1e-9 * len;
    ppb_msample a = ppb_sample(P, map, col.tau0, px, py, mx, my, la + eps);
    ppb_msample b = ppb_sample(P, map, col.tau0, px, py, mx, my, lb - eps);
    ppb_msample m = ppb_sample(P, map, col.tau0, px, py, mx, my, 0.5 * (la + lb));
    double Da = clamp(a.D, 0.0, db), Db = clamp(b.D, 0.0, db), Dm = clamp(m.D, 0.0, db);
    double tolD = 1e-9 * (1.0 + a.D + b.D);
    int regular =
        fabs(a.lit - b.lit) <= 1e-12 && fabs(a.lit - m.lit) <= 1e-12 &&
        (P->nalb < 2 || (fabs(a.abar - b.abar) <= 1e-12 && fabs(a.abar - m.abar) <= 1e-12)) &&
        fabs(Dm - 0.5 * (Da + Db)) <= tolD;
    double d0 = *d;
    *d = d0 + sigma_t * len;
    if (regular) {
        if (a.lit <= 0.0)
            return 0.0;
        double c_up = ppb_coef(cup, ndir, dir, ppb_albedo_nodes(P, a.abar));
        return alpha * a.lit *
               ppb_beam_step(c_up, sigma_t, len, -(d0 + db - Da), -(sigma_t * len - Db + Da));
    }
    int n = max(1, (int)ceil(len / P->ds));
    double h = len / n, sum = 0.0, D1 = Da, d1;
    ppb_msample s2, sm;
    for (int i = 0; i < n && ppb_step(P, map, col.tau0, px, py, mx, my, la, h, i, n, d0, sigma_t, b,
                                      &d1, &s2, &sm);
         i++) {
        double D2 = clamp(s2.D, 0.0, db); /* Db at the last step */
        if (sm.lit > 0.0) {
            double c_up = ppb_coef(cup, ndir, dir, ppb_albedo_nodes(P, sm.abar));
            sum +=
                sm.lit * ppb_beam_step(c_up, sigma_t, h, -(d1 + db - D1), -(sigma_t * h - D2 + D1));
        }
        D1 = D2;
    }
    return alpha * sum;
}

/* The tube at oblique incidence: the beam through the cross-section's mirror images
 * (ppb_beam_images.h), with the exact phase of the light travelling along v in each of the
 * beam's four directions; advances *d. */
inline double ppb_piece_images(const ppb_march_params *P, double px, double py, double mx,
                               double my, double vx, double vy, double la, double lb,
                               double sigma_t, double alpha, double *d)
{
    double d0 = *d;
    *d = d0 + sigma_t * (lb - la);
    double cb[4];
    ppb_beam_phases(P->med.g, P->light_x, P->cos_theta_l, vx, vy, cb);
    ppb_beam_tube B = PPB_BEAM_TUBE(P, light_x);
    return alpha * ppb_beam_images(&B, cb, px, py, mx, my, la, lb, sigma_t, d0);
}

/* One straight leg of the viewing ray inside, from (px, py) along (mx, my) for length lfar,
 * with the light travelling along v = -(mx, my, mz): the pieces of ppb_march_ray (cut at the step
 * plane and the light lines), each with the source J above; advances *d. */
inline double ppb_leg_fresnel(const ppb_march_params *P, __global const double *map,
                              __global const double *tabR, __global const double *tabS,
                              __global const double *coefC, int ndir, int dirv, double px,
                              double py, double vx, double vy, double vz, double lfar, double *d)
{
    double mx = -vx, my = -vy;
    /* 0, at most five breaks (ppb_tube_breaks: the step plane, three light lines of the step and
     * S1's edge, a searchlight's two edges), lfar. */
    double brk[7];
    int nb = 0;
    brk[nb++] = 0.0;
    if (P->med.tube)
        nb = ppb_lit_breaks(&P->med, &P->lit, P->tan_theta_l, px, py, mx, my, lfar, brk, nb);
    ppb_sort_doubles(brk + 1, nb - 1);
    brk[nb++] = lfar;
    double ct = P->cos_theta_l, st = P->light_x;
    double p_down = ppb_hg_phase(P->med.g, vx * st - vy * ct);
    double p_up = ppb_hg_phase(P->med.g, vx * st + vy * ct);
    double L = 0.0;
    for (int k = 0; k + 1 < nb && *d < P->d_cap; k++) {
        double la = brk[k], lb = brk[k + 1];
        if (lb <= la)
            continue;
        double sigma_t, alpha;
        ppb_piece_medium(&P->med, px, mx, la, lb, &sigma_t, &alpha);
        double db = sigma_t * P->med.height / ct;
        double e = P->beam_in / (1.0 - P->beam_fb * P->beam_fb * exp(-2.0 * db));
        if (P->with_modes) {
            /* pp: the Fresnel slab solution's field, tabulated along this leg's direction
             * variant dirv (march_tables.c), read by ppb_piece with the downward beam's whole
             * coefficient (its single scattering, series and entry included); the upward
             * beam's coefficient multiplies e^{-(D_b - D)} (ppb_piece_up). Both read the
             * piece's column slab and the albedo nodes at abar, as at n = 1 (ppb_march_ray):
             * db is that column's D_b. */
            int c = P->ncols > 1 && sigma_t != P->med.sigma_t;
            ppb_mcol col = ppb_column(P, ndir, c);
            double dpp = *d;
            L += ppb_piece(P, map, tabR, tabS, coefC, col, ndir, dirv, vy, px, py, mx, my, la, lb,
                           sigma_t, alpha, &dpp);
            __global const double *cup = coefC + (long)P->ncols * P->nalb * ndir + col.coef_off;
            L += ppb_piece_up(P, map, col, cup, ndir, dirv, px, py, mx, my, la, lb, sigma_t, alpha,
                              db, d);
        } else if (P->med.tube && P->tan_theta_l > 0.0)
            L += ppb_piece_images(P, px, py, mx, my, vx, vy, la, lb, sigma_t, alpha, d);
        else
            L += ppb_piece_fresnel(P, map, px, py, mx, my, la, lb, sigma_t, alpha, e * p_down,
                                   e * P->beam_fb * p_up, 2.0 * db, d);
    }
    return L;
}

/* Air-side radiance leaving p on surface surf along the air-side direction w (n > 1): the
 * direction inside by Snell (tangential part / n, normal part the refracted cosine), the n^2 law
 * (1 - F) / n^2 times the inside radiance, which is the viewing ray's legs summed: at each face
 * it meets the ray continues mirrored (the cross-section's mirror images), weighted by F of its
 * cosine to that face (1 under total internal reflection). The legs stop where the optical
 * distance reaches d_cap or the weight times e^{-d} falls below 1e-15 (below the sum's
 * resolution), and after 4096 legs (a ray so close to the tube's axis that its legs are
 * shorter than d_cap / 4096 in total: e^{-d} decides long before). */
inline double ppb_march_ray_fresnel(const ppb_march_params *P, __global const double *map,
                                    __global const double *tabR, __global const double *tabS,
                                    __global const double *coefC, int ndir, int dir, int surf,
                                    double px, double py, double wx, double wy, double wz)
{
    /* pp's tables: variant v of sample dir at dir + v nbase (y mirrored: v & 1, x: v & 2). */
    int nbase = ndir / (P->with_modes ? (P->med.tube ? 4 : 2) : 1), var = 0;
    double n = P->med.n, nx = ppb_normal_x(surf), ny = ppb_normal_y(surf);
    double ca = wx * nx + wy * ny, ci = ppb_refract_cos(ca, n);
    double vx = (wx - ca * nx) / n + ci * nx, vy = (wy - ca * ny) / n + ci * ny, vz = wz / n;
    double wt = (1.0 - ppb_fresnel(ca, n)) / (n * n);
    double sig_min = ppb_medium_sigma_min(&P->med);
    double W = 1.0, d = 0.0, L = 0.0;
    for (int leg = 0; leg < 4096 && d < P->d_cap && W * exp(-d) > 1e-15; leg++) {
        double mx = -vx, my = -vy, l;
        int face = ppb_exit_face(P->med.tube, P->med.width, P->med.height, px, py, mx, my, &l);
        double lfar = fmax(0.0, l), lcap = (P->d_cap - d) / sig_min;
        int dirv = dir + var * nbase;
        if (!(lfar <= lcap)) {
            L += W * ppb_leg_fresnel(P, map, tabR, tabS, coefC, ndir, dirv, px, py, vx, vy, vz,
                                     lcap, &d);
            break;
        }
        L += W *
             ppb_leg_fresnel(P, map, tabR, tabS, coefC, ndir, dirv, px, py, vx, vy, vz, lfar, &d);
        /* Onto the face exactly, then mirrored (the march direction m = -v). */
        int side = ppb_face_is_side(face);
        W *= ppb_fresnel(fabs(side ? vx : vy), 1.0 / n);
        ppb_tube_reflect(face, P->med.width, P->med.height, lfar, &px, &py, &mx, &my);
        vx = -mx;
        vy = -my;
        var ^= side ? 2 : 1;
    }
    return wt * L;
}

/* One work-item per (segment row, bin): the bin-averaged exit radiance over the segment's points
 * and the bin's direction samples, each with its weight (reference: Bins). */
__kernel void ppb_march_kernel(const ppb_march_params P, __global const double *map,
                               __global const double *tabR, __global const double *tabS,
                               __global const double *coefC, __global double *out)
{
    int nbins = ppb_bin_count(P.ntheta, P.nphi), seg, bin;
    int surf = ppb_exit_cell((int)get_global_id(0), P.row0, nbins, P.offset, P.nseg, &seg, &bin);
    if (surf < 0)
        return;
    /* pp's tables at n > 1 hold 2 (slab) or 4 (tube) variants of each sample (march_tables.h) */
    int nvar = P.med.n > 1.0 && P.with_modes ? (P.med.tube ? 4 : 2) : 1;
    int ndir = nvar * ppb_bin_sample_count(ppb_surface_count(P.med.tube), nbins, P.nsamp);
    int ns = ppb_exit_nsamples(&P.med, P.npts, P.nsamp);
    double sum = 0.0;
    for (int k = 0; k < ns; k++) {
        double px, py, w[3], wk;
        int dir = ppb_exit_sample(&P.med, surf, seg, P.nseg[surf], bin, P.npts, P.nsamp, P.ntheta,
                                  P.nphi, k, &px, &py, w, &wk);
        if (P.med.n > 1.0)
            sum += wk * ppb_march_ray_fresnel(&P, map, tabR, tabS, coefC, ndir, dir, surf, px, py,
                                              w[0], w[1], w[2]);
        else
            sum += wk * ppb_march_ray(&P, map, tabR, tabS, coefC, ndir, dir, px, py, w[0], w[1]);
    }
    out[ppb_cell_index(P.offset[surf], seg, nbins, bin)] = sum / ns;
}
