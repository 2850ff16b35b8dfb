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
