/* rte2d_ls.h: the linear source of `rte2d`'s sweep (`[rte2d] source = linear`; reference:
 * Methods, `rte2d`, the linear source), shared by the sweep (rte2d.cl, moc_track) and the host
 * tests: the transport of one track segment through a source linear along it, with the two
 * integrals of the radiance the fit needs, the sums each region's tracks accumulate, and the
 * least-squares fit of the radiance's gradient over a region from them.
 *
 * The method is the linear-source method of characteristics of Ferrer and Rhodes (2016, Nucl.
 * Sci. Eng. 182, 151): each region's emission is q + g . (r - r_c) about its centre r_c, its
 * mean kept by the region's balance as the flat source's is, its gradient g from the radiance's
 * fitted gradient (what the tracks give, fitted over the same tracks, so the quadrature's own
 * moments and not the region's exact ones divide: a linear field is reproduced exactly
 * whatever the track layout). Plain C that is also OpenCL C, like rte2d_params.h. */
#ifndef PPB_RTE2D_LS_H
#define PPB_RTE2D_LS_H

#include "rte2d_params.h"

/* The linear source (P.ls; reference: Methods, `rte2d`, the linear source): along a segment of
 * 3-D length L and optical length tau = sigma_t L the source is b + c l, l the 3-D length from
 * the entry, and psi(l) = a e^{-sigma l} + b l phi0(sigma l) + c l^2 phi1(sigma l), phi0(t) =
 * (1 - e^{-t}) / t, phi1 = (1 - phi0) / t, exact for that source (Ferrer and Rhodes 2016 for
 * the method). Returns psi(L); *i0 and *i1 the integrals of psi and of l psi over the segment,
 * from the transport equation's balance sigma i0 = b L + c L^2 / 2 + a - psi(L) and its first
 * moment sigma i1 = b L^2 / 2 + c L^3 / 3 + i0 - L psi(L), which lose digits as 1 / tau^2 (at
 * tau = 0.02 i1 of a source c l was 1e-10 off). Below tau = 0.1 psi's Taylor series instead,
 * (m + 1) a_(m+1) = [m = 0] b + [m = 1] c - sigma a_m, to tau^11 (what is left, tau^12 / 12!,
 * is below 1e-20). */
PPB_RTE_HOT double ppb_ls_segment(double a, double b, double c, double st, double tau, double L,
                                  double *i0, double *i1)
{
    if (tau < 0.1) {
        double am = a, Lm = 1.0, out = 0.0, s0 = 0.0, s1 = 0.0;
        for (int m = 0; m < 12; m++) {
            out += am * Lm;
            s0 += am * Lm * L / (m + 1);
            s1 += am * Lm * L * L / (m + 2);
            am = ((m == 0 ? b : 0.0) + (m == 1 ? c : 0.0) - st * am) / (m + 1);
            Lm *= L;
        }
        *i0 = s0;
        *i1 = s1;
        return out;
    }
    double p0 = -expm1(-tau) / tau, p1 = (1.0 - p0) / tau;
    double out = a * exp(-tau) + b * L * p0 + c * L * L * p1;
    *i0 = (b * L + 0.5 * c * L * L + a - out) / st;
    *i1 = (0.5 * b * L * L + c * L * L * L / 3.0 + *i0 - L * out) / st;
    return out;
}

/* The linear source's sums of one segment (PPB_MOC_LS_ACC): it starts (dx, dy) from its FSR's
 * centre and runs l (planar) along u, its track delta wide; w = s delta weights psi as the
 * balance does (w i0 = delta times psi's integral over the planar length). */
PPB_RTE_HOT void ppb_ls_add(PPB_RTE_GMEM double *acc, double w, double delta, double dx, double dy,
                            double ux, double uy, double s, double l, double i0, double i1)
{
    double dl = delta * l, l3 = l * l / 3.0;
    acc[0] += w * i0;
    acc[1] += w * (dx * i0 + ux * s * i1);
    acc[2] += w * (dy * i0 + uy * s * i1);
    acc[3] += dl;
    acc[4] += dl * (dx + 0.5 * ux * l);
    acc[5] += dl * (dy + 0.5 * uy * l);
    acc[6] += dl * (dx * dx + dx * ux * l + ux * ux * l3);
    acc[7] += dl * (dx * dy + 0.5 * (dx * uy + dy * ux) * l + ux * uy * l3);
    acc[8] += dl * (dy * dy + dy * uy * l + uy * uy * l3);
}

/* The radiance's gradient in an FSR from its tracks' sums: the least-squares fit of
 * psi ~ c + a . (r - r_c) over the tracks (the quadrature the balance is made of), so a linear
 * field is reproduced exactly whatever the track layout; 0 where the tracks do not span the
 * FSR in two directions. */
PPB_FN void ppb_ls_fit(const PPB_RTE_GMEM double *acc, double *gx, double *gy)
{
    double Aq = acc[3];
    *gx = *gy = 0.0;
    if (!(Aq > 0.0))
        return;
    double mx = acc[1] - acc[4] * acc[0] / Aq, my = acc[2] - acc[5] * acc[0] / Aq;
    double Mxx = acc[6] - acc[4] * acc[4] / Aq, Mxy = acc[7] - acc[4] * acc[5] / Aq,
           Myy = acc[8] - acc[5] * acc[5] / Aq, det = Mxx * Myy - Mxy * Mxy;
    if (!(det > 1e-9 * Mxx * Myy))
        return;
    *gx = (Myy * mx - Mxy * my) / det;
    *gy = (Mxx * my - Mxy * mx) / det;
}

#endif
