/* multipole.c: Donner & Jensen 2005 multipole (Jensen et al. 2001 dipole as its one-pair case);
 * see multipole.h for the geometry and the conventions. */
#include "methods/mp/multipole.h"

#include <math.h>

#include "kernels/ppb_conventions.h"
#include "kernels/ppb_fresnel.h"

#include "base/quadrature.h"
#include "physics/diffuse_exit.h"

/* Mirror index of pair k in the order 0, +1, -1, +2, -2, ... */
static int pair_index(int k)
{
    return (k % 2) ? (k + 1) / 2 : -k / 2;
}

static void place_sources(ppb_multipole *mp)
{
    /* DJ2005 Sec. 3: mirroring the dipole about both extrapolated boundaries (z = -z_b and
     * z = d + z_b) repeats it with period 2 (d + 2 z_b). */
    double period = isinf(mp->thickness) ? 0.0 : 2.0 * (mp->thickness + 2.0 * mp->z_b);
    for (int k = 0; k < mp->npairs; k++) {
        double shift = pair_index(k) * period;
        mp->depth[2 * k] = shift + mp->z_r;
        mp->charge[2 * k] = 1.0;
        mp->depth[2 * k + 1] = shift - mp->z_r - 2.0 * mp->z_b;
        mp->charge[2 * k + 1] = -1.0;
    }
}

int ppb_multipole_init(ppb_multipole *mp, double sigma_t, double albedo, double g, double d,
                       int extra_pairs, ppb_err *err)
{
    return ppb_multipole_init_boundary(mp, sigma_t, albedo, g, d, extra_pairs, 1.0, 1.0, err);
}

int ppb_multipole_init_boundary(ppb_multipole *mp, double sigma_t, double albedo, double g,
                                double d, int extra_pairs, double A, double mu_source, ppb_err *err)
{
    if (!(sigma_t > 0) || !(albedo >= 0 && albedo <= 1) || !(g > -1 && g < 1) || !(d > 0))
        return ppb_fail(err,
                        "multipole: needs sigma_t > 0, 0 <= albedo <= 1, -1 < g < 1, d > 0 "
                        "(got %g, %g, %g, %g)",
                        sigma_t, albedo, g, d);
    if (albedo == 1 && !isinf(d))
        return ppb_fail(err, "multipole: albedo = 1 gives sigma_tr = 0, where the image series of "
                             "a finite slab converges only conditionally (truncated, it gives "
                             "T = 0); use albedo < 1");
    if (!(A >= 1.0) || !isfinite(A))
        return ppb_fail(err, "multipole: boundary factor A = %g, needs A >= 1", A);
    if (!(mu_source > 0.0 && mu_source <= 1.0))
        return ppb_fail(err, "multipole: source cosine %g outside (0, 1]", mu_source);
    if (extra_pairs < 0 || extra_pairs >= PPB_MP_MAX_PAIRS)
        return ppb_fail(err, "multipole: pairs = %d outside [0, %d]", extra_pairs,
                        PPB_MP_MAX_PAIRS - 1);
    double sigma_s = albedo * sigma_t, sigma_a = sigma_t - sigma_s;
    mp->sigma_t = sigma_t;
    mp->albedo = albedo;
    mp->g = g;
    mp->sigma_s_reduced = sigma_s * (1.0 - g);
    mp->sigma_t_reduced = sigma_a + mp->sigma_s_reduced;
    mp->albedo_reduced = mp->sigma_s_reduced / mp->sigma_t_reduced;
    mp->sigma_tr = sqrt(3.0 * sigma_a * mp->sigma_t_reduced);
    mp->D = 1.0 / (3.0 * mp->sigma_t_reduced);
    mp->z_r = mu_source / mp->sigma_t_reduced; /* 1 / sigma_t' at mu_source = 1 */
    mp->A = A;
    mp->z_b = 2.0 * A * mp->D; /* Jensen 2001: z_b = 2 A D; A = 1 at n = 1 */
    mp->thickness = d;
    mp->npairs = isinf(d) ? 1 : 1 + extra_pairs;
    place_sources(mp);
    return 0;
}

double ppb_mp_diffuse_fresnel_fit(double n)
{
    return -1.440 / (n * n) + 0.710 / n + 0.668 + 0.0636 * n;
}

double ppb_multipole_boundary_A(double n)
{
    if (!(n > 1.0))
        return 1.0;
    double fdr = ppb_diffuse_fresnel(1.0 / n);
    return (1.0 + fdr) / (1.0 - fdr);
}

int ppb_multipole_nsources(const ppb_multipole *mp)
{
    return 2 * mp->npairs;
}

/* Outward flux of one unit point source at distance dist, (p - s) . n = along, per unit power
 * of the source before the alpha' factor: (1 + s d) exp(-s d) / (4 pi d^3) x along. */
static double point_flux(double sigma_tr, double dist, double along)
{
    return (1.0 + sigma_tr * dist) * exp(-sigma_tr * dist) / (4.0 * PPB_PI * dist * dist * dist) *
           along;
}

double ppb_multipole_R(const ppb_multipole *mp, double r)
{
    double sum = 0;
    for (int k = 0; k < ppb_multipole_nsources(mp); k++) {
        double z = mp->depth[k];
        sum += mp->charge[k] * point_flux(mp->sigma_tr, sqrt(r * r + z * z), z);
    }
    return mp->albedo_reduced * sum;
}

double ppb_multipole_T(const ppb_multipole *mp, double r)
{
    if (isinf(mp->thickness))
        return 0.0;
    double sum = 0;
    for (int k = 0; k < ppb_multipole_nsources(mp); k++) {
        double h = mp->thickness - mp->depth[k];
        sum += mp->charge[k] * point_flux(mp->sigma_tr, sqrt(r * r + h * h), h);
    }
    return mp->albedo_reduced * sum;
}

/* 2 pi int_0^inf r (1 + s d) exp(-s d) h / (4 pi d^3) dr with d^2 = r^2 + h^2: substituting
 * r dr = d dd, the integrand is -(h/2) d/dd (exp(-s d) / d), so it equals sign(h) exp(-s|h|)/2. */
static double plane_integral(double sigma_tr, double h)
{
    return h == 0 ? 0.0 : copysign(0.5 * exp(-sigma_tr * fabs(h)), h);
}

double ppb_multipole_total_R(const ppb_multipole *mp)
{
    double sum = 0;
    for (int k = 0; k < ppb_multipole_nsources(mp); k++)
        sum += mp->charge[k] * plane_integral(mp->sigma_tr, mp->depth[k]);
    return mp->albedo_reduced * sum;
}

double ppb_multipole_total_T(const ppb_multipole *mp)
{
    if (isinf(mp->thickness))
        return 0.0;
    double sum = 0;
    for (int k = 0; k < ppb_multipole_nsources(mp); k++)
        sum += mp->charge[k] * plane_integral(mp->sigma_tr, mp->thickness - mp->depth[k]);
    return mp->albedo_reduced * sum;
}

/* x K1(x) - 1 (0 when sigma_tr = 0: pure scattering, where the line kernel is exactly 2/rho^2). */
static double k1_excess(double sigma_tr, double rho)
{
    if (sigma_tr == 0)
        return 0.0;
    double x = sigma_tr * rho;
    return x * ppb_bessel_k1(x) - 1.0;
}

/* int_{ua}^{ub} (-u nx + v ny) / (u^2 + v^2) du, exactly. */
static double inverse_square_strip(double ua, double ub, double v, double nx, double ny)
{
    double v2 = fmax(v * v, 1e-300);
    double log_part = -0.5 * nx * log((ub * ub + v2) / (ua * ua + v2));
    double atan_part = v == 0 ? 0.0 : ny * (atan(ub / v) - atan(ua / v));
    return log_part + atan_part;
}

/* int_{ua}^{ub} (-u nx + v ny) (x K1(x) - 1) / rho^2 du, rho^2 = u^2 + v^2, x = sigma_tr rho:
 * the smooth remainder after the 1/rho^2 part, by composite 4-point Gauss-Legendre (gl_node,
 * gl_weight: ppb_gauss_legendre(4), summed in ascending x). */
static double remainder_strip(double sigma_tr, double ua, double ub, double v, double nx, double ny,
                              int nodes_per_mfp, const double gl_node[4], const double gl_weight[4])
{
    if (sigma_tr == 0)
        return 0.0;
    int panels = (int)ceil((ub - ua) * nodes_per_mfp / 4.0);
    panels = panels < 1 ? 1 : panels;
    double half = 0.5 * (ub - ua) / panels, sum = 0;
    for (int p = 0; p < panels; p++) {
        double mid = ua + (2 * p + 1) * half;
        for (int j = 3; j >= 0; j--) {
            double u = mid + half * gl_node[j];
            double rho2 = u * u + v * v;
            if (rho2 == 0)
                continue; /* the integrand tends to 0 there: (-u nx) (x^2/2) ln x / rho^2 */
            sum += gl_weight[j] * (-u * nx + v * ny) * k1_excess(sigma_tr, sqrt(rho2)) / rho2;
        }
    }
    return sum * half;
}

double ppb_multipole_strip_flux(const ppb_multipole *mp, double xp, double yp, double nx, double ny,
                                double xa, double xb, int nodes_per_mfp)
{
    if (!(xb > xa))
        return 0.0;
    /* A source line at (x_e, -z) along z: (p - s) . n = -u nx + v ny with u = x_e - xp and
     * v = yp + z; its z-integrated flux is alpha' q (-u nx + v ny) 2 s K1(s rho) / (4 pi rho),
     * i.e. alpha' q / (2 pi) x (-u nx + v ny) (1 + (x K1(x) - 1)) / rho^2. */
    double ua = xa - xp, ub = xb - xp, sum = 0, gl_node[4], gl_weight[4];
    ppb_gauss_legendre(4, gl_node, gl_weight);
    for (int k = 0; k < ppb_multipole_nsources(mp); k++) {
        double v = yp + mp->depth[k];
        double line =
            inverse_square_strip(ua, ub, v, nx, ny) +
            remainder_strip(mp->sigma_tr, ua, ub, v, nx, ny, nodes_per_mfp, gl_node, gl_weight);
        sum += mp->charge[k] * line;
    }
    return mp->albedo_reduced * sum / (2.0 * PPB_PI);
}

/* int atan(c / v) dc (v != 0). */
static double atan_primitive(double c, double v)
{
    return c * atan(c / v) - 0.5 * v * log(c * c + v * v);
}

/* int ln(u^2 + v^2) dv, with 0 ln 0 = 0 at u = v = 0. */
static double log_primitive(double u, double v)
{
    double r2 = u * u + v * v;
    double vlog = v == 0 ? 0.0 : v * log(r2);
    return vlog - 2.0 * v + (u == 0 ? 0.0 : 2.0 * u * atan(v / u));
}

/* Segment average of int_{xa}^{xb} (-u nx + v ny) / (u^2 + v^2) dx_e for one source at depth z:
 * along x (nx = 0) the exit x runs over [x0, x1] at v = y0 + z; along y (ny = 0) v runs over
 * [y0 + z, y1 + z] at u = x_e - x0. */
static double inverse_square_segment(double x0, double y0, double x1, double y1, double nx,
                                     double ny, double xa, double xb, double z)
{
    if (y0 == y1) {
        double v = y0 + z;
        if (v == 0 || x1 == x0)
            return inverse_square_strip(xa - x0, xb - x0, v, nx, ny);
        double up = atan_primitive(xb - x0, v) - atan_primitive(xb - x1, v);
        double lo = atan_primitive(xa - x0, v) - atan_primitive(xa - x1, v);
        return ny * (up - lo) / (x1 - x0);
    }
    double va = y0 + z, vb = y1 + z, ua = xa - x0, ub = xb - x0;
    double logs = (log_primitive(ub, vb) - log_primitive(ub, va)) -
                  (log_primitive(ua, vb) - log_primitive(ua, va));
    return -0.5 * nx * logs / (vb - va);
}

double ppb_multipole_segment_flux(const ppb_multipole *mp, double x0, double y0, double x1,
                                  double y1, double nx, double ny, double xa, double xb,
                                  int nodes_per_mfp, int points)
{
    if (!(xb > xa))
        return 0.0;
    points = points < 1 ? 1 : points;
    double sum = 0, gl_node[4], gl_weight[4];
    ppb_gauss_legendre(4, gl_node, gl_weight);
    for (int k = 0; k < ppb_multipole_nsources(mp); k++) {
        double z = mp->depth[k], rem = 0;
        for (int j = 0; j < points; j++) {
            double f = (j + 0.5) / points;
            double xp = x0 + f * (x1 - x0), yp = y0 + f * (y1 - y0);
            rem += remainder_strip(mp->sigma_tr, xa - xp, xb - xp, yp + z, nx, ny, nodes_per_mfp,
                                   gl_node, gl_weight);
        }
        double line = inverse_square_segment(x0, y0, x1, y1, nx, ny, xa, xb, z) + rem / points;
        sum += mp->charge[k] * line;
    }
    return mp->albedo_reduced * sum / (2.0 * PPB_PI);
}
