/* rte2d_beam.c: the direct beam's collision density over a rectangle, exactly (rte2d_beam.h).
 *
 * Every case of rte2d.cl's beam is a sum of terms w lit exp(-D') with, for each term, one entry
 * point x_e affine in (x, y): lit is lo <= x_e < hi, and D' (the term's optical depth) is affine
 * on either side of x_e = step_x (density step) and elsewhere affine throughout. A term is
 * integrated by clipping the rectangle to its lit strip, splitting it at x_e = step_x, fitting
 * the exponent's affine coefficients from the term's point formula at three points inside each
 * piece (so the point formula stays the one definition), and integrating exp(affine) over each
 * convex piece in closed form (poly_exp: chord lengths along the gradient). */
#include "methods/rte2d/rte2d_beam.h"

#include <math.h>

/* A convex polygon: the rectangle clipped by at most four lines. */
enum { POLY_MAX = 16 };
typedef struct beam_poly {
    int n;
    double x[POLY_MAX], y[POLY_MAX];
} beam_poly;

/* a + b x + c y */
typedef struct beam_affine {
    double a, b, c;
} beam_affine;

static double aff_at(beam_affine f, double x, double y)
{
    return f.a + f.b * x + f.c * y;
}

/* The kinds of a term's exponent (rte2d.cl's rte_ray_side). */
typedef enum { TERM_LIGHT, TERM_BACK, TERM_IMAGE } term_kind;

/* One term w lit exp(exponent): lit where lo <= x_e < hi (if has_lit), the exponent's formula
 * changing at x_e = step_x (if cut). */
typedef struct beam_term {
    term_kind kind;
    int cls, k, j; /* direction class; image tile (TERM_IMAGE) */
    double w;      /* weight: 1, e, e F_b or beam_in F_b^j F_s^k */
    beam_affine xe;
    int has_lit, cut;
    double lo, hi;
    double db; /* TERM_BACK: the column's D_b = sigma_t H / cos theta_t */
} beam_term;

/* ---- exp(affine) over a convex polygon ---- */

/* psi(z) = int_0^1 r e^{z r} dr and chi(z) = int_0^1 (1 - r) e^{z r} dr for z <= 0: both
 * positive, by their Taylor series (z^n / (n! (n + 2)), z^n / (n! (n + 1)(n + 2))) for |z| <= 1,
 * where the closed forms cancel, in closed form beyond (at most a factor 4 lost at z = -1). */
static void psi_chi(double z, double *psi, double *chi)
{
    if (z >= -1.0) {
        double t = 1.0, s = 0.0, c = 0.0; /* t = z^n / n! */
        for (int n = 0; n < 24; n++) {
            s += t / (n + 2);
            c += t / ((n + 1.0) * (n + 2));
            t *= z / (n + 1);
        }
        *psi = s;
        *chi = c;
        return;
    }
    double e = exp(z), phi1 = expm1(z) / z;
    *psi = (1.0 + e * (z - 1.0)) / (z * z);
    *chi = phi1 - *psi;
}

/* Chord length at u of a convex polygon given by its vertices' coordinates (u_i, v_i): the
 * extent in v of the polygon's points with that u (an edge lying along u = const included). */
static double chord_at(const double *u, const double *v, int n, double uq)
{
    double vmin = INFINITY, vmax = -INFINITY;
    for (int i = 0; i < n; i++) {
        int k = (i + 1) % n;
        if (u[i] == uq) {
            vmin = fmin(vmin, v[i]);
            vmax = fmax(vmax, v[i]);
        }
        if ((u[i] - uq) * (u[k] - uq) < 0.0) {
            double vq = v[i] + (v[k] - v[i]) * (uq - u[i]) / (u[k] - u[i]);
            vmin = fmin(vmin, vq);
            vmax = fmax(vmax, vq);
        }
    }
    return vmax > vmin ? vmax - vmin : 0.0;
}

/* int exp(a + b x + c y) dA over the convex polygon. With u along the gradient (b, c) the
 * exponent is g_0 + |grad| u and the chord length L(u) is piecewise linear between the vertices'
 * u: the integral is sum over those pieces of h int_0^1 e^{g(u)} L(u) ds, in closed form
 *   h e^{g_b} [L_a psi(z) + L_b chi(z)],  z = -|grad| h <= 0,
 * g_b the larger end's exponent. Both weights are positive, so nothing cancels, and a vanishing
 * gradient needs no fallback (z -> 0 is the trapezoid rule of L, exact for its linear pieces). */
double ppb_rte_poly_exp(const double *x, const double *y, int n, double a, double b, double c)
{
    double G = hypot(b, c), ux = G > 0.0 ? b / G : 1.0, uy = G > 0.0 ? c / G : 0.0;
    double u[POLY_MAX], v[POLY_MAX], us[POLY_MAX];
    if (n < 3 || n > POLY_MAX)
        return 0.0;
    for (int i = 0; i < n; i++) { /* relative to vertex 0: no cancellation of large coordinates */
        double dx = x[i] - x[0], dy = y[i] - y[0];
        u[i] = us[i] = ux * dx + uy * dy;
        v[i] = -uy * dx + ux * dy;
    }
    for (int i = 1; i < n; i++) /* insertion sort of the u's */
        for (int k = i; k > 0 && us[k] < us[k - 1]; k--) {
            double t = us[k];
            us[k] = us[k - 1];
            us[k - 1] = t;
        }
    double g0 = a + b * x[0] + c * y[0], sum = 0.0;
    double La = chord_at(u, v, n, us[0]);
    for (int i = 0; i + 1 < n; i++) {
        double h = us[i + 1] - us[i];
        if (!(h > 0.0))
            continue;
        double Lb = chord_at(u, v, n, us[i + 1]), psi, chi;
        psi_chi(-G * h, &psi, &chi);
        sum += h * exp(g0 + G * us[i + 1]) * (La * psi + Lb * chi);
        La = Lb;
    }
    return sum;
}

/* ---- pieces ---- */

/* The part of the convex polygon where f >= 0 (Sutherland-Hodgman, one line). */
static void poly_clip(const beam_poly *in, beam_affine f, beam_poly *out)
{
    out->n = 0;
    for (int i = 0; i < in->n; i++) {
        int k = (i + 1) % in->n;
        double fi = aff_at(f, in->x[i], in->y[i]), fk = aff_at(f, in->x[k], in->y[k]);
        if (fi >= 0.0 && out->n < POLY_MAX) {
            out->x[out->n] = in->x[i];
            out->y[out->n++] = in->y[i];
        }
        if (((fi >= 0.0) != (fk >= 0.0)) && out->n < POLY_MAX) {
            double t = fi / (fi - fk);
            out->x[out->n] = in->x[i] + t * (in->x[k] - in->x[i]);
            out->y[out->n++] = in->y[i] + t * (in->y[k] - in->y[i]);
        }
    }
}

/* Twice the signed area of triangle (i, j, k) of the polygon. */
static double tri2(const beam_poly *p, int i, int j, int k)
{
    return (p->x[j] - p->x[i]) * (p->y[k] - p->y[i]) - (p->x[k] - p->x[i]) * (p->y[j] - p->y[i]);
}

/* The term's exponent at a point: its point formula (rte2d.cl; ppb_beam_images.h). */
static double term_exponent(const ppb_rte_params *P, const beam_term *t, double x, double y);

/* The affine exponent of a piece: the point formula at three points halfway between the
 * vertex centroid and the vertices of the piece's largest fan triangle (inside the piece, off
 * its cut lines), solved for (a, b, c) about the centroid. Returns 0 for a degenerate piece. */
static int piece_affine(const ppb_rte_params *P, const beam_term *t, const beam_poly *p,
                        beam_affine *f)
{
    double cx = 0.0, cy = 0.0, best = 0.0;
    int i1 = 1, i2 = 2;
    for (int i = 0; i < p->n; i++)
        cx += p->x[i] / p->n, cy += p->y[i] / p->n;
    for (int i = 1; i + 1 < p->n; i++)
        for (int k = i + 1; k < p->n; k++)
            if (fabs(tri2(p, 0, i, k)) > best)
                best = fabs(tri2(p, 0, i, k)), i1 = i, i2 = k;
    if (!(best > 0.0))
        return 0;
    int id[3] = {0, i1, i2};
    double qx[3], qy[3], g[3];
    for (int m = 0; m < 3; m++) {
        qx[m] = 0.5 * (p->x[id[m]] - cx), qy[m] = 0.5 * (p->y[id[m]] - cy);
        g[m] = term_exponent(P, t, cx + qx[m], cy + qy[m]);
    }
    double ax = qx[1] - qx[0], ay = qy[1] - qy[0], bx = qx[2] - qx[0], by = qy[2] - qy[0];
    double det = ax * by - ay * bx, d1 = g[1] - g[0], d2 = g[2] - g[0];
    f->b = (d1 * by - d2 * ay) / det;
    f->c = (ax * d2 - bx * d1) / det;
    /* a about the origin: g at the centroid minus the gradient there */
    double gc = g[0] - f->b * qx[0] - f->c * qy[0];
    f->a = gc - f->b * cx - f->c * cy;
    return 1;
}

/* int exp(exponent) over one piece, the exponent affine on it. */
static double piece_integral(const ppb_rte_params *P, const beam_term *t, const beam_poly *p)
{
    beam_affine f;
    if (p->n < 3 || !piece_affine(P, t, p, &f))
        return 0.0;
    return ppb_rte_poly_exp(p->x, p->y, p->n, f.a, f.b, f.c);
}

/* int lit exp(exponent) over the rectangle: clipped to lo <= x_e <= hi, split at x_e = step_x. */
static double term_integral(const ppb_rte_params *P, const beam_term *t, const beam_poly *rect)
{
    beam_poly a = *rect, b;
    if (t->has_lit) {
        beam_affine lo = {t->xe.a - t->lo, t->xe.b, t->xe.c};
        beam_affine hi = {t->hi - t->xe.a, -t->xe.b, -t->xe.c};
        poly_clip(rect, lo, &b);
        poly_clip(&b, hi, &a);
    }
    if (a.n < 3)
        return 0.0;
    if (!t->cut)
        return piece_integral(P, t, &a);
    beam_affine left = {P->med.step_x - t->xe.a, -t->xe.b, -t->xe.c};
    beam_affine right = {t->xe.a - P->med.step_x, t->xe.b, t->xe.c};
    beam_poly l, r;
    poly_clip(&a, left, &l);
    poly_clip(&a, right, &r);
    return piece_integral(P, t, &l) + piece_integral(P, t, &r);
}

/* ---- the terms of each case ---- */

/* ppb_beam_images.h's ppb_image_right on the host (fmin, fmax for clamp): the measure of the
 * unfolded right medium [2mW + s, 2mW + W - s] on x' < x, up to a constant. */
static double image_right(double x, double s, double W)
{
    double len = W - 2.0 * s, m = floor((x - s) / (2.0 * W));
    return m * len + fmin(fmax(x - s - m * 2.0 * W, 0.0), len);
}

/* Image (k, j) of (x, y): x' = kW +- x, depth' = jH - y or (j + 1)H + y (ppb_beam_images.h). */
static void image_point(const ppb_rte_params *P, int k, int j, double x, double y, double *xp,
                        double *dp)
{
    *xp = k * P->med.width + ((k & 1) ? -x : x);
    *dp = (j & 1) ? (j + 1) * P->med.height + y : j * P->med.height - y;
}

/* Optical depth of image (k, j)'s beam to (x, y): sigma_t depth' / cos theta_t, through the
 * step's images with a density step (ppb_image_depth). */
static double image_depth(const ppb_rte_params *P, int k, int j, double x, double y)
{
    double xp, dp;
    image_point(P, k, j, x, y, &xp, &dp);
    if (P->med.step != PPB_STEP_DENSITY)
        return P->med.sigma_t * dp / P->cos_theta_l;
    double xe = xp - dp * P->tan_theta_l, s = P->med.step_x, W = P->med.width;
    return P->med.sigma_t * dp / P->cos_theta_l +
           (P->med.sigma_t_right - P->med.sigma_t) / P->sin_theta_l *
               (image_right(xp, s, W) - image_right(xe, s, W));
}

static double term_exponent(const ppb_rte_params *P, const beam_term *t, double x, double y)
{
    if (t->kind == TERM_IMAGE)
        return -image_depth(P, t->k, t->j, x, y);
    double D;
    int lit;
    ppb_rte_light(P, x, y, &D, &lit);
    return t->kind == TERM_BACK ? -(2.0 * t->db - D) : -D;
}

/* A term of ppb_rte_light's beam: x_e = x + y tan theta, lit on S1's lit part in the tube. */
static beam_term light_term(const ppb_rte_params *P, term_kind kind, int cls, double w)
{
    beam_term t = {.kind = kind, .cls = cls, .w = w, .xe = {0.0, 1.0, P->tan_theta_l}};
    t.has_lit = P->med.tube;
    t.cut = P->med.tube && P->med.step == PPB_STEP_DENSITY;
    t.lo = ppb_lit_lo(&P->med, &P->lit); /* S1's lit part (ppb_light.h) */
    t.hi = ppb_lit_hi(&P->med, &P->lit);
    return t;
}

/* Image tile (k, j): x_e = x' - depth' tan theta_t, affine in (x, y) (ppb_beam_images.h). */
static beam_term image_term(const ppb_rte_params *P, int k, int j, double w)
{
    double tn = P->tan_theta_l, d0 = (j & 1) ? (j + 1) * P->med.height : j * P->med.height;
    beam_term t = {.kind = TERM_IMAGE, .cls = 2 * (k & 1) + (j & 1), .k = k, .j = j, .w = w};
    t.xe.a = k * P->med.width - d0 * tn;
    t.xe.b = (k & 1) ? -1.0 : 1.0;
    t.xe.c = (j & 1) ? -tn : tn;
    t.has_lit = 1;
    t.cut = P->med.step == PPB_STEP_DENSITY;
    t.lo = ppb_lit_lo(&P->med, &P->lit); /* S1's lit part (ppb_light.h) */
    t.hi = ppb_lit_hi(&P->med, &P->lit);
    return t;
}

/* The depth tiles j to sum: image j + 2 is image j's beam after one more round trip S2 -> S1
 * (F_b^2, at least 2 sigma_min H / cos theta_t more), so with q = F_b e^{-sigma_min H / cos}
 * the images beyond J with q^J < 1e-17 (plus a margin of 4 for the first lit tiles) count for
 * less than 1e-17 of the first ones. */
static int image_jmax(const ppb_rte_params *P)
{
    double smin = ppb_medium_sigma_min(&P->med);
    double q = P->beam_fb * exp(-smin * P->med.height / P->cos_theta_l);
    if (!(q > 0.0))
        return 4;
    double J = log(1e-17) / log(q);
    return J > 1e5 ? 100000 : (int)ceil(J) + 4;
}

/* n > 1, the tube at oblique incidence: every image tile whose entry interval can reach the
 * cross-section (the k bounds of ppb_beam_images). */
static void sum_images(const ppb_rte_params *P, double sigma_t, const beam_poly *rect,
                       double out[PPB_BEAM_CLASSES])
{
    double W = P->med.width, H = P->med.height, tn = P->tan_theta_l;
    if (!(ppb_lit_hi(&P->med, &P->lit) > ppb_lit_lo(&P->med, &P->lit)))
        return;
    int jmax = image_jmax(P);
    double fj = 1.0;
    for (int j = 0; j <= jmax; j++, fj *= P->beam_fb) {
        int kmin = (int)ceil((j * H * tn - W) / W), kmax = (int)floor(1.0 + (j + 1) * H * tn / W);
        kmin = kmin < 0 ? 0 : kmin;
        double fk = pow(P->beam_fs, kmin);
        for (int k = kmin; k <= kmax; k++, fk *= P->beam_fs) {
            beam_term t = image_term(P, k, j, P->beam_in * fj * fk);
            if (t.w > 0.0)
                out[t.cls] += t.w * sigma_t * term_integral(P, &t, rect);
        }
    }
}

void ppb_rte_beam_rect(const ppb_rte_params *P, double x0, double x1, double y0, double y1,
                       double out[PPB_BEAM_CLASSES])
{
    for (int k = 0; k < PPB_BEAM_CLASSES; k++)
        out[k] = 0.0;
    if (!P->med.tube) /* slab: per unit width */
        x0 = 0.0, x1 = 1.0;
    beam_poly rect = {4, {x0, x1, x1, x0}, {y0, y0, y1, y1}};
    double xm = 0.5 * (x0 + x1);
    double sigma_t = ppb_medium_sigma_t(&P->med, xm);
    if (!(sigma_t > 0.0))
        return;
    if (P->med.n <= 1.0) {
        beam_term t = light_term(P, TERM_LIGHT, PPB_BEAM_PLUS_DOWN, 1.0);
        out[0] = sigma_t * term_integral(P, &t, &rect);
        return;
    }
    if (ppb_rte_beam_images(P)) {
        sum_images(P, sigma_t, &rect, out);
        return;
    }
    /* The refracted beam and its reflection off S2, every round trip summed (rte2d.cl). */
    double db = sigma_t * P->med.height / P->cos_theta_l;
    double e = P->beam_in / (1.0 - P->beam_fb * P->beam_fb * exp(-2.0 * db));
    beam_term down = light_term(P, TERM_LIGHT, PPB_BEAM_PLUS_DOWN, e);
    beam_term up = light_term(P, TERM_BACK, PPB_BEAM_PLUS_UP, e * P->beam_fb);
    up.db = db;
    out[0] = e * sigma_t * term_integral(P, &down, &rect);
    out[1] = up.w * sigma_t * term_integral(P, &up, &rect);
}
