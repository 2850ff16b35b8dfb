/* bdipole_profile.c: d'Eon's better dipole and its integrals (bdipole_profile.h). */
#include "methods/bdipole/bdipole_profile.h"

#include <math.h>

#include "base/bessel.h"
#include "base/quadrature.h"
#include "kernels/ppb_fresnel.h"

double ppb_bdipole_fresnel_moment(int i, double n)
{
    if (!(n > 1.0))
        return 0.0;
    enum { Q = 16, PANELS = 4 };
    double x[Q], w[Q];
    ppb_gauss_legendre(Q, x, w);
    double mu_c = sqrt(1.0 - 1.0 / (n * n)), sum = 0.0;
    for (int p = 0; p < PANELS; p++) {
        double lo = (double)p / PANELS, half = 0.5 / PANELS, mid = lo + half;
        for (int j = 0; j < Q; j++) {
            double mu_o = mid + half * x[j];
            double mu = sqrt(1.0 - (1.0 - mu_o * mu_o) / (n * n)); /* the inside cosine */
            sum += half * w[j] * ppb_fresnel(mu_o, n) * mu_o * pow(mu, i - 1);
        }
    }
    return pow(mu_c, i + 1) / (i + 1) + sum / (n * n);
}

ppb_bdipole ppb_bdipole_make(double sigma_t, double albedo, double g, double n)
{
    double sigma_a = sigma_t * (1.0 - albedo), sigma_s_r = sigma_t * albedo * (1.0 - g);
    double sigma_t_r = sigma_a + sigma_s_r;
    double C1 = ppb_bdipole_fresnel_moment(1, n), C2 = ppb_bdipole_fresnel_moment(2, n);
    double A = (1.0 + 3.0 * C2) / (1.0 - 2.0 * C1);
    ppb_bdipole b;
    b.alpha = sigma_s_r / sigma_t_r;
    b.D = (2.0 * sigma_a + sigma_s_r) / (3.0 * sigma_t_r * sigma_t_r);
    b.sigma_tr = sqrt(sigma_a / b.D);
    b.zr = 1.0 / sigma_t_r;
    b.zv = -b.zr - 4.0 * A * b.D; /* -z_r - 2 z_b */
    b.c_phi = 0.25 * (1.0 - 2.0 * C1);
    b.c_e = 0.5 * (1.0 - 3.0 * C2);
    return b;
}

double ppb_bdipole_R(const ppb_bdipole *b, double r)
{
    double s = b->sigma_tr, zv = -b->zv;
    double dr = sqrt(r * r + b->zr * b->zr), dv = sqrt(r * r + zv * zv);
    double er = exp(-s * dr), ev = exp(-s * dv);
    /* e^(-s dr) / dr - e^(-s dv) / dv as two non-negative parts, without the cancellation that
     * loses the fluence pair's far tail (dv - dr -> 0): e^(-s dr) (dv - dr) / (dr dv) +
     * (e^(-s dr) - e^(-s dv)) / dv, dv - dr = (zv^2 - zr^2) / (dv + dr). */
    double gap = (zv * zv - b->zr * b->zr) / (dv + dr);
    double phi = (er * gap / (dr * dv) - er * expm1(-s * gap) / dv) / b->D;
    double E =
        b->zr * (1.0 + s * dr) * er / (dr * dr * dr) + zv * (1.0 + s * dv) * ev / (dv * dv * dv);
    return b->alpha * (b->c_phi * phi + b->c_e * E) / (4.0 * PPB_PI);
}

/* (e^(-s a) - e^(-s b)) / s for 0 < a < b, and its limit b - a at s = 0, without cancellation. */
static double exp_diff_over_s(double s, double a, double b)
{
    return s > 0.0 ? -exp(-s * a) * expm1(-s * (b - a)) / s : b - a;
}

double ppb_bdipole_plane(const ppb_bdipole *b, double h)
{
    double s = b->sigma_tr, zv = -b->zv;
    double Qr = sqrt(h * h + b->zr * b->zr), Qv = sqrt(h * h + zv * zv);
    double phi = exp_diff_over_s(s, Qr, Qv) / (2.0 * b->D);
    double E = 0.5 * (b->zr * exp(-s * Qr) / Qr + zv * exp(-s * Qv) / Qv);
    return b->alpha * (b->c_phi * phi + b->c_e * E);
}

double ppb_bdipole_line(const ppb_bdipole *b, double rho)
{
    double s = b->sigma_tr, zv = -b->zv;
    double qr = sqrt(rho * rho + b->zr * b->zr), qv = sqrt(rho * rho + zv * zv), phi, E;
    if (s > 0.0) {
        phi = ppb_bessel_k0(s * qr) - ppb_bessel_k0(s * qv);
        E = s * (b->zr * ppb_bessel_k1(s * qr) / qr + zv * ppb_bessel_k1(s * qv) / qv);
    } else { /* the limits: K0(s qr) - K0(s qv) -> ln(qv / qr), s K1(s q) -> 1 / q */
        phi = 0.5 * log1p((zv * zv - b->zr * b->zr) / (qr * qr)); /* exact far out too */
        E = b->zr / (qr * qr) + zv / (qv * qv);
    }
    /* 2 (phi-part / (4 pi D) + E-part / (4 pi)) */
    return b->alpha * (b->c_phi * phi / b->D + b->c_e * E) / (2.0 * PPB_PI);
}

#define GL_ORDER 10

static double panel(const ppb_bdipole *b, double v, double lo, double hi, const double *x,
                    const double *w)
{
    double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo), sum = 0.0;
    for (int j = GL_ORDER - 1; j >= 0; j--) {
        double u = mid + half * x[j];
        sum += w[j] * ppb_bdipole_line(b, sqrt(u * u + v * v));
    }
    return half * sum;
}

/* int_a^b of the line kernel over u, 0 <= a < b: the integrand falls with u, fastest near a,
 * where its nearest complex singularities lie at u = +-i sqrt(v^2 + z_r^2). */
static double from_near(const ppb_bdipole *b, double v, double a, double bb, double hmax,
                        const double *x, const double *w)
{
    const double far = 100.0; /* sigma_tr q_r beyond which the profile is below e^-100 */
    double s = b->sigma_tr, zr2 = b->zr * b->zr;
    double near = sqrt(a * a + v * v + zr2);
    if (s * near > far)
        return 0.0;
    double c = fmin(bb, a + hmax), sum = 0.0, stop = 0.25 * near, hi = c;
    /* Panels halving toward a: [a + w/2, a + w] lies w/2 or more from a and `near` from the
     * singularities, so 10 nodes converge fast; the last one, [a, a + w], has w <= near / 4. */
    while (hi - a > stop) {
        double lo = a + 0.5 * (hi - a);
        sum += panel(b, v, lo, hi, x, w);
        hi = lo;
    }
    sum += panel(b, v, a, hi, x, w);
    for (double lo = c; lo < bb; lo += hmax) {
        if (s * sqrt(lo * lo + v * v + zr2) > far)
            break;
        sum += panel(b, v, lo, fmin(bb, lo + hmax), x, w);
    }
    return sum;
}

double ppb_bdipole_strip(const ppb_bdipole *b, double ua, double ub, double v, int nodes_per_l)
{
    if (!(ub > ua) || !(b->alpha > 0.0))
        return 0.0;
    double x[GL_ORDER], w[GL_ORDER];
    ppb_gauss_legendre(GL_ORDER, x, w);
    nodes_per_l = nodes_per_l < 1 ? 1 : nodes_per_l;
    double hmax = b->sigma_tr > 0.0 ? (double)GL_ORDER / (nodes_per_l * b->sigma_tr) : INFINITY;
    /* The integrand is even in u: fold [ua, ub] onto u >= 0, split at the nearest point. */
    if (ua >= 0.0)
        return from_near(b, v, ua, ub, hmax, x, w);
    if (ub <= 0.0)
        return from_near(b, v, -ub, -ua, hmax, x, w);
    return from_near(b, v, 0.0, -ua, hmax, x, w) + from_near(b, v, 0.0, ub, hmax, x, w);
}
