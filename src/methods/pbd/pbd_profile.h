/* pbd_profile.h: photon beam diffusion's radial profile Sr(r) of one medium, read from the table
 * as pbrt-v4's TabulatedBSSRDF::Sr reads it (bssrdf.h), and its integrals over the tube's
 * geometry (reference: Methods, `pbd`).
 *
 * Sr(r) = sigma_t^2 P(r sigma_t) / (2 pi r sigma_t), clamped at 0, where P is the table's
 * Catmull-Rom spline (pbd_table.h) in albedo and optical radius; 0 past the table's last radius
 * (r sigma_t > 2.5e-3 1.2^62 = 203), as pbrt. The spline's weights in albedo are the same at
 * every r, so the tensor product sum_j sum_k w_j(rho) w_k(r) T[j][k] is the spline in r of the
 * row mixture sum_j w_j(rho) T[j][.], which a profile keeps (identical to pbrt's Sr).
 *
 * The plane integral 2 pi int_h^inf Sr(r) r dr = int_{h sigma_t} P (clamped) over the optical
 * radius; at h = 0 it is the table's rhoEff mixed by the same weights (the spline's integral is
 * linear in its values). */
#ifndef PPB_PBD_PROFILE_H
#define PPB_PBD_PROFILE_H

#include "methods/pbd/pbd_table.h"

typedef struct ppb_pbd_profile {
    double sigma_t;
    double radius[PPB_PBD_NR]; /* the table's optical radii */
    double p[PPB_PBD_NR];      /* the row mixture at the medium's albedo: 2 pi r Sr, sigma_t = 1 */
    double rho_eff;            /* the table's rhoEff mixed by the same weights */
} ppb_pbd_profile;

/* The profile of a medium (sigma_t, albedo) of the table's g and eta. */
void ppb_pbd_profile_init(ppb_pbd_profile *p, const ppb_pbd_table *t, double sigma_t,
                          double albedo);

/* Sr(r), r >= 0 (physical units: per area). */
double ppb_pbd_sr(const ppb_pbd_profile *p, double r);

/* 2 pi int_h^inf Sr(r) r dr: the flux through a plane at distance h >= 0 from the entry point;
 * 4-point Gauss-Legendre on 64 sub-panels of each spline interval: exact for the cubic, and
 * close where the clamp at 0 cuts it (a kink, far out where the spline dips below 0). */
double ppb_pbd_plane(const ppb_pbd_profile *p, double h);

/* int_{-inf}^{inf} Sr(sqrt(rho^2 + z^2)) dz, rho >= 0: the line of entry points along z. Panels
 * of `nodes`-point Gauss-Legendre between the z where r crosses a table radius (the spline is a
 * cubic over 2 pi r between them, so each panel's integrand is smooth), the first one halved
 * toward z = 0 until its width is below rho / 4 (the integrand's complex singularity at
 * z = +-i rho: r = sqrt(rho^2 + z^2)). */
double ppb_pbd_line(const ppb_pbd_profile *p, double rho, int nodes);

/* int_{ua}^{ub} line(sqrt(u^2 + v^2)) du: the flux at an exit point at in-plane offset v from
 * the line of entry points (its depth below S1's plane), per unit irradiance entering over u in
 * [ua, ub] x all z. The same panels in u (edges where sqrt(u^2 + v^2) crosses a table radius,
 * halved toward the strip's nearest point down to a quarter of its distance), `nodes` points
 * each; the integrand is even in u, so the strip is folded onto u >= 0 at its nearest point. */
double ppb_pbd_strip(const ppb_pbd_profile *p, double ua, double ub, double v, int nodes);

#endif
