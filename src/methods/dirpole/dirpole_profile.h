/* dirpole_profile.h: the directional dipole of Frisvad, Al-Mashat, Christensen & Jensen / Frisvad,
 * Hachisuka & Kjeldsen 2014 ("Directional Dipole Model for Subsurface Scattering", ACM TOG 34(1),
 * article 5; the authors' sample code, dirpole.cpp, fixes the conventions where the text leaves
 * them open) and its integrals over the tube's lit strip (reference: Methods, `dirpole`).
 *
 * Owns: the parameters from (sigma_t, albedo, g, n) and the refracted beam direction w_12; the
 * Fresnel moments' fits C1, C2 (d'Eon & Irving 2011's polynomials, as the paper uses them); the
 * exitance of one entry point at an exit point (the paper's S_d times the exit hemisphere's
 * Fresnel transmission, pi (1 - 2 C1(1/eta)) = 4 pi C_phi(1/eta): the power that crosses the
 * boundary per unit power entering); its integral over the whole z axis of entry points by
 * Gauss-Legendre on z = q sinh t, and over a strip of S1 by graded Gauss-Legendre panels. */
#ifndef PPB_DIRPOLE_PROFILE_H
#define PPB_DIRPOLE_PROFILE_H

/* d'Eon & Irving 2011's fits of the first two Fresnel moments at relative index eta (the
 * medium's index over the outside's), as the paper's Sec. 3 uses them: 2 C1(eta) = 2 int_0^1
 * F mu dmu and 3 C2(eta) = 3 int_0^1 F mu^2 dmu for light inside the medium meeting the boundary
 * (total internal reflection at eta > 1); C1(1/eta) is the outside's. Exactly 0 at eta = 1 (no
 * boundary: the fits are within 7e-3 of 0 there). */
double ppb_dirpole_c1(double eta);
double ppb_dirpole_c2(double eta);

typedef struct ppb_dirpole {
    double D;        /* diffusion coefficient 1 / (3 sigma_t') */
    double sigma_tr; /* effective transport coefficient sqrt(sigma_a / D) */
    double sigma_t;  /* extinction: the real source's offset 1 / (3 sigma_t) behind an exit face */
    double de;       /* extrapolation distance 2.131 D / sqrt(alpha') */
    double A;        /* boundary factor (1 - C_E(eta)) / (2 C_phi(eta)) */
    double c_phi;    /* C_phi(eta) = (1 - 2 C1(eta)) / 4 */
    double c_e;      /* C_E(eta) = (1 - 3 C2(eta)) / 2 */
    double w[3];     /* w_12: the refracted beam's direction inside */
    int none;        /* alpha' = 0: no scattering, nothing diffuses (exitance 0) */
} ppb_dirpole;

/* The parameters of a medium (sigma_t, albedo, g) of index n under a beam whose refracted
 * direction inside is w12 (a unit vector into the medium). */
void ppb_dirpole_init(ppb_dirpole *p, double sigma_t, double albedo, double g, double n,
                      const double w12[3]);

/* The exitance (power per unit area crossing the boundary outward) at x_o per unit power
 * entering at x_i along w_12: 4 pi C_phi(1/eta) S_d(x_i, w_12; x_o), with x = x_o - x_i, n_i the
 * entry point's outward normal and n_o the exit point's (unit vectors). S_d is the real ray
 * source minus the virtual one mirrored across the modified tangent plane, clamped at 0 as the
 * authors' code does. */
double ppb_dirpole_exitance(const ppb_dirpole *p, const double x[3], const double ni[3],
                            const double no[3]);

/* The exitance integrated over the line of entry points (x_i, 0, z), z over the whole axis, for
 * an exit point at (x_i + u, v, 0) with outward normal no (the entry normal is S1's, +y):
 * 2 int_0^inf over z = q sinh t, q = min(sqrt(u^2 + v^2 + l^2), |u|) (l the sources' smallest
 * offset from the exit point; |u| because the integrand is not smooth at u = z = 0: d_r holds
 * r, not r^2, and n_i* turns over where x_o lies below x_i), Gauss-Legendre panels of 8 nodes,
 * `samples` nodes per unit of t, out to where sigma_tr r > 40 (e^-40). */
double ppb_dirpole_line(const ppb_dirpole *p, double u, double v, const double no[3], int samples);

/* int over u in [ua, ub] of line(u, v): an exit point at (x, v) and entry points at x - u on S1.
 * 10-point Gauss-Legendre panels halving toward the nearest point of [ua, ub] (u = 0 when it is
 * inside) down to a quarter of its distance sqrt(u^2 + v^2 + l^2) from the sources (a hundredth
 * of that toward u = 0, where the line is not smooth), then panels of at most
 * 10 / (samples sigma_tr) out to where sigma_tr sqrt(u^2 + v^2) > 40. */
double ppb_dirpole_strip(const ppb_dirpole *p, double ua, double ub, double v, const double no[3],
                         int samples);

#endif
