/* ppb_conventions.h: the conventions (reference: Geometry to Bins), for host and kernels.
 *
 * Owns: surface ids, the surface count, and their local frames (n, b = +z, t = n x b), the
 * direction bins (equal sin^2(theta) theta bins, phi folded to [0, 180] deg) and their count,
 * the deterministic methods' direction samples of a bin and their weights (with the
 * Gauss-Legendre rule they use), the (surface, segment, bin) cell index of every radiance array,
 * segment centres and lengths, the piecewise-constant medium and the Henyey-Greenstein phase
 * function (and its factored form for sums over many cosines). Where each surface's rows start (the
 * offsets) is the host's ppb_scene_layout (src/model/scene.h); kernels receive those offsets. Plain
 * C that is also OpenCL C: the host includes it from src/, kernels with -I kernels. Nothing here
 * allocates or keeps state. */
#ifndef PPB_CONVENTIONS_H
#define PPB_CONVENTIONS_H

#ifdef __OPENCL_VERSION__
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#define PPB_FN inline
#else
#include <math.h>
#include <stddef.h>
#define PPB_FN static inline
#endif

#define PPB_PI 3.14159265358979323846

/* Surfaces (reference: Geometry). In slab mode only S1 and S2 exist. */
enum { PPB_S1 = 0, PPB_S2 = 1, PPB_S3 = 2, PPB_S4 = 3, PPB_NSURF = 4 };

/* Surfaces that exist: S1..S4 in the tube, S1 and S2 in slab mode. */
PPB_FN int ppb_surface_count(int tube)
{
    return tube ? 4 : 2;
}

/* Step kinds (reference: Medium, Light). */
enum { PPB_STEP_NONE = 0, PPB_STEP_DENSITY = 1, PPB_STEP_ALBEDO = 2, PPB_STEP_SHADOW = 3 };

/* Outward normal of a surface, as (x, y); the z component is 0. */
PPB_FN double ppb_normal_x(int surf)
{
    return surf == PPB_S3 ? -1.0 : surf == PPB_S4 ? 1.0 : 0.0;
}
PPB_FN double ppb_normal_y(int surf)
{
    return surf == PPB_S1 ? 1.0 : surf == PPB_S2 ? -1.0 : 0.0;
}
/* t = n x b with b = +z gives t = (n_y, -n_x, 0): +x on S1, -x on S2, +y on S3, -y on S4. */
PPB_FN double ppb_tangent_x(int surf)
{
    return ppb_normal_y(surf);
}
PPB_FN double ppb_tangent_y(int surf)
{
    return -ppb_normal_x(surf);
}

/* Theta bin of an outgoing direction with mu = cos(theta) = w.n >= 0: edges at
 * sin^2(theta) = k / ntheta (equal projected solid angle). */
PPB_FN int ppb_theta_bin(double mu, int ntheta)
{
    int k = (int)((1.0 - mu * mu) * ntheta);
    return k < 0 ? 0 : (k >= ntheta ? ntheta - 1 : k);
}

/* Phi bin from the direction's components along t and b; phi is folded to [0, pi] because the
 * set-up is symmetric in z, so the sign of the b component does not matter. */
PPB_FN int ppb_phi_bin(double wt, double wb, int nphi)
{
    double phi = atan2(fabs(wb), wt); /* in [0, pi] */
    int k = (int)(phi * (1.0 / PPB_PI) * nphi);
    return k < 0 ? 0 : (k >= nphi ? nphi - 1 : k);
}

/* The bin of theta bin itheta and phi bin iphi: bin = itheta * nphi + iphi, so itheta =
 * bin / nphi and iphi = bin % nphi (reference: Bins). */
PPB_FN int ppb_bin_index(int itheta, int iphi, int nphi)
{
    return itheta * nphi + iphi;
}

/* Bin of an outgoing direction w = (wx, wy, wz) leaving surface surf. */
PPB_FN int ppb_dir_bin(int surf, double wx, double wy, double wz, int ntheta, int nphi)
{
    double mu = wx * ppb_normal_x(surf) + wy * ppb_normal_y(surf);
    double wt = wx * ppb_tangent_x(surf) + wy * ppb_tangent_y(surf);
    return ppb_bin_index(ppb_theta_bin(mu, ntheta), ppb_phi_bin(wt, wz, nphi), nphi);
}

/* Direction bins per surface point (ppb_bin_index). */
PPB_FN int ppb_bin_count(int ntheta, int nphi)
{
    return ntheta * nphi;
}

/* Flat index of (segment row, bin) in every radiance array and tally: row = the surface's first
 * row (its layout offset) + segment, rows of nbins bins each. */
PPB_FN size_t ppb_cell_index(int surf_offset, int seg, int nbins, int bin)
{
    return ((size_t)surf_offset + (size_t)seg) * (size_t)nbins + (size_t)bin;
}

/* Projected solid angle of every bin: (1/2) d(sin^2) x 2 d(phi) = pi / (ntheta nphi); the
 * folded bin counts both phi and -phi. */
PPB_FN double ppb_bin_proj_solid_angle(int ntheta, int nphi)
{
    return PPB_PI / (ntheta * nphi);
}

/* A bin's centre in (sin^2(theta), phi), the middle of its projected solid angle: theta in
 * radians from the normal, phi in radians from t in [0, pi] (the folded half). */
PPB_FN double ppb_theta_bin_centre(int itheta, int ntheta)
{
    return asin(sqrt((itheta + 0.5) / ntheta));
}
PPB_FN double ppb_phi_bin_centre(int iphi, int nphi)
{
    return (iphi + 0.5) * PPB_PI / nphi;
}

/* A direction inside bin (itheta, iphi) at fractional position (u, v) in [0,1)^2, uniform in
 * sin^2(theta) and phi, i.e. uniform in projected solid angle; written in world coordinates
 * for surface surf. The folded bin's phi > 0 half is used (b = +z component >= 0). */
PPB_FN void ppb_bin_direction(int surf, int itheta, int iphi, double u, double v, int ntheta,
                              int nphi, double *wx, double *wy, double *wz)
{
    double s2 = (itheta + u) / ntheta;
    double st = sqrt(s2), ct = sqrt(1.0 - s2);
    double phi = (iphi + v) * PPB_PI / nphi;
    double wt = st * cos(phi), wb = st * sin(phi);
    *wx = ct * ppb_normal_x(surf) + wt * ppb_tangent_x(surf);
    *wy = ct * ppb_normal_y(surf) + wt * ppb_tangent_y(surf);
    *wz = wb;
}

/* Node i of the q-point Gauss-Legendre rule on [-1, 1] (descending, x_0 nearest 1); *w its
 * weight. Newton on P_q from the Chebyshev guess, P_q and P_q' by the three-term recurrence; it
 * converges to machine precision for every q the project uses (at most 64). The one code of the
 * rule: the host's ppb_gauss_legendre (base/quadrature.h) and the bin samples below call it. */
PPB_FN double ppb_gauss_legendre_node(int q, int i, double *w)
{
    double z = cos(PPB_PI * (i + 0.75) / (q + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; it++) {
        double p0 = 1.0, p1 = z;
        for (int l = 2; l <= q; l++) {
            double p2 = ((2 * l - 1) * z * p1 - (l - 1) * p0) / l;
            p0 = p1;
            p1 = p2;
        }
        dp = q * (z * p1 - p0) / (z * z - 1.0);
        double dz = p1 / dp;
        z -= dz;
        if (fabs(dz) < 1e-16)
            break;
    }
    *w = 2.0 / ((1.0 - z * z) * dp * dp);
    return z;
}

/* Row a of the n sample rows of theta bin itheta (reference: Bins): *u, its position in the
 * bin's sin^2(theta) range as a fraction in (0, 1), and the return value, its weight in the bin's
 * average (the n rows' weights sum to n). Every row but the last: the midpoints, weight 1. The
 * last row reaches the tangent plane (mu = 0), where the exit radiance goes as a + b mu (the
 * Fresnel transmittance 1 - F at n > 1 falls to 0 linearly in mu; a half-space's exit radiance
 * rises about as a + b mu from its value at grazing, Chandrasekhar's H-function, whose
 * mu log(mu) term the rule integrates well but not exactly), mu = sqrt(1 - sin^2),
 * which midpoints in sin^2 integrate with an error of order n^-1.5 (1.1-1.4 % high at 4 x 4 and
 * n = 1.4). There sin^2(theta) = 1 - (1 - t)^2 / ntheta, so u = 1 - (1 - t)^2 and mu = (1 - t) /
 * sqrt(ntheta): t on the n-point Gauss-Legendre rule over [0, 1] (nodes (1 - x_a) / 2, weights
 * W_a / 2) with the Jacobian du/dt = 2 (1 - t), so a + b mu becomes a polynomial in t, which the
 * rule integrates exactly to degree 2n - 1. */
PPB_FN double ppb_bin_sample_u(int itheta, int a, int n, int ntheta, double *u)
{
    if (itheta < ntheta - 1) {
        *u = (a + 0.5) / n;
        return 1.0;
    }
    double W, t = 0.5 * (1.0 - ppb_gauss_legendre_node(n, a, &W));
    *u = 1.0 - (1.0 - t) * (1.0 - t);
    return n * 0.5 * W * 2.0 * (1.0 - t);
}

/* The stratified direction samples of the deterministic methods (`pp`, `ss`, `ppslab`, `rte2d`,
 * `pp3d`; reference: Bins): sample (a, b) of bin `bin` on surface surf, in phi the midpoint of
 * column b of n, in sin^2(theta) row a of ppb_bin_sample_u. Returns the sample's weight in the
 * bin's average: a bin's value is sum(weight x radiance) / n^2 (the weights sum to n^2). */
PPB_FN double ppb_bin_sample_dir(int surf, int bin, int a, int b, int n, int ntheta, int nphi,
                                 double *wx, double *wy, double *wz)
{
    double u, weight = ppb_bin_sample_u(bin / nphi, a, n, ntheta, &u);
    ppb_bin_direction(surf, bin / nphi, bin % nphi, u, (b + 0.5) / n, ntheta, nphi, wx, wy, wz);
    return weight;
}

/* The samples' flat index (the marchers' tables and source planes are in this order). */
PPB_FN int ppb_bin_sample_index(int surf, int bin, int a, int b, int n, int nbins)
{
    return ((surf * nbins + bin) * n + a) * n + b;
}

/* Samples of every bin of nsurf surfaces. */
PPB_FN int ppb_bin_sample_count(int nsurf, int nbins, int n)
{
    return nsurf * nbins * n * n;
}

/* The inverse of ppb_bin_sample_index: surface, bin and sample (a, b) of index dir. */
PPB_FN void ppb_bin_sample_split(int dir, int n, int nbins, int *surf, int *bin, int *a, int *b)
{
    int per_bin = n * n, ab = dir % per_bin;
    *surf = dir / (nbins * per_bin);
    *bin = dir / per_bin % nbins;
    *a = ab / n;
    *b = ab % n;
}

/* The surface and segment of layout row `row`: surface s holds the rows [offset[s], offset[s] +
 * nseg[s]). Returns the surface, -1 for a row outside every surface. */
PPB_FN int ppb_row_surface(int row, const int *offset, const int *nseg, int *seg)
{
    int surf = -1;
    for (int s = 0; s < PPB_NSURF; s++)
        if (nseg[s] > 0 && row >= offset[s] && row < offset[s] + nseg[s])
            surf = s;
    *seg = surf < 0 ? 0 : row - offset[surf];
    return surf;
}

/* Segment holding coordinate s along a surface of length len starting at s0. */
PPB_FN int ppb_segment_of(double s, double s0, double len, int nseg)
{
    int k = (int)((s - s0) / len * nseg);
    return k < 0 ? 0 : (k >= nseg ? nseg - 1 : k);
}

/* Piecewise-constant medium (reference: Medium): the right value holds for x >= step_x. */
PPB_FN double ppb_sigma_t_at(double x, int step, double step_x, double sigma_t,
                             double sigma_t_right)
{
    return (step == PPB_STEP_DENSITY && x >= step_x) ? sigma_t_right : sigma_t;
}
PPB_FN double ppb_albedo_at(double x, int step, double step_x, double albedo, double albedo_right)
{
    return (step == PPB_STEP_ALBEDO && x >= step_x) ? albedo_right : albedo;
}

/* Henyey-Greenstein phase function of the scattering cosine, per steradian, normalised to 1
 * over the sphere (reference: Medium; paper Sec. 4.1):
 *     p(cos) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2)) = ppb_hg_norm(g) / base^(3/2),
 * base = ppb_hg_base(g, cos). The factored form is for sums of p over many cosines (the phase
 * matrix's quadratures, src/physics/phase.c), which take the constant out of the sum; it agrees
 * with ppb_hg_phase to rounding (a few ulps), not bit for bit. */
PPB_FN double ppb_hg_base(double g, double cos_angle)
{
    return 1.0 + g * g - 2.0 * g * cos_angle;
}
PPB_FN double ppb_hg_norm(double g)
{
    return (1.0 - g * g) / (4.0 * PPB_PI);
}
PPB_FN double ppb_hg_phase(double g, double cos_angle)
{
    double den = ppb_hg_base(g, cos_angle);
    return (1.0 - g * g) / (4.0 * PPB_PI * den * sqrt(den));
}

#endif
