/* pbd_table.c: photon beam diffusion's profile table (pbd_table.h). After pbrt-v4, bssrdf.cpp
 * and util/math.cpp (own code, pbrt's conventions). */
#include "methods/pbd/pbd_table.h"

#include <math.h>

#include "kernels/ppb_conventions.h"
#include "kernels/ppb_fresnel.h"

double ppb_pbd_fresnel_moment1(double eta)
{
    double e2 = eta * eta, e3 = e2 * eta, e4 = e3 * eta, e5 = e4 * eta;
    if (eta < 1.0)
        return 0.45966 - 1.73965 * eta + 3.37668 * e2 - 3.904945 * e3 + 2.49277 * e4 - 0.68441 * e5;
    return -4.61686 + 11.1136 * eta - 10.4646 * e2 + 5.11455 * e3 - 1.27198 * e4 + 0.12746 * e5;
}

double ppb_pbd_fresnel_moment2(double eta)
{
    double e2 = eta * eta, e3 = e2 * eta, e4 = e3 * eta, e5 = e4 * eta;
    if (eta < 1.0)
        return 0.27614 - 0.87350 * eta + 1.12077 * e2 - 0.65095 * e3 + 0.07883 * e4 + 0.04860 * e5;
    double r1 = 1.0 / eta, r2 = r1 * r1, r3 = r2 * r1;
    return -547.033 + 45.3087 * r3 - 218.725 * r2 + 458.843 * r1 + 404.557 * eta - 189.519 * e2 +
           54.9327 * e3 - 9.00603 * e4 + 0.63942 * e5;
}

/* The better dipole's exitance at distance r from a real source at depth zr (PBRT 15.5): the
 * fluence weighted by c_phi plus the normal flux weighted by c_e. */
typedef struct dipole {
    double D, sigma_tr, ze, c_phi, c_e;
} dipole;

static double dipole_exitance(const dipole *p, double r, double zr)
{
    double zv = -zr + 2.0 * p->ze;
    double dr = sqrt(r * r + zr * zr), dv = sqrt(r * r + zv * zv);
    double er = exp(-p->sigma_tr * dr), ev = exp(-p->sigma_tr * dv);
    double phi = (er / dr - ev / dv) / (4.0 * PPB_PI * p->D);
    double e_n = (zr * (1.0 + p->sigma_tr * dr) * er / (dr * dr * dr) -
                  zv * (1.0 + p->sigma_tr * dv) * ev / (dv * dv * dv)) /
                 (4.0 * PPB_PI);
    return phi * p->c_phi + e_n * p->c_e;
}

double ppb_pbd_ms(double sigma_s, double sigma_a, double g, double eta, double r, int samples)
{
    double sps = sigma_s * (1.0 - g), spt = sigma_a + sps, rhop = sps / spt;
    dipole p;
    p.D = (2.0 * sigma_a + sps) / (3.0 * spt * spt); /* Grosjean's D_g */
    p.sigma_tr = sqrt(fmax(0.0, sigma_a / p.D));
    double fm1 = ppb_pbd_fresnel_moment1(eta), fm2 = ppb_pbd_fresnel_moment2(eta);
    p.ze = -2.0 * p.D * (1.0 + 3.0 * fm2) / (1.0 - 2.0 * fm1);
    p.c_phi = 0.25 * (1.0 - 2.0 * fm1);
    p.c_e = 0.5 * (1.0 - 3.0 * fm2);
    double sum = 0.0;
    for (int i = 0; i < samples; i++) {
        /* The beam's reduced attenuation sigma_t' exp(-sigma_t' z) is the sampling density, so
         * each quantile's dipole counts with weight 1 / samples. */
        double zr = -log(1.0 - (i + 0.5) / samples) / spt;
        double dr = sqrt(r * r + zr * zr);
        double kappa = 1.0 - exp(-2.0 * spt * (dr + zr));
        sum += kappa * rhop * rhop * dipole_exitance(&p, r, zr);
    }
    return sum / samples;
}

/* Henyey-Greenstein at scattering cosine mu (the standard sign: mu = 1 forward). */
static double hg(double mu, double g)
{
    g = fmin(0.99, fmax(-0.99, g)); /* pbrt's clamp */
    double den = 1.0 + g * g - 2.0 * g * mu;
    return (1.0 - g * g) / (4.0 * PPB_PI * den * sqrt(den));
}

double ppb_pbd_ss(double sigma_s, double sigma_a, double g, double eta, double r, int samples)
{
    double sigma_t = sigma_a + sigma_s, rho = sigma_s / sigma_t;
    double t_crit = r * sqrt(fmax(0.0, eta * eta - 1.0));
    double sum = 0.0;
    for (int i = 0; i < samples; i++) {
        /* Depths past t_crit sampled by exp(-sigma_t (t - t_crit)): the beam's attenuation
         * exp(-sigma_t t) divided by the density leaves exp(-sigma_t t_crit). */
        double t = t_crit - log(1.0 - (i + 0.5) / samples) / sigma_t;
        double d = sqrt(r * r + t * t), cos_o = t / d;
        double f_out = eta > 1.0 ? ppb_fresnel(cos_o, 1.0 / eta) : 0.0;
        sum += rho * exp(-sigma_t * (d + t_crit)) / (d * d) * hg(-cos_o, g) * (1.0 - f_out) * cos_o;
    }
    return sum / samples;
}

/* The interval [nodes[i], nodes[i + 1]] holding x, i in [0, n - 2] (pbrt's FindInterval). */
static int find_interval(const double *nodes, int n, double x)
{
    int lo = 0, hi = n - 1; /* nodes[lo] <= x, and the answer is below hi */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (nodes[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    return lo > n - 2 ? n - 2 : lo;
}

int ppb_pbd_cr_weights(const double *nodes, int n, double x, int *offset, double w[4])
{
    if (!(x >= nodes[0] && x <= nodes[n - 1]))
        return 0;
    int i = find_interval(nodes, n, x);
    *offset = i - 1;
    double x0 = nodes[i], x1 = nodes[i + 1];
    double t = (x - x0) / (x1 - x0), t2 = t * t, t3 = t2 * t;
    w[1] = 2.0 * t3 - 3.0 * t2 + 1.0;
    w[2] = -2.0 * t3 + 3.0 * t2;
    /* The Hermite basis' slope terms, the slopes as finite differences over the neighbours
     * (one-sided at the ends), folded into the node weights. */
    double h0 = t3 - 2.0 * t2 + t, h1 = t3 - t2;
    if (i > 0) {
        double w0 = h0 * (x1 - x0) / (x1 - nodes[i - 1]);
        w[0] = -w0;
        w[2] += w0;
    } else {
        w[0] = 0.0;
        w[1] -= h0;
        w[2] += h0;
    }
    if (i + 2 < n) {
        double w3 = h1 * (x1 - x0) / (nodes[i + 2] - x0);
        w[1] -= w3;
        w[3] = w3;
    } else {
        w[1] -= h1;
        w[2] += h1;
        w[3] = 0.0;
    }
    return 1;
}

double ppb_pbd_cr_integral(const double *nodes, const double *f, int n)
{
    double sum = 0.0;
    for (int i = 0; i + 1 < n; i++) {
        double x0 = nodes[i], x1 = nodes[i + 1], f0 = f[i], f1 = f[i + 1], width = x1 - x0;
        double d0 = i > 0 ? width * (f1 - f[i - 1]) / (x1 - nodes[i - 1]) : f1 - f0;
        double d1 = i + 2 < n ? width * (f[i + 2] - f0) / (nodes[i + 2] - x0) : f1 - f0;
        sum += width * (0.5 * (f0 + f1) + (d0 - d1) / 12.0);
    }
    return sum;
}

void ppb_pbd_table_build(ppb_pbd_table *t, double g, double eta, int samples)
{
    t->g = g;
    t->eta = eta;
    t->radius[0] = 0.0;
    t->radius[1] = 2.5e-3;
    for (int j = 2; j < PPB_PBD_NR; j++)
        t->radius[j] = t->radius[j - 1] * 1.2;
    for (int i = 0; i < PPB_PBD_NRHO; i++)
        t->rho[i] = (1.0 - exp(-8.0 * i / (PPB_PBD_NRHO - 1.0))) / (1.0 - exp(-8.0));
    for (int i = 0; i < PPB_PBD_NRHO; i++) {
        double rho = t->rho[i], *row = &t->profile[i * PPB_PBD_NR];
        for (int j = 0; j < PPB_PBD_NR; j++) {
            double r = t->radius[j];
            /* sigma_t = 1: sigma_s = rho, sigma_a = 1 - rho. The factor 2 pi r makes the row a
             * density in r (pbrt's "marginal PDF factor", cancelled again by Sr). */
            row[j] = 2.0 * PPB_PI * r *
                     (ppb_pbd_ss(rho, 1.0 - rho, g, eta, r, samples) +
                      ppb_pbd_ms(rho, 1.0 - rho, g, eta, r, samples));
        }
        t->rho_eff[i] = ppb_pbd_cr_integral(t->radius, row, PPB_PBD_NR);
    }
}
