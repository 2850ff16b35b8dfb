/* pbd_table.h: photon beam diffusion's profile table (reference: Methods, `pbd`), written after
 * pbrt-v4's bssrdf.cpp (ComputeBeamDiffusionBSSRDF, BeamDiffusionMS, BeamDiffusionSS) and
 * util/math.cpp (CatmullRomWeights, IntegrateCatmullRom): Habel, Christensen & Jarosz 2013,
 * "Photon Beam Diffusion: A Hybrid Monte Carlo Method for Subsurface Scattering" (EGSR; "PBD"
 * below), as pbrt-v4 ships it and Pharr, Jakob & Humphreys, "Physically Based Rendering" 4th ed.
 * Sec. 15.5 derives it ("PBRT 15.5"). Own code, pbrt's conventions (in double precision).
 *
 * Owns: the beam's multiple-scattering exitance (PBD's dipoles along the beam with the
 * better dipole's Grosjean coefficient, and PBD's kappa and pbrt's rho'^2 factors), its
 * single-scattering exitance (PBD's exact single-scattering term, beam at normal incidence), the
 * Fresnel moment fits pbrt uses, the table of 2 pi r (SS + MS)(r) over pbrt's 100 albedos and 64
 * optical radii at sigma_t = 1 with each row's plane integral rhoEff, and the Catmull-Rom spline
 * pbrt interpolates it with. */
#ifndef PPB_PBD_TABLE_H
#define PPB_PBD_TABLE_H

#define PPB_PBD_NRHO    100 /* pbrt-v4's table: albedo samples */
#define PPB_PBD_NR      64  /* and optical radius samples */
#define PPB_PBD_SAMPLES 100 /* beam samples of BeamDiffusionMS and BeamDiffusionSS */

/* pbrt-v4's polynomial fits of the first two Fresnel moments 2 int_0^1 F(mu) mu^k dmu, k = 1,
 * 2, in the relative index eta (util/scattering.cpp; d'Eon & Irving 2011's fits). pbrt calls
 * FresnelMoment1(eta) in the dipole's boundary (eta = n) and FresnelMoment1(1 / eta) in the exit
 * lobe's normalisation. */
double ppb_pbd_fresnel_moment1(double eta);
double ppb_pbd_fresnel_moment2(double eta);

/* Radiant exitance at distance r from where a beam enters normally, per unit power entering,
 * multiple scattering (BeamDiffusionMS): the mean over `samples` beam depths z_r = -ln(1 - (i +
 * 1/2) / samples) / sigma_t' (quantiles of the beam's reduced attenuation: PBD's exponential
 * importance sampling of the beam) of the better dipole's exitance (PBRT 15.5: the dipole's
 * fluence times 1/4 (1 - 2 C1) plus its normal flux times 1/2 (1 - 3 C2), with D_g = (2 sigma_a +
 * sigma_s') / (3 sigma_t'^2), sigma_tr = sqrt(sigma_a / D_g), z_v = -z_r + 2 z_e, z_e = -2 D_g (1 +
 * 3 C2) / (1 - 2 C1), C_k = FresnelMoment_k(eta)), each weighted by kappa = 1 - exp(-2 sigma_t'
 * (d_r + z_r)) (PBD's correction near the source) and rho'^2 (pbrt's; rho' = sigma_s' / sigma_t').
 * samples = 100: pbrt's. */
double ppb_pbd_ms(double sigma_s, double sigma_a, double g, double eta, double r, int samples);

/* The same, single scattering (BeamDiffusionSS, PBD's exact single-scattering term for the
 * normally refracted beam):
 * the mean over `samples` depths t = t_c - ln(1 - (i + 1/2) / samples) / sigma_t, from t_c = r
 * sqrt(eta^2 - 1) (the exit ray's critical angle), of rho exp(-sigma_t (d + t_c)) / d^2 p(-cos
 * theta_o) (1 - F(cos theta_o, 1 / eta)) cos theta_o, d = sqrt(r^2 + t^2), cos theta_o = t / d,
 * p Henyey-Greenstein at g (pbrt-v4's HenyeyGreenstein(cos theta_o, g) is the standard
 * (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5) at mu = -cos theta_o: the back-scattering angle). */
double ppb_pbd_ss(double sigma_s, double sigma_a, double g, double eta, double r, int samples);

/* Catmull-Rom spline weights of pbrt (CatmullRomWeights): for x in [nodes[0], nodes[n-1]]
 * (ascending), *offset and w[4] such that sum_k w[k] f[offset + k] (k with w[k] != 0) is the
 * cubic Hermite interpolant on x's interval with finite-difference slopes (one-sided at the
 * ends); 0 (nothing set) outside. */
int ppb_pbd_cr_weights(const double *nodes, int n, double x, int *offset, double w[4]);

/* The spline's integral over [nodes[0], nodes[n-1]] (IntegrateCatmullRom, exact for the
 * spline: width ((f0 + f1) / 2 + (d0 - d1) / 12) per interval). */
double ppb_pbd_cr_integral(const double *nodes, const double *f, int n);

typedef struct ppb_pbd_table {
    double g, eta;
    double rho[PPB_PBD_NRHO];                  /* (1 - exp(-8 i / 99)) / (1 - exp(-8)) */
    double radius[PPB_PBD_NR];                 /* 0, 2.5e-3, then x 1.2: optical radii */
    double profile[PPB_PBD_NRHO * PPB_PBD_NR]; /* 2 pi r (SS + MS)(r), sigma_t = 1 */
    double rho_eff[PPB_PBD_NRHO];              /* each row's spline integral over r */
} ppb_pbd_table;

/* ComputeBeamDiffusionBSSRDF(g, eta): the table of a medium with phase asymmetry g and relative
 * index eta (1 at n = 1), beam samples `samples` (PPB_PBD_SAMPLES: pbrt's). */
void ppb_pbd_table_build(ppb_pbd_table *t, double g, double eta, int samples);

#endif
