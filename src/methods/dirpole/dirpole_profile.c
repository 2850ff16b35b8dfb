/* dirpole_profile.c: the directional dipole and its integrals (dirpole_profile.h). Equation
 * numbers are Frisvad, Hachisuka & Kjeldsen 2014's. */
#include "methods/dirpole/dirpole_profile.h"

#include <math.h>

#include "base/quadrature.h"
#include "kernels/ppb_conventions.h"

double ppb_dirpole_c1(double eta)
{
    if (eta == 1.0)
        return 0.0;
    double r =
        eta > 1.0
            ? -9.23372 +
                  eta * (22.2272 +
                         eta * (-20.9292 + eta * (10.2291 + eta * (-2.54396 + 0.254913 * eta))))
            : 0.919317 +
                  eta * (-3.4793 +
                         eta * (6.75335 + eta * (-7.80989 + eta * (4.98554 - 1.36881 * eta))));
    return 0.5 * r; /* the fit is of 2 C1 */
}

double ppb_dirpole_c2(double eta)
{
    if (eta == 1.0)
        return 0.0;
    double r =
        -1641.1 +
        eta * (1213.67 + eta * (-568.556 + eta * (164.798 + eta * (-27.0181 + 1.91826 * eta))));
    r += ((135.926 / eta - 656.175) / eta + 1376.53) / eta;
    return r / 3.0; /* the fit is of 3 C2 */
}

void ppb_dirpole_init(ppb_dirpole *p, double sigma_t, double albedo, double g, double n,
                      const double w12[3])
{
    double sigma_s = albedo * sigma_t, sigma_a = sigma_t - sigma_s;
    double sigma_s_r = sigma_s * (1.0 - g), sigma_t_r = sigma_a + sigma_s_r;
    double alpha_r = sigma_s_r / sigma_t_r;
    p->none = !(alpha_r > 0.0);
    p->sigma_t = sigma_t;
    p->D = 1.0 / (3.0 * sigma_t_r);
    p->sigma_tr = sqrt(sigma_a / p->D);
    p->de = p->none ? 0.0 : 2.131 * p->D / sqrt(alpha_r);
    double eta = n > 1.0 ? n : 1.0; /* n <= 1: no boundary (model/scene.h) */
    p->c_phi = 0.25 * (1.0 - 2.0 * ppb_dirpole_c1(eta));
    p->c_e = 0.5 * (1.0 - 3.0 * ppb_dirpole_c2(eta));
    p->A = (1.0 - p->c_e) / (2.0 * p->c_phi);
    for (int k = 0; k < 3; k++)
        p->w[k] = w12[k];
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* One ray source's term of Eq. 19 (S'_d) times 4 pi C_phi(1/eta): the diffusive fluence and
 * flux of a ray source along w at x (to the exit point), at the source distance r, leaving
 * through the exit normal no: C_phi phi - C_E (the flux's normal part). */
static double source(const ppb_dirpole *p, const double *x, const double *w, double r,
                     const double *no)
{
    double sr = p->sigma_tr * r, s1 = 1.0 + sr, r2 = r * r, xw = dot3(x, w);
    double fluence = r2 / p->D + 3.0 * s1 * xw;
    double flux = 3.0 * p->D * s1 * dot3(w, no) -
                  (s1 + 3.0 * p->D * (3.0 * s1 + sr * sr) / r2 * xw) * dot3(x, no);
    return exp(-sr) / (4.0 * PPB_PI * r * r2) * (p->c_phi * fluence - p->c_e * flux);
}

/* The modified tangent plane's normal n_i* = x^ x (n_i x x^) / |n_i x x^|, which is n_i less its
 * part along x^, normalised; n_i where x is along n_i or 0 (x_o = x_i). */
static void modified_normal(const double *x, const double *ni, double *ns)
{
    double r2 = dot3(x, x), xn = dot3(x, ni);
    double len2 = 1.0 - (r2 > 0.0 ? xn * xn / r2 : 0.0);
    if (!(len2 > 1e-24)) {
        ns[0] = ni[0], ns[1] = ni[1], ns[2] = ni[2];
        return;
    }
    double s = 1.0 / sqrt(len2);
    for (int k = 0; k < 3; k++)
        ns[k] = (ni[k] - (r2 > 0.0 ? x[k] * xn / r2 : 0.0)) * s;
}

/* The real source's distance d_r (the paper's corrected distance, Sec. 4): with
 * mu0 = -n_o . w_12 > 0, d_r^2 = r^2 + D mu0 (D mu0 - 2 d_e cos beta),
 * cos beta = -sqrt((r^2 - (x . w_12)^2) / (r^2 + d_e^2)); otherwise d_r^2 = r^2 + 1/(3 sigma_t)^2.
 */
static double real_distance(const ppb_dirpole *p, const double *x, const double *no)
{
    double r2 = dot3(x, x), xw = dot3(x, p->w), mu0 = -dot3(no, p->w);
    if (mu0 > 0.0) {
        double cos_beta = -sqrt(fmax(0.0, r2 - xw * xw) / (r2 + p->de * p->de));
        return sqrt(r2 + p->D * mu0 * (p->D * mu0 - 2.0 * p->de * cos_beta));
    }
    double o = 1.0 / (3.0 * p->sigma_t);
    return sqrt(r2 + o * o);
}

double ppb_dirpole_exitance(const ppb_dirpole *p, const double x[3], const double ni[3],
                            const double no[3])
{
    if (p->none)
        return 0.0;
    double ns[3], xv[3], wv[3];
    modified_normal(x, ni, ns);
    double wn = dot3(p->w, ns);
    for (int k = 0; k < 3; k++) {
        xv[k] = x[k] - 2.0 * p->A * p->de * ns[k]; /* x_o - x_v, x_v = x_i + 2 A d_e n_i* */
        wv[k] = p->w[k] - 2.0 * wn * ns[k];        /* w_v: w_12 mirrored in the plane */
    }
    double s =
        source(p, x, p->w, real_distance(p, x, no), no) - source(p, xv, wv, sqrt(dot3(xv, xv)), no);
    return s > 0.0 ? s : 0.0;
}

#define REACH 40.0 /* sigma_tr r beyond which e^(-sigma_tr r) < 5e-18 */
#define GL_Z  8
#define GL_X  10
/* Where the strip holds u = 0, its panels halve down to 1e-2 of the usual stop: the line
 * integral is not smooth there. */
#define STOP_KINK 1e-2

/* The decay rate that sets where the integrals stop: sigma_tr, or 1e-4 / D where nothing is
 * absorbed (the real and virtual sources' difference then falls like r^-3, and the plane
 * beyond 4e5 D holds below 1e-5 of the integral). */
static double cut_rate(const ppb_dirpole *p)
{
    return fmax(p->sigma_tr, 1e-4 / p->D);
}

/* The sources' smallest offset from the exit point at r = 0: the real one's (D mu0 or
 * 1/(3 sigma_t)) and the virtual one's (2 A d_e), at least 1e-3 D (a beam at grazing
 * refraction, mu0 -> 0). */
static double offset(const ppb_dirpole *p, const double *no)
{
    double mu0 = -dot3(no, p->w);
    double real = mu0 > 0.0 ? p->D * mu0 : 1.0 / (3.0 * p->sigma_t);
    return fmax(1e-3 * p->D, fmin(real, 2.0 * p->A * p->de));
}

double ppb_dirpole_line(const ppb_dirpole *p, double u, double v, const double no[3], int samples)
{
    if (p->none)
        return 0.0;
    double reach = REACH / cut_rate(p), rho2 = u * u + v * v;
    if (rho2 >= reach * reach)
        return 0.0;
    double l = offset(p, no), q = sqrt(rho2 + l * l);
    /* The integrand is not smooth in (u, z) at u = z = 0 (d_r holds r, not r^2: a cone; n_i*
     * turns over where x_o lies near the normal line of x_i): resolve |z| ~ |u| too. */
    q = fmin(q, fmax(fabs(u), 1e-9 * q));
    double tmax = asinh(sqrt(reach * reach - rho2) / q);
    samples = samples < 1 ? 1 : samples;
    int panels = (int)ceil(tmax * samples / GL_Z);
    panels = panels < 1 ? 1 : panels;
    double xg[GL_Z], wg[GL_Z], h = tmax / panels, sum = 0.0;
    ppb_gauss_legendre(GL_Z, xg, wg);
    const double ni[3] = {0.0, 1.0, 0.0};
    for (int k = 0; k < panels; k++) {
        double mid = (k + 0.5) * h;
        for (int j = 0; j < GL_Z; j++) {
            double t = mid + 0.5 * h * xg[j];
            double x[3] = {u, v, q * sinh(t)};
            sum += wg[j] * ppb_dirpole_exitance(p, x, ni, no) * q * cosh(t);
        }
    }
    return 2.0 * 0.5 * h * sum; /* both halves of the z axis (the integrand is even in z) */
}

typedef struct strip_ctx {
    const ppb_dirpole *p;
    const double *no;
    double v, l, hmax, reach;
    int samples;
    double xg[GL_X], wg[GL_X];
} strip_ctx;

/* 10-point Gauss-Legendre of line(u) over u = a + dir s, s in [lo, hi]. */
static double panel(const strip_ctx *c, double a, double dir, double lo, double hi)
{
    double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo), sum = 0.0;
    for (int j = 0; j < GL_X; j++)
        sum += c->wg[j] *
               ppb_dirpole_line(c->p, a + dir * (mid + half * c->xg[j]), c->v, c->no, c->samples);
    return half * sum;
}

/* int over u from a to b (either order) of line(u), graded toward a, the end nearest the
 * exit point. */
static double from_near(const strip_ctx *c, double a, double b)
{
    double dir = b >= a ? 1.0 : -1.0, len = fabs(b - a);
    double near = sqrt(a * a + c->v * c->v);
    if (near > c->reach || !(len > 0.0))
        return 0.0;
    double span = fmin(len, c->hmax), sum = 0.0, hi = span;
    double stop = 0.25 * sqrt(near * near + c->l * c->l);
    if (a == 0.0) /* the line's singularity at u = 0 (the cone, n_i* turning) */
        stop *= STOP_KINK;
    while (hi > stop) { /* [hi/2, hi] lies hi/2 or more from a: 10 nodes converge fast */
        sum += panel(c, a, dir, 0.5 * hi, hi);
        hi *= 0.5;
    }
    sum += panel(c, a, dir, 0.0, hi);
    for (double lo = span; lo < len; lo += c->hmax) {
        double u = a + dir * lo;
        if (sqrt(u * u + c->v * c->v) > c->reach)
            break;
        sum += panel(c, a, dir, lo, fmin(len, lo + c->hmax));
    }
    return sum;
}

double ppb_dirpole_strip(const ppb_dirpole *p, double ua, double ub, double v, const double no[3],
                         int samples)
{
    if (!(ub > ua) || p->none)
        return 0.0;
    strip_ctx c = {.p = p, .no = no, .v = v, .l = offset(p, no), .samples = samples};
    samples = samples < 1 ? 1 : samples;
    c.hmax = (double)GL_X / (samples * cut_rate(p));
    c.reach = REACH / cut_rate(p);
    ppb_gauss_legendre(GL_X, c.xg, c.wg);
    if (ua >= 0.0)
        return from_near(&c, ua, ub);
    if (ub <= 0.0)
        return from_near(&c, ub, ua);
    return from_near(&c, 0.0, ua) + from_near(&c, 0.0, ub);
}
