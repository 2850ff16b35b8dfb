/* diffuse_exit.c: the refractive boundary's shared terms (diffuse_exit.h), moved here from the
 * `mp` slice unchanged so that `burley` uses the same exit lobe and ballistic total. */
#include "physics/diffuse_exit.h"

#include <math.h>

#include "base/quadrature.h"
#include "kernels/ppb_fresnel.h"
#include "physics/maps.h"

/* 2 int_a^b (1 - F(mu, n)) mu dmu for light from air (n_rel = n >= 1), where F is analytic in
 * mu on [0, 1] (cos_t >= sqrt(1 - 1/n^2) > 0): `panels` panels of 16-point Gauss-Legendre. */
static double transmitted_moment(double n, double a, double b, int panels)
{
    double x[16], w[16], sum = 0, half = 0.5 * (b - a) / panels;
    ppb_gauss_legendre(16, x, w);
    for (int p = 0; p < panels; p++) {
        double mid = a + (2 * p + 1) * half;
        for (int j = 0; j < 16; j++) {
            double mu = mid + half * x[j];
            sum += w[j] * (1.0 - ppb_fresnel(mu, n)) * mu;
        }
    }
    return 2.0 * half * sum;
}

double ppb_diffuse_fresnel(double n_rel)
{
    if (n_rel == 1.0)
        return 0.0;
    if (n_rel > 1.0)
        return 1.0 - transmitted_moment(n_rel, 0.0, 1.0, 8);
    double n = 1.0 / n_rel; /* from inside: Prahl 1988 Eq. B.14 (diffuse_exit.h) */
    return 1.0 - transmitted_moment(n, 0.0, 1.0, 8) / (n * n);
}

void ppb_diffuse_exit_lobe(double n, int ntheta, double *lobe)
{
    double mean = 1.0 - ppb_diffuse_fresnel(n); /* 1 - F_dr,e */
    for (int k = 0; k < ntheta; k++) {
        /* Bin k spans sin^2 in [k, k + 1] / ntheta, i.e. mu_o from sqrt(1 - (k + 1) / ntheta)
         * to sqrt(1 - k / ntheta); d(sin^2) = 2 mu dmu, so the bin mean is ntheta times the
         * transmitted moment over that mu range. */
        double lo = sqrt(fmax(0.0, 1.0 - (double)(k + 1) / ntheta));
        double hi = sqrt(1.0 - (double)k / ntheta);
        lobe[k] = ntheta * transmitted_moment(n, lo, hi, 1) / mean;
    }
}

typedef struct beam_dir {
    double n, sin_t, cos_t;
} beam_dir;

/* Fraction of the power entering at x_e on S1 that leaves the tube unscattered: the refracted
 * beam runs to a face, leaves with 1 - F(cos_i, 1/n) and reflects specularly with F (TIR: all),
 * until less than 1e-16 of it is left (a corner hit reflects both components). */
static double beam_left(const ppb_scene *sc, double xe, void *arg)
{
    const beam_dir *b = arg;
    double hw = 0.5 * sc->width, depth = sc->height;
    double x = xe, y = 0.0, dx = b->sin_t, dy = -b->cos_t, w = 1.0, left = 0.0;
    for (int hit = 0; hit < 1000000 && w > 1e-16; hit++) {
        double tx = dx > 0 ? (hw - x) / dx : (dx < 0 ? (-hw - x) / dx : INFINITY);
        double ty = dy > 0 ? -y / dy : (dy < 0 ? (-depth - y) / dy : INFINITY);
        int wall_x = tx <= ty, wall_y = ty <= tx;
        double t = fmin(tx, ty);
        double x1 = wall_x ? (dx > 0 ? hw : -hw) : x + t * dx;
        double y1 = wall_y ? (dy > 0 ? 0.0 : -depth) : y + t * dy;
        w *= exp(-ppb_segment_optical_depth(sc, x, y, x1, y1));
        double f = ppb_fresnel(wall_y ? fabs(dy) : fabs(dx), 1.0 / b->n);
        left += w * (1.0 - f);
        w *= f;
        if (wall_x)
            dx = -dx;
        if (wall_y)
            dy = -dy;
        x = x1;
        y = y1;
    }
    return left;
}

/* diffuse_exit.h. Slab: with e = exp(-tau0 / cos theta_t) and F_b = F(cos theta_t, 1/n) at
 * both faces, the bounces sum to (1 - F_b) e / (1 - F_b e). Tube: beam_left averaged over the
 * lit entry points (ppb_lit_integral's Gauss-Legendre panels). Where every side hit is total
 * internal reflection (sin theta_t below the critical cosine: theta_L < 78.5 deg at n = 1.4)
 * the mirrored path is the slab's and the integrand is the slab's constant; otherwise the
 * panels' breaks, those of the unreflected path, miss the kinks that side exits add. */
double ppb_ballistic_refracted(const ppb_scene *sc)
{
    if (!(sc->n > 1.0))
        return ppb_ballistic_fraction(sc);
    double entry = 1.0 - ppb_fresnel(ppb_scene_cos_theta_l(sc), sc->n);
    beam_dir b = {sc->n, 0.0, ppb_refract_cos(ppb_scene_cos_theta_l(sc), sc->n)};
    b.sin_t = sqrt(fmax(0.0, 1.0 - b.cos_t * b.cos_t));
    if (sc->geometry == PPB_GEOM_SLAB) {
        double e = exp(-sc->sigma_t * sc->height / b.cos_t), fb = ppb_fresnel(b.cos_t, 1.0 / sc->n);
        return entry * (1.0 - fb) * e / (1.0 - fb * e);
    }
    double width, sum = ppb_lit_integral(sc, beam_left, &b, &width);
    return width > 0.0 ? entry * sum / width : 0.0;
}
