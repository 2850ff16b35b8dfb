/* multipole.h: the multipole diffusion model of a homogeneous slab (Donner & Jensen 2005, Sec. 3
 * "multipole"; its one-pair case is the dipole of Jensen et al. 2001, Sec. 2.4): the reduced
 * coefficients, the source positions, the reflectance and transmittance profiles R(r), T(r), their
 * plane integrals, and the flux through any surface of the tube from sources below a strip of S1.
 *
 * Geometry: depth z is measured down from the lit face (S1, tube y = -z); the slab is
 * 0 <= z <= d. The extrapolated boundaries sit z_b = 2 A D outside each face, A the boundary
 * factor: 1 at n = 1, (1 + F_dr) / (1 - F_dr) at n > 1 (Jensen et al. 2001 Eq. 4-5's form, with
 * the exact diffuse Fresnel reflectance below; the same A at both faces, both facing air, as in
 * Donner & Jensen 2005 Sec. 3). Pair i (i = 0, +1, -1, +2, -2, ...) is a real source at
 * z_{r,i} = 2i(d + 2 z_b) + z_r and a negative (virtual) source at z_{v,i} = 2i(d + 2 z_b) - z_r
 * - 2 z_b, each of strength alpha' per unit incident power (DJ2005's source placement; i = 0 is
 * Jensen 2001's dipole with z_v = -(z_r + 4 A D)). A point source's fluence is
 * phi = alpha' exp(-sigma_tr d) / (4 pi D d) and the diffuse flux through a surface of outward
 * normal n is -D grad(phi) . n (Fick's law; Jensen 2001 R_d(r) is this at the top face). */
#ifndef PPB_MULTIPOLE_H
#define PPB_MULTIPOLE_H

#include "base/bessel.h" /* K1: the line kernel */
#include "base/err.h"
#include "physics/diffuse_exit.h" /* the diffuse Fresnel reflectance, the exit lobe */

#define PPB_MP_MAX_PAIRS 257

typedef struct ppb_multipole {
    double sigma_t, albedo, g; /* the medium as given: 1/mfp, single-scattering albedo, HG g */
    double sigma_s_reduced;    /* sigma_s' = sigma_s (1 - g) */
    double sigma_t_reduced;    /* sigma_t' = sigma_a + sigma_s' */
    double albedo_reduced;     /* alpha' = sigma_s' / sigma_t' */
    double sigma_tr;           /* effective transport coefficient sqrt(3 sigma_a sigma_t') */
    double D;                  /* diffusion constant 1 / (3 sigma_t') */
    double A;                  /* boundary factor: 1 at n = 1 (ppb_multipole_boundary_A) */
    double z_r, z_b;           /* depth of the first real source mu_source/sigma_t' (1/sigma_t' at
                                * n = 1); z_b = 2 A D */
    double thickness;          /* d; INFINITY for the semi-infinite dipole */
    int npairs;                /* dipole pairs in use: 1 + extra pairs */
    double depth[2 * PPB_MP_MAX_PAIRS];  /* source depths z (signed, below S1) */
    double charge[2 * PPB_MP_MAX_PAIRS]; /* +1 real, -1 virtual */
} ppb_multipole;

/* Sets up the multipole of a slab of thickness d (INFINITY: the semi-infinite dipole, always one
 * pair) with extra_pairs pairs beyond the first, taken in the order i = +1, -1, +2, -2, ...
 * (an even count is the symmetric truncation i = -n..n of DJ2005). Fails on coefficients
 * outside sigma_t > 0, 0 <= albedo <= 1, -1 < g < 1, d > 0, on albedo = 1 with a finite d (the
 * images' plane integrals then do not decay: truncation gives R = 1, T = 0), or too many pairs.
 * Outside the model's validity but accepted: d < z_r (d sigma_t' < 1), where the first real
 * source lies below the slab and T(r) goes negative. Convergence in pairs goes like
 * exp(-sigma_tr 2 (d + 2 z_b) n): slow as albedo -> 1. */
int ppb_multipole_init(ppb_multipole *mp, double sigma_t, double albedo, double g, double d,
                       int extra_pairs, ppb_err *err);

/* The same with boundary factor A >= 1 and the real source at z_r = mu_source / sigma_t'
 * (0 < mu_source <= 1: the depth of a point 1/sigma_t' along a beam of cosine mu_source);
 * A = 1, mu_source = 1 is ppb_multipole_init, bit for bit. */
int ppb_multipole_init_boundary(ppb_multipole *mp, double sigma_t, double albedo, double g,
                                double d, int extra_pairs, double A, double mu_source,
                                ppb_err *err);

/* ---- Refractive boundaries (n > 1; reference: Methods, `mp`) ---- */

/* The Egan-Hilgeman / Groenhuis polynomial fit of the inside F_dr that Jensen et al. 2001 Eq. 5
 * uses, -1.440/n^2 + 0.710/n + 0.668 + 0.0636 n (n the medium's index): kept for comparison
 * (tests), not used by mp (0.0016 at n = 1, where the exact value is 0). */
double ppb_mp_diffuse_fresnel_fit(double n);

/* A = (1 + F_dr) / (1 - F_dr) with the exact inside F_dr = ppb_diffuse_fresnel(1/n)
 * (Jensen et al. 2001 Eq. 4); exactly 1 at n <= 1. */
double ppb_multipole_boundary_A(double n);

int ppb_multipole_nsources(const ppb_multipole *mp);

/* Diffuse flux per unit incident power at radial distance r from the entry point, leaving the
 * top face (R) and the bottom face (T) (DJ2005 R(r), T(r); Jensen 2001 R_d(r) for one pair). */
double ppb_multipole_R(const ppb_multipole *mp, double r);
double ppb_multipole_T(const ppb_multipole *mp, double r);

/* Their integrals over the plane, 2 pi int r R(r) dr, in closed form: each source at signed
 * depth z contributes charge * alpha' * sign(z) exp(-sigma_tr |z|) / 2 (T: with d - z). */
double ppb_multipole_total_R(const ppb_multipole *mp);
double ppb_multipole_total_T(const ppb_multipole *mp);

/* Flux, per unit irradiance on S1, through a surface of outward normal (nx, ny) at the tube
 * point (xp, yp) (y = -depth) from the sources below every point of the strip xa <= x <= xb of
 * S1, all along z. Over z in closed form: a line of point sources gives
 * int (1 + s d) exp(-s d) / d^3 dz = 2 s K1(s rho) / rho (s = sigma_tr, rho the in-plane
 * distance). Over x by composite Gauss-Legendre (nodes_per_mfp nodes per mfp) after subtracting
 * the 1/rho^2 part, which is integrated exactly: the sides' log singularity at the real source's
 * depth is thus handled analytically. */
double ppb_multipole_strip_flux(const ppb_multipole *mp, double xp, double yp, double nx, double ny,
                                double xa, double xb, int nodes_per_mfp);

/* The same flux averaged over a segment of S1..S4 from (x0, y0) to (x1, y1): along x (y0 = y1,
 * normal (0, +-1)) or along y (x0 = x1, normal (+-1, 0)). The 1/rho^2 part is averaged in closed
 * form (primitives of atan and log), which resolves the sides' log singularity at y = -z_r; the
 * smooth remainder by the midpoint rule on `points` points. */
double ppb_multipole_segment_flux(const ppb_multipole *mp, double x0, double y0, double x1,
                                  double y1, double nx, double ny, double xa, double xb,
                                  int nodes_per_mfp, int points);

#endif
