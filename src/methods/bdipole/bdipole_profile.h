/* bdipole_profile.h: d'Eon's better dipole (E. d'Eon, "A Better Dipole", 2012 technical note;
 * the same terms as Habel, Christensen & Jarosz 2013's photon beam diffusion evaluates per beam
 * sample, and pbrt-v4's BeamDiffusionMS), its closed-form plane integrals and its integrals over
 * the tube's geometry (reference: Methods, `bdipole`).
 *
 * Parameters from (sigma_t, albedo, g, n): sigma_s' = sigma_s (1 - g), sigma_t' = sigma_a +
 * sigma_s', alpha' = sigma_s' / sigma_t'; Grosjean's D = (2 sigma_a + sigma_s') / (3 sigma_t'^2);
 * sigma_tr = sqrt(sigma_a / D); the real source at depth z_r = 1 / sigma_t'; the extrapolation
 * distance z_b = 2 A D, A = (1 + 3 C2) / (1 - 2 C1), C_i = int_0^1 F(mu, 1/n) mu^i dmu the
 * Fresnel moments of light inside meeting the boundary (exact F, TIR included: pbrt's
 * FresnelMoment1/2(n) are polynomial fits of these); the virtual source at z_v = -z_r - 2 z_b.
 *
 * Profile: R(r) = alpha' (C_phi phi(r) + C_E E(r)), C_phi = (1 - 2 C1) / 4, C_E = (1 - 3 C2) / 2,
 *   phi(r) = (e^(-sigma_tr d_r) / d_r - e^(-sigma_tr d_v) / d_v) / (4 pi D),
 *   E(r)   = (z_r (1 + sigma_tr d_r) e^(-sigma_tr d_r) / d_r^3
 *             - z_v (1 + sigma_tr d_v) e^(-sigma_tr d_v) / d_v^3) / (4 pi),
 * d_r = sqrt(r^2 + z_r^2), d_v = sqrt(r^2 + z_v^2): the fluence and the normal flux -D dphi/dz
 * of a unit source and its negative image, read through the boundary with the P1 radiance
 * (phi / 4 pi + 3 E mu / 4 pi, times 1 - F, over the exit hemisphere gives C_phi phi + C_E E).
 * One alpha': the single-depth dipole stands for the whole first-collision source (strength
 * alpha'), every order it starts, single scattering included (pbrt's beam sum has alpha'^2: it
 * adds single scattering exactly, so its diffusion term keeps only the part of a scattering
 * point's emission that collides and scatters again).
 *
 * Plane integral at distance h (2 pi int R(sqrt(rho^2 + h^2)) rho drho, r dr = rho drho):
 *   P(h) = alpha' [C_phi (e^(-sigma_tr Q_r) - e^(-sigma_tr Q_v)) / (2 D sigma_tr)
 *                  + C_E (z_r e^(-sigma_tr Q_r) / Q_r + |z_v| e^(-sigma_tr Q_v) / Q_v) / 2],
 * Q = sqrt(h^2 + z^2); R_d = P(0) = alpha' [C_phi (e^(-sigma_tr z_r) - e^(-sigma_tr |z_v|)) /
 * (2 D sigma_tr) + C_E (e^(-sigma_tr z_r) + e^(-sigma_tr |z_v|)) / 2] (2 pi int e^(-s d) / d r dr =
 * 2 pi e^(-s z) / s; 2 pi int z (1 + s d) e^(-s d) / d^3 r dr = 2 pi e^(-s z)). At alpha' = 1
 * (sigma_tr = 0) R_d = C_phi 4 A + C_E = 1: all that enters returns.
 *
 * Line kernel (the tube's z axis): with q = sqrt(rho^2 + z_src^2),
 *   int e^(-s d) / d dz = 2 K0(s q)            (A&S 9.6.21),
 *   int z_src (1 + s d) e^(-s d) / d^3 dz = 2 z_src s K1(s q) / q (its q-derivative),
 * and at s = 0 their limits 2 ln(q_v / q_r) (the pair) and 2 z_src / q^2. */
#ifndef PPB_BDIPOLE_PROFILE_H
#define PPB_BDIPOLE_PROFILE_H

typedef struct ppb_bdipole {
    double alpha;    /* alpha': the source strength */
    double D;        /* diffusion coefficient, length */
    double sigma_tr; /* 1/length; 0 where nothing is absorbed */
    double zr, zv;   /* source depths: z_r > 0, z_v < 0 (above the surface) */
    double c_phi, c_e;
} ppb_bdipole;

/* The Fresnel moment C_i = int_0^1 F(mu, 1/n) mu^i dmu (i = 1, 2) of the exact unpolarized F
 * (kernels/ppb_fresnel.h) for light inside the medium (index n >= 1) meeting the boundary:
 * exactly mu_c^(i+1) / (i + 1) below the critical cosine mu_c = sqrt(1 - 1/n^2) (TIR), and above
 * it, in the air-side cosine (n^2 mu dmu = mu_o dmu_o, F equal on both sides by Stokes), the
 * smooth n^-2 int_0^1 F(mu_o, n) mu_o mu^(i-1) dmu_o by 4 panels of 16-point Gauss-Legendre.
 * 0 at n = 1. */
double ppb_bdipole_fresnel_moment(int i, double n);

/* The model's parameters for a medium (sigma_t > 0, albedo in [0, 1], g in (-1, 1), n >= 1). */
ppb_bdipole ppb_bdipole_make(double sigma_t, double albedo, double g, double n);

/* The profile R(r) above, r >= 0 (finite at 0: z_r > 0). */
double ppb_bdipole_R(const ppb_bdipole *b, double r);

/* The plane integral P(h) above, h >= 0; R_d = P(0). */
double ppb_bdipole_plane(const ppb_bdipole *b, double h);

/* The line kernel: int R(sqrt(rho^2 + z^2)) dz over the whole z axis, rho >= 0. */
double ppb_bdipole_line(const ppb_bdipole *b, double rho);

/* int_{ua}^{ub} line(sqrt(u^2 + v^2)) du: a point at in-plane offset v from the line of entry
 * points, the entry points at offset u along S1. Composite 10-point Gauss-Legendre: panels
 * halving toward the strip's point nearest the exit point down to a quarter of that point's
 * distance sqrt(u^2 + v^2 + z_r^2) from the nearest complex singularity (at least z_r: the
 * profile is finite), then panels of at most 10 / (nodes_per_l sigma_tr) out to where
 * sigma_tr q_r > 100 (the profile below e^-100); at sigma_tr = 0 the halving panels span the
 * strip (the profile's algebraic tail). */
double ppb_bdipole_strip(const ppb_bdipole *b, double ua, double ub, double v, int nodes_per_l);

#endif
