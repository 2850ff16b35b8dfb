/* ppb_beam_images.h: the direct beam's first scattering along a ray piece, coded once for the
 * ray marchers of `ss` and `pp` (march.cl) and of `rte2d` (rte2d.cl) (reference: Methods;
 * Medium for n > 1).
 *
 * Owns: the closed form of the beam's first scattering over a step along which both optical
 * depths are linear (ppb_beam_step), and, at n > 1 in the tube at oblique incidence, the
 * refracted beam unfolded over the cross-section's mirror images (ppb_beam_images): which tiles
 * (k, j) reach a piece, their weights F_b^j F_s^k, entry points on S1's lit part and directions,
 * and with a density step the beam's optical depth through the step's images (ppb_image_depth).
 * The kernels hand it the beam's geometry inside (ppb_beam_tube, built from their own launch
 * parameters) and the phase coefficients of the beam's four directions (the exact phase at an
 * exit sample, the cell average in rte2d's sweep).
 *
 * OpenCL C only (pown, clamp): no host code evaluates the images. */
#ifndef PPB_BEAM_IMAGES_H
#define PPB_BEAM_IMAGES_H

#include "ppb_light.h"

/* The image series' stopping tolerance, relative to what has been summed: 2^-60, 64 times below
 * the half ulp (2^-54 of the sum at least) under which a term leaves a double sum unchanged. */
#define PPB_IMAGE_TOL 0x1p-60

/* (e^z - 1) / z, stable at z = 0. */
inline double ppb_phi1(double z)
{
    return fabs(z) < 1e-300 ? 1.0 : expm1(z) / z;
}

/* The direct beam's factor exp(e_a) phi1(z) over a step whose exponent runs from e_a to
 * e_b = e_a + z <= 0, times C sigma_t h (in the association the march always used). As written,
 * exp(e_a) phi1(z) is 0 x inf once e_a underflows while z overflows (a grazing beam in a thick
 * medium marched towards the light: e_a ~ -D, z ~ +D; the NaN); the scaled form exp(e_b) (1
 * - e^{-z}) / z is the same number without either. It is taken only below e_a = -700, where
 * exp(e_a) leaves the normal range: since e_b <= 0 bounds z by -e_a, neither factor can overflow
 * above that threshold, and the direct form keeps its bits there. */
inline double ppb_beam_step(double C, double sigma_t, double h, double e_a, double z)
{
    if (e_a < -700.0 && z > 0.0)
        return C * sigma_t * h * (exp(e_a + z) * (-expm1(-z) / z));
    return C * exp(e_a) * sigma_t * h * ppb_phi1(z);
}

/* The phase coefficients cb of ppb_beam_images for light leaving along v = (vx, vy, .): HG of
 * the angle between v and each of the beam's four directions inside, (st, -ct) (+sin, down),
 * (st, ct) (+sin, up), (-st, -ct) (-sin, down) and (-st, ct) (-sin, up), st, ct = sin, cos
 * theta_t. */
inline void ppb_beam_phases(double g, double st, double ct, double vx, double vy, double *cb)
{
    cb[0] = ppb_hg_phase(g, vx * st - vy * ct);
    cb[1] = ppb_hg_phase(g, vx * st + vy * ct);
    cb[2] = ppb_hg_phase(g, -vx * st - vy * ct);
    cb[3] = ppb_hg_phase(g, -vx * st + vy * ct);
}

/* The refracted beam inside the tube (n > 1), as both kernels' parameters hold it. */
typedef struct ppb_beam_tube {
    ppb_medium med;             /* the cross-section and the medium (ppb_medium.h) */
    ppb_lit lit;                /* S1's lit part (ppb_light.h) */
    double sin_t, cos_t, tan_t; /* the beam's direction (sin, -cos) inside */
    double beam_in;             /* its perpendicular irradiance inside */
    double beam_fb, beam_fs;    /* F at S1, S2 and at S3, S4 from inside */
    double d_cap;               /* optical distance where a march stops */
} ppb_beam_tube;

/* The beam of a kernel's launch parameters P (march_params.h, rte2d_params.h: the same field
 * names but the sine of the beam's angle, SIN: light_x in march's, sin_theta_l in rte2d's). */
#define PPB_BEAM_TUBE(P, SIN)                                                                      \
    ((ppb_beam_tube){.med = (P)->med,                                                              \
                     .lit = (P)->lit,                                                              \
                     .sin_t = (P)->SIN,                                                            \
                     .cos_t = (P)->cos_theta_l,                                                    \
                     .tan_t = (P)->tan_theta_l,                                                    \
                     .beam_in = (P)->beam_in,                                                      \
                     .beam_fb = (P)->beam_fb,                                                      \
                     .beam_fs = (P)->beam_fs,                                                      \
                     .d_cap = (P)->d_cap})

/* The unfolded tube's right medium (ppb_beam_images): tile (k, j) holds the cross-section
 * mirrored in x when k is odd, so the real x >= step_x = s is x' >= kW + s in an even tile and
 * x' <= kW - s in an odd one; the two join into one interval per pair of tiles, [2mW + s,
 * 2mW + W - s] for every integer m (the tile edge between them is a mirror, not a step), of
 * period 2W. Measure of the right medium on x' < x, up to a constant: G(x). */
inline double ppb_image_right(double x, double s, double W)
{
    double len = W - 2.0 * s, m = floor((x - s) / (2.0 * W));
    return m * len + clamp(x - s - m * 2.0 * W, 0.0, len);
}

/* Optical depth of the unfolded beam from its entry x_e on S1 to the image point (x', depth'):
 * a straight line along (sin theta_t, down), so its length is depth' / cos theta_t, of which
 * (G(x') - G(x_e)) / sin theta_t lies in the right medium's images (ppb_image_right). */
inline double ppb_image_depth(const ppb_beam_tube *B, double xp, double xe, double dp)
{
    double W = B->med.width, s = B->med.step_x;
    return B->med.sigma_t * dp / B->cos_t +
           (B->med.sigma_t_right - B->med.sigma_t) / B->sin_t *
               (ppb_image_right(xp, s, W) - ppb_image_right(xe, s, W));
}

/* The tube at oblique incidence (n > 1): the beam meets the side walls too. Unfolded by the
 * cross-section's mirror images (tile (k, j), k >= 0 along x, j >= 0 in depth, mirrored when k
 * or j is odd: x' = kW +- x, depth' = jH + d or jH + H - d), every beam is a straight line from
 * its entry point x_e on S1 along (sin theta_t, down), and the beam reaching q through image
 * (k, j) has crossed j horizontal and k vertical tile edges: weight F_b^j F_s^k, optical depth
 * sigma_t depth' / cos theta_t, entry point x_e = x' - depth' tan theta_t, which must lie on S1's
 * lit part, and direction (+-sin theta_t, -+cos theta_t) in the real tube. Along a piece x' and
 * depth' are linear in l, so each image's lit part is one interval and its integral one closed
 * form (ppb_beam_step). With a density step (x >= step_x: sigma_t_right) the beam's optical
 * depth is integrated through the step's images instead: ppb_image_depth.
 *
 * The piece [la, lb] of the ray from (px, py) along (mx, my) has constant sigma_t (it lies in
 * one medium) and starts at optical distance d0; cb are the phase coefficients of the beam's
 * directions (+sin, down), (+sin, up), (-sin, down), (-sin, up). Returns the sum before the
 * albedo. */
inline double ppb_beam_images(const ppb_beam_tube *B, const double *cb, double px, double py,
                              double mx, double my, double la, double lb, double sigma_t, double d0)
{
    double W = B->med.width, H = B->med.height, ct = B->cos_t, tn = B->tan_t;
    double lo = ppb_lit_lo(&B->med, &B->lit), hi = ppb_lit_hi(&B->med, &B->lit); /* S1's lit */
    if (!(hi > lo))
        return 0.0;
    /* Image j's beam has come at least j H / cos theta_t, through the lesser sigma_t at worst;
     * with the ray's own d0 beyond d_cap it counts for nothing. */
    int step = B->med.step == PPB_STEP_DENSITY && B->med.sigma_t_right != B->med.sigma_t;
    double sig_beam = step ? fmin(B->med.sigma_t, B->med.sigma_t_right) : sigma_t;
    int jmax = (int)ceil((B->d_cap - d0) * ct / (sig_beam * H));
    /* The contribution bound (docs/reference.md: Methods, ss at n > 1): term (k, j) is at
     * most beam_in F_b^j F_s^k c_max sigma_t (lb - la) e^{-d0} e^{-j a}, a = sig_beam H / cos
     * theta_t (its beam has come at least j H / cos theta_t), and a depth row j holds at most
     * nk tiles, so the terms of rows j and beyond sum to at most tail r^j, r = F_b e^{-a} < 1.
     * Once that is below PPB_IMAGE_TOL times the sum, every one of them is below half an ulp
     * of the sum and adding it would not change a bit: the series stops there. */
    double r = B->beam_fb * exp(-sig_beam * H / ct);
    double nk = floor(1.0 + H * tn / W) + 3.0;
    double cmax = fmax(fmax(cb[0], cb[1]), fmax(cb[2], cb[3]));
    double tail =
        r < 1.0 ? B->beam_in * cmax * sigma_t * (lb - la) * exp(-d0) * nk / (1.0 - r) : INFINITY;
    double sum = 0.0, fj = 1.0;
    for (int j = 0; j <= jmax; j++, fj *= B->beam_fb, tail *= r) {
        if (sum > 0.0 && tail <= PPB_IMAGE_TOL * sum)
            break;
        int jodd = j & 1;
        /* depth'(l) = dp0 + l dpl */
        double dp0 = jodd ? (j + 1) * H + py : j * H - py, dpl = jodd ? my : -my;
        int kmin = max(0, (int)ceil((j * H * tn - W) / W));
        int kmax = (int)floor(1.0 + (j + 1) * H * tn / W);
        double fk = pown(B->beam_fs, kmin);
        for (int k = kmin; k <= kmax; k++, fk *= B->beam_fs) {
            int kodd = k & 1;
            double xe0 = k * W + (kodd ? -px : px) - dp0 * tn, xel = (kodd ? -mx : mx) - dpl * tn;
            double l1 = la, l2 = lb;
            if (xel == 0.0) {
                if (xe0 < lo || xe0 >= hi)
                    continue;
            } else {
                double a = (lo - xe0) / xel, b = (hi - xe0) / xel;
                l1 = fmax(l1, fmin(a, b));
                l2 = fmin(l2, fmax(a, b));
            }
            if (!(l2 > l1))
                continue;
            double C = B->beam_in * fj * fk * cb[2 * kodd + jodd];
            if (!step) {
                double D1 = sigma_t * (dp0 + l1 * dpl) / ct, D2 = sigma_t * (dp0 + l2 * dpl) / ct;
                double e_a = -(d0 + sigma_t * (l1 - la) + D1), z = -(sigma_t * (l2 - l1) + D2 - D1);
                sum += ppb_beam_step(C, sigma_t, l2 - l1, e_a, z);
                continue;
            }
            /* Density step: along the piece x' = xp0 + l xpl stays on one side of the step's
             * image (the piece lies in one medium, inside tile k), and x_e on S1 (tile 0) crosses
             * the step at most once, at ls: D is linear on either side of it. */
            double xp0 = k * W + (kodd ? -px : px), xpl = kodd ? -mx : mx;
            double cut[3] = {l1, l2, l2};
            int ncut = 2;
            if (xel != 0.0) {
                double ls = (B->med.step_x - xe0) / xel;
                if (ls > l1 && ls < l2)
                    cut[1] = ls, ncut = 3;
            }
            for (int q = 0; q + 1 < ncut; q++) {
                double u1 = cut[q], u2 = cut[q + 1];
                double D1 = ppb_image_depth(B, xp0 + u1 * xpl, xe0 + u1 * xel, dp0 + u1 * dpl);
                double D2 = ppb_image_depth(B, xp0 + u2 * xpl, xe0 + u2 * xel, dp0 + u2 * dpl);
                double e_a = -(d0 + sigma_t * (u1 - la) + D1), z = -(sigma_t * (u2 - u1) + D2 - D1);
                sum += ppb_beam_step(C, sigma_t, u2 - u1, e_a, z);
            }
        }
    }
    return sum;
}

#endif
