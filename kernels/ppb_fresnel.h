/* ppb_fresnel.h: the smooth dielectric boundary at n > 1 (reference: Keys), coded
 * once for host and kernels.
 *
 * Owns: the exact unpolarized Fresnel reflectance from the s- and p-amplitude coefficients
 * (Born & Wolf Sec. 1.5.2; not Schlick's approximation), with total internal reflection, and
 * the refraction of a cosine (Snell's law). The relative index n_rel = n_t / n_i: light entering
 * the medium from air sees n_rel = n, light leaving it sees n_rel = 1 / n. Plain C that is also
 * OpenCL C (double precision, as ppb_conventions.h). */
#ifndef PPB_FRESNEL_H
#define PPB_FRESNEL_H

#include "ppb_conventions.h"

/* Cosine of the refracted direction for incidence cosine cos_i in [0, 1] (Snell: sin_t =
 * sin_i / n_rel); -1 where the incidence is beyond the critical angle (total internal
 * reflection). */
PPB_FN double ppb_refract_cos(double cos_i, double n_rel)
{
    double sin2_t = (1.0 - cos_i * cos_i) / (n_rel * n_rel);
    return sin2_t >= 1.0 ? -1.0 : sqrt(1.0 - sin2_t);
}

/* Unpolarized reflectance F = (r_s^2 + r_p^2) / 2 with
 *     r_s = (cos_i - n_rel cos_t) / (cos_i + n_rel cos_t),
 *     r_p = (n_rel cos_i - cos_t) / (n_rel cos_i + cos_t);
 * 1 under total internal reflection; F(cos_i = 0) = 1 (grazing). At n_rel = 1 it is 0 up to
 * round-off; callers skip the boundary entirely at n = 1. */
PPB_FN double ppb_fresnel(double cos_i, double n_rel)
{
    double cos_t = ppb_refract_cos(cos_i, n_rel);
    if (cos_t < 0.0)
        return 1.0;
    double rs = (cos_i - n_rel * cos_t) / (cos_i + n_rel * cos_t);
    double rp = (n_rel * cos_i - cos_t) / (n_rel * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

/* The direction inside that leaves surface surf along the air-side direction w (w . n > 0,
 * n the outward normal), in place: Snell's law keeps the tangential part divided by n and
 * gives the normal part the refracted cosine. Returns the air-side cosine. */
PPB_FN double ppb_inside_dir(int surf, double n, double *w)
{
    double nx = ppb_normal_x(surf), ny = ppb_normal_y(surf);
    double ca = w[0] * nx + w[1] * ny, ci = ppb_refract_cos(ca, n);
    w[0] = (w[0] - ca * nx) / n + ci * nx;
    w[1] = (w[1] - ca * ny) / n + ci * ny;
    w[2] = w[2] / n;
    return ca;
}

/* The collimated beam at S1 (E_perp = 1 in air at cos theta_L): the refracted direction inside
 * (cos_t, sin_t, in the plane of incidence), the specular fraction F(cos theta_L), the
 * perpendicular irradiance of the transmitted beam inside, (1 - F) cos theta_L / cos theta_t (the
 * power (1 - F) cos theta_L per unit length of S1 spread over a beam cross-section shrunk by
 * cos theta_t / cos theta_L), and the reflectance f_inside = F(cos theta_t, 1/n) that the beam
 * meets at every internal reflection off S2 or S1 (equal to F(cos theta_L, n) by Stokes'
 * relations, computed from inside as the bounces see it). */
typedef struct ppb_fresnel_beam {
    double cos_t, sin_t, specular, irradiance, f_inside;
} ppb_fresnel_beam;

PPB_FN ppb_fresnel_beam ppb_fresnel_beam_in(double cos_l, double n)
{
    ppb_fresnel_beam b;
    b.cos_t = ppb_refract_cos(cos_l, n);
    b.sin_t = sqrt(fmax(0.0, 1.0 - b.cos_t * b.cos_t));
    b.specular = ppb_fresnel(cos_l, n);
    b.irradiance = (1.0 - b.specular) * cos_l / b.cos_t;
    b.f_inside = ppb_fresnel(b.cos_t, 1.0 / n);
    return b;
}

#endif
