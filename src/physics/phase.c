/* phase.c: HG and truncated-series cell-pair and point-cell integrals by product Gauss
 * (phase.h). */
#include "physics/phase.h"
#include "physics/phase_rings.h"

#include "kernels/ppb_conventions.h"

#include "base/progress.h"
#include "base/quadrature.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#define PHASE_TOL 1e-8 /* target relative quadrature error of one pair */

double pp_hg(double g, double cos_theta)
{
    return ppb_hg_phase(g, cos_theta);
}

/* Gauss order per axis for a cell of corner radius h whose nearest point lies theta_min from
 * the HG peak: Gauss-Legendre converges like rho^(-2q), rho the Bernstein ellipse parameter
 * fixed by the distance d = sqrt(D / |g|) of the nearest complex singularity. */
static double gauss_order_wanted(double g, double cos_theta_min, double h)
{
    double ag = fabs(g);
    if (ag < 1e-14)
        return 1; /* isotropic: p is constant */
    double den = ppb_hg_base(ag, cos_theta_min);
    double ratio = sqrt(den / ag) / h;
    double rho = ratio + sqrt(ratio * ratio + 1.0);
    return ceil(log(1.0 / PHASE_TOL) / (2.0 * log(rho)));
}

static int gauss_order(double g, double cos_theta_min, double h)
{
    double q = gauss_order_wanted(g, cos_theta_min, h);
    return q < 2 ? 2 : (q > PP_QMAX ? PP_QMAX : (int)q);
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Angle between a and the peak seen from b: the forward direction for g >= 0, the backward one
 * for g < 0, where p peaks at cos = -1. */
static double peak_angle(double g, const double *a, const double *b)
{
    double c = dot3(a, b) * (g < 0 ? -1.0 : 1.0);
    return acos(c > 1.0 ? 1.0 : (c < -1.0 ? -1.0 : c));
}

/* Sum over node pairs of w_a w_b p(x_a . x_b), p in the shared factored form (ppb_conventions.h:
 * p = ppb_hg_norm(g) / base^(3/2), base = ppb_hg_base(g, cos) = (1 + g^2) - 2g cos), with the
 * normalisation taken out of the sum and base's two terms split so that the 2g scaling of the
 * inner cell's nodes leaves the inner loop: the nodes are copied into columns scaled by 2g
 * (padded to an even count with a zero-weight node) and the loop runs two nodes at a time with
 * SSE2; a scalar loop does the same elsewhere. It is the hot loop of the phase matrix, which is
 * why it does not call ppb_hg_phase per pair. */
static double pair_sum(double g, const double *na, const double *nb, int nq)
{
    enum { CAP = PP_QMAX * PP_QMAX + 2 };
    double y0[CAP], y1[CAP], y2[CAP], yw[CAP];
    /* g2 = base at cos = 0, i.e. 1 + g^2, exactly */
    double c1 = ppb_hg_norm(g), g2 = ppb_hg_base(g, 0.0), tg = 2.0 * g, sum = 0.0;
    int np = nq + (nq & 1);
    for (int b = 0; b < np; b++) {
        const double *y = nb + 4 * (b < nq ? b : 0);
        y0[b] = tg * y[0], y1[b] = tg * y[1], y2[b] = tg * y[2], yw[b] = b < nq ? y[3] : 0.0;
    }
    for (int a = 0; a < nq; a++) {
        const double *x = na + 4 * a;
        double inner = 0.0;
#ifdef __SSE2__
        __m128d x0 = _mm_set1_pd(x[0]), x1 = _mm_set1_pd(x[1]), x2 = _mm_set1_pd(x[2]);
        __m128d base = _mm_set1_pd(g2), acc = _mm_setzero_pd();
        for (int b = 0; b < np; b += 2) {
            __m128d dot = _mm_add_pd(_mm_add_pd(_mm_mul_pd(x0, _mm_loadu_pd(y0 + b)),
                                                _mm_mul_pd(x1, _mm_loadu_pd(y1 + b))),
                                     _mm_mul_pd(x2, _mm_loadu_pd(y2 + b)));
            __m128d den = _mm_sub_pd(base, dot);
            acc = _mm_add_pd(acc,
                             _mm_div_pd(_mm_loadu_pd(yw + b), _mm_mul_pd(den, _mm_sqrt_pd(den))));
        }
        double lanes[2];
        _mm_storeu_pd(lanes, acc);
        inner = lanes[0] + lanes[1];
#else
        for (int b = 0; b < np; b++) {
            double den = g2 - (x[0] * y0[b] + x[1] * y1[b] + x[2] * y2[b]);
            inner += yw[b] / (den * sqrt(den));
        }
#endif
        sum += x[3] * inner;
    }
    return c1 * sum;
}

/* The series' terms (2l + 1) chi_l / (4 pi), l < L. */
static void series_coeffs(const pp_phase_fn *ph, double *c)
{
    for (int l = 0; l < ph->nmom; l++)
        c[l] = (2.0 * l + 1.0) * ph->chi[l] / (4.0 * PPB_PI);
}

/* sum_{l < L} c_l P_l(x) by the upward three-term recurrence of P_l (stable on [-1, 1]). */
static double series_sum(const double *c, int L, double x)
{
    double p0 = 1.0, p1 = x, sum = c[0] + (L > 1 ? c[1] * x : 0.0);
    for (int l = 1; l + 1 < L; l++) {
        double p2 = ((2.0 * l + 1.0) * x * p1 - l * p0) / (l + 1.0);
        sum += c[l + 1] * p2;
        p0 = p1, p1 = p2;
    }
    return sum;
}

double pp_phase_eval(const pp_phase_fn *ph, double cos_theta)
{
    if (ph->nmom == 0)
        return pp_hg(ph->g, cos_theta);
    double c[PP_SERIES_MAX];
    series_coeffs(ph, c);
    return series_sum(c, ph->nmom, cos_theta);
}

/* Gauss order per axis for the series over cells of half-length h: along an axis it is a
 * trigonometric polynomial of degree L - 1 (L with the sin(theta) weight), and Gauss-Legendre
 * on [-h, h] integrates e^{i L t} to about (e L h / 4q)^{2q}; the least q with that under
 * PHASE_TOL, at least 2, at most PP_QMAX (6 at L = 16 on 128 cells, where the ring sums of
 * tests/test_phase_series.c agree with the addition theorem within 1e-12 sr^2). */
static int series_order(int L, double h)
{
    for (int q = 2; q < PP_QMAX; q++)
        if (2.0 * q * log(exp(1.0) * L * h / (4.0 * q)) < log(PHASE_TOL))
            return q;
    return PP_QMAX;
}

/* Sum over node pairs of w_a w_b p(x_a . x_b) for the series with terms c. */
static double series_pair_sum(const double *c, int L, const double *na, const double *nb, int nq)
{
    double sum = 0.0;
    for (int a = 0; a < nq; a++) {
        const double *x = na + 4 * a;
        double inner = 0.0;
        for (int b = 0; b < nq; b++) {
            const double *y = nb + 4 * b;
            inner += y[3] * series_sum(c, L, dot3(x, y));
        }
        sum += x[3] * inner;
    }
    return sum;
}

static double cell_radius(const pp_dirs *d, int cell)
{
    return d->radius[cell % d->n];
}
static double cell_half(const pp_dirs *d, int cell)
{
    return d->half[cell % d->n];
}

/* Cosine of the angle between the peak seen from a and the nearest point of the cell pair:
 * cos(max(0, peak_angle - R)), R = the sum of the two corner radii, from the radii's cosines
 * and sines (no inverse trigonometry in the pair loop). */
static double cos_gap(double g, const double *a, const double *b, double cos_r, double sin_r)
{
    double c = dot3(a, b) * (g < 0 ? -1.0 : 1.0);
    c = c > 1.0 ? 1.0 : (c < -1.0 ? -1.0 : c);
    if (sin_r < 0.0 || c >= cos_r) /* R >= pi, or the peak within R of the pair */
        return 1.0;
    return c * cos_r + sqrt(1.0 - c * c) * sin_r;
}

static int ring_count(const pp_dirs *d, int r)
{
    return d->ring_first[r + 1] - d->ring_first[r];
}

/* Gauss order cell a's azimuth rule needs against cell b when a's sector is wide (the polar
 * ring, narrow collars): there the arc-length estimate of gauss_order fails, because along a
 * small circle the singularity of p lies acosh(X) away in phi, X = (C - mu_a mu_b) / (s_a s_b),
 * C = (1 + g^2) / (2|g|), however far the peak. Taken at a's widest circle and at cb, the other
 * cell's centre or the point of a row; 0 where not needed. */
#define AZ_WIDE 0.1 /* sector half-widths (radians of phi) checked */
static int azimuth_order(const pp_dirs *d, double g, int a, const double *cb)
{
    int ua = a % d->n, r = d->ring[ua];
    double H = 0.5 * (d->phi_hi[ua] - d->phi_lo[ua]);
    if (H < AZ_WIDE || fabs(g) < 1e-14)
        return 0;
    double mu_a = (a < d->n ? 1.0 : -1.0) * d->mu_edge[r + 1], s_a = sqrt(1.0 - mu_a * mu_a);
    double s_b = sqrt(cb[0] * cb[0] + cb[2] * cb[2]), C = (1.0 + g * g) / (2.0 * fabs(g));
    double X = (C - (g < 0 ? -1.0 : 1.0) * mu_a * cb[1]) / (s_a * s_b);
    if (!(X > 1.0) || !(X < 1e300))
        return 0;
    double y = log(X + sqrt(X * X - 1.0)), q;
    if (ring_count(d, r) == 1) { /* the cap's periodic trapezoid: error about 2 exp(-q y) */
        q = ceil(log(2.0 / PHASE_TOL) / y);
    } else {
        double ratio = y / H, rho = ratio + sqrt(ratio * ratio + 1.0);
        q = ceil(log(1.0 / PHASE_TOL) / (2.0 * log(rho)));
    }
    return q > PP_QMAX ? PP_QMAX : (int)q;
}

/* S between cells a and b (any hemispheres), a != b; cr, sr: cosines and sines of the up
 * cells' corner radii (HG only). */
static int pair_integral(pp_dirs *d, const pp_phase_fn *ph, int a, int b, const double *cr,
                         const double *sr, double *out, ppb_err *err)
{
    int ua = a % d->n, ub = b % d->n;
    if (ph->nmom > 0) {
        int q = series_order(ph->nmom, fmax(cell_half(d, a), cell_half(d, b)));
        const double *na = pp_dirs_nodes(d, a, q, err), *nb = pp_dirs_nodes(d, b, q, err);
        if (!na || !nb)
            return -1;
        double c[PP_SERIES_MAX];
        series_coeffs(ph, c);
        *out = series_pair_sum(c, ph->nmom, na, nb, q * q);
        return 0;
    }
    double g = ph->g;
    if (d->polar) { /* long, thin cells: phase_rings.h */
        *out = pp_phase_pair_rings(d, g, a, b);
        return 0;
    }
    double cos_r = cr[ua] * cr[ub] - sr[ua] * sr[ub], sin_r = sr[ua] * cr[ub] + cr[ua] * sr[ub];
    double cmin = cos_gap(g, d->centre + 3 * a, d->centre + 3 * b, cos_r, sin_r);
    int q = gauss_order(g, cmin, fmax(cell_half(d, a), cell_half(d, b)));
    int qa = azimuth_order(d, g, a, d->centre + 3 * b),
        qb = azimuth_order(d, g, b, d->centre + 3 * a);
    q = q > qa ? q : qa;
    q = q > qb ? q : qb;
    const double *na = pp_dirs_nodes(d, a, q, err), *nb = pp_dirs_nodes(d, b, q, err);
    if (!na || !nb)
        return -1;
    *out = pair_sum(g, na, nb, q * q);
    return 0;
}

static int check_series(const pp_phase_fn *ph, ppb_err *err)
{
    if (ph->nmom < 1 || ph->nmom > PP_SERIES_MAX)
        return ppb_fail(err, "phase series: %d moments, need 1 .. %d", ph->nmom, PP_SERIES_MAX);
    for (int l = 0; l < ph->nmom; l++)
        if (!(fabs(ph->chi[l]) <= 1.0))
            return ppb_fail(err, "phase series: moment %d = %g, need |chi| <= 1", l, ph->chi[l]);
    if (ph->chi[0] != 1.0)
        return ppb_fail(err, "phase series: chi_0 = %g, need 1", ph->chi[0]);
    return 0;
}

static int check_g(double g, ppb_err *err)
{
    if (!(fabs(g) < 1.0))
        return ppb_fail(err, "HG phase function: g = %g, need |g| < 1", g);
    return 0;
}

/* Sets S(i, j) in a symmetric block and its images under the transpose and the z mirror zm. */
static void set_sym(size_t n, const int *zm, double *S, int i, int j, double v)
{
    int mi = zm[i], mj = zm[j];
    S[i * n + j] = S[j * n + i] = S[mi * n + mj] = S[mj * n + mi] = v;
}

static int gcd(int a, int b)
{
    while (b) {
        int t = a % b;
        a = b, b = t;
    }
    return a;
}

/* Up cell i turned by `steps` sectors of its ring (a one-cell ring stays). */
static int turn(const pp_dirs *d, int i, int steps)
{
    int r = d->ring[i], count = ring_count(d, r);
    return d->ring_first[r] + (i - d->ring_first[r] + steps) % count;
}

/* The azimuthal symmetry of the pair of rings holding up cells i and j: turning both cells by
 * 2 pi / G maps the pair onto another with the same integrals. G = gcd of the sector counts,
 * or the other ring's count when one ring is a single (rotation invariant) cap. The steps are
 * in sectors of each ring. */
static int ring_pair_symmetry(const pp_dirs *d, int i, int j, int *si, int *sj)
{
    int ni = ring_count(d, d->ring[i]), nj = ring_count(d, d->ring[j]);
    int G = ni == 1 ? nj : (nj == 1 ? ni : gcd(ni, nj));
    *si = ni / G, *sj = nj / G; /* 0 for a cap beside a real ring */
    return G;
}

/* Self terms from conservation: what scatters out of cell i is all of |Omega_i|. */
static void conserve_rows(const pp_dirs *d, double *Sa, const double *Sb)
{
    size_t n = (size_t)d->n;
    for (size_t i = 0; i < n; i++) {
        /* Neumaier's compensated sum: the rest to about an ulp, whatever its order */
        double rest = 0.0, comp = 0.0;
        for (size_t k = 0; k < 2 * n; k++) {
            double v = k < n ? (k == i ? 0.0 : Sa[i * n + k]) : Sb[i * n + k - n], t = rest + v;
            comp += fabs(rest) >= fabs(v) ? (rest - t) + v : (v - t) + rest;
            rest = t;
        }
        Sa[i * n + i] = d->area[i] - (rest + comp);
    }
}

/* Whether every ring is a cap or has an even count, so that w -> -w maps cells onto cells. */
static int antipodal(const pp_dirs *d)
{
    for (int r = 0; r < d->nrings; r++)
        if (ring_count(d, r) > 1 && ring_count(d, r) % 2)
            return 0;
    return 1;
}

/* A series' negative cell integrals set to 0 (phase.h), S_ij and S_ji alike, so S stays
 * symmetric; the diagonal, conserved afterwards, takes what they held. *clipped: the largest
 * share of a row so moved. */
static void clip_negative(const pp_dirs *d, double *Sa, double *Sb, double *clipped)
{
    size_t n = (size_t)d->n;
    double most = 0.0;
    for (size_t i = 0; i < n; i++) {
        double row = 0.0;
        for (size_t j = 0; j < n; j++) {
            if (j != i && Sa[i * n + j] < 0.0)
                row -= Sa[i * n + j], Sa[i * n + j] = 0.0;
            if (Sb[i * n + j] < 0.0)
                row -= Sb[i * n + j], Sb[i * n + j] = 0.0;
        }
        most = fmax(most, row / d->area[i]);
    }
    if (clipped)
        *clipped = most;
}

/* The blocks by quadrature: one pair integral per orbit of the ring pair's rotations, the z
 * mirror and the transpose (each orbit's members are copied, so the symmetries hold exactly). */
static int blocks_by_quadrature(pp_dirs *d, const pp_phase_fn *ph, double *Sa, double *Sb,
                                double *clipped, ppb_err *err)
{
    size_t n = (size_t)d->n;
    unsigned char *done = calloc(n * n, 1);
    int *zm = malloc(n * sizeof(int));
    double *cr = malloc(n * sizeof(double)), *sr = malloc(n * sizeof(double));
    if (!done || !zm || !cr || !sr) {
        free(done), free(zm), free(cr), free(sr);
        return ppb_fail(err, "phase matrix: out of memory");
    }
    for (int i = 0; i < d->n; i++)
        zm[i] = pp_dirs_zmirror(d, i), cr[i] = cos(d->radius[i]), sr[i] = sin(d->radius[i]);
    int rc = 0;
    for (int i = 0; rc == 0 && i < d->n; i++) {
        if (ppb_interrupted()) /* SIGINT or SIGTERM, checked row by row */
            rc = ppb_fail(err, "phase matrix: interrupted");
        for (int j = i; rc == 0 && j < d->n; j++) {
            if (done[i * n + j])
                continue;
            double va = 0.0, vb = 0.0;
            if (j > i)
                rc |= pair_integral(d, ph, i, j, cr, sr, &va, err);
            rc |= pair_integral(d, ph, i, d->n + j, cr, sr, &vb, err);
            int si, sj, G = ring_pair_symmetry(d, i, j, &si, &sj);
            for (int t = 0; t < G; t++) {
                int it = turn(d, i, t * si), jt = turn(d, j, t * sj);
                set_sym(n, zm, Sa, it, jt, va);
                set_sym(n, zm, Sb, it, jt, vb);
                int mi = zm[it], mj = zm[jt];
                done[it * n + jt] = done[jt * n + it] = done[mi * n + mj] = done[mj * n + mi] = 1;
            }
        }
    }
    free(zm), free(cr), free(sr);
    free(done);
    if (rc == 0 && ph->nmom > 0)
        clip_negative(d, Sa, Sb, clipped);
    if (rc == 0)
        conserve_rows(d, Sa, Sb);
    return rc;
}

int pp_phase_blocks_fn(pp_dirs *d, const pp_phase_fn *ph, double *Sa, double *Sb, double *clipped,
                       ppb_err *err)
{
    if (clipped)
        *clipped = 0.0;
    if (ph->nmom > 0) /* no peak: integrated directly for either sign of its moments */
        return check_series(ph, err) ? -1 : blocks_by_quadrature(d, ph, Sa, Sb, clipped, err);
    double g = ph->g;
    if (check_g(g, err) != 0)
        return -1;
    if (g >= 0 || !antipodal(d))
        return blocks_by_quadrature(d, ph, Sa, Sb, NULL, err);
    /* p(x.y; g) = p(x.(-y); -g): S(i, j; g) = S(i, antipode(j); -g). With a the up cell of
     * antipode(up j), Sa(g)_ij = Sb(-g)_i,a(j) and Sb(g)_ij = Sa(-g)_i,a(j): the peak of the
     * backward matrix is the conserved self term of the forward one. */
    pp_phase_fn neg = {-g, 0, {0}};
    if (blocks_by_quadrature(d, &neg, Sa, Sb, NULL, err) != 0)
        return -1;
    size_t n = (size_t)d->n;
    for (size_t i = 0; i < n; i++) {
        double *ra = Sa + i * n, *rb = Sb + i * n;
        for (int j = 0; j < d->n; j++) {
            int aj = pp_dirs_antipode(d, j) - d->n;
            if (aj < j)
                continue; /* each pair {j, a(j)} swapped once */
            double t = ra[j];
            ra[j] = rb[aj], rb[aj] = t;
            if (aj != j)
                t = ra[aj], ra[aj] = rb[j], rb[j] = t;
        }
    }
    return 0;
}

int pp_phase_blocks(pp_dirs *d, double g, double *Sa, double *Sb, ppb_err *err)
{
    pp_phase_fn ph = {g, 0, {0}};
    return pp_phase_blocks_fn(d, &ph, Sa, Sb, NULL, err);
}

int pp_phase_matrix_fn(pp_dirs *d, const pp_phase_fn *ph, double *P, double *clipped, ppb_err *err)
{
    size_t n = (size_t)d->n, m = 2 * n;
    double *Sa = malloc(sizeof(double) * n * n), *Sb = malloc(sizeof(double) * n * n);
    int rc = (Sa && Sb) ? pp_phase_blocks_fn(d, ph, Sa, Sb, clipped, err)
                        : ppb_fail(err, "phase matrix: out of memory");
    for (size_t i = 0; rc == 0 && i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            P[i * m + j] = P[(n + i) * m + n + j] = Sa[i * n + j] / d->area[i];
            P[i * m + n + j] = P[(n + i) * m + j] = Sb[i * n + j] / d->area[i];
        }
    }
    free(Sa);
    free(Sb);
    return rc;
}

int pp_phase_matrix(pp_dirs *d, double g, double *P, ppb_err *err)
{
    pp_phase_fn ph = {g, 0, {0}};
    return pp_phase_matrix_fn(d, &ph, P, NULL, err);
}

static void rect_dir(double theta, double phi, double ysign, double *v)
{
    v[0] = sin(theta) * cos(phi), v[1] = ysign * cos(theta), v[2] = sin(theta) * sin(phi);
}

/* Integral of p(w . y) over y in the (theta, phi) rectangle [t0, t1] x [p0, p1] (theta from
 * the pole of the rectangle's hemisphere, ysign = -1 for the down one), product Gauss with the
 * weight sin(theta); the rectangle is cut in four while the peak asks for more than PP_QMAX
 * nodes per axis (at most RECT_DEPTH times). */
#define RECT_DEPTH 10
static double point_rect(double g, const double w[3], double t0, double t1, double p0, double p1,
                         double ysign, int depth)
{
    double c[3], v[3], rad = 0.0, tm = 0.5 * (t0 + t1), pm = 0.5 * (p0 + p1);
    rect_dir(tm, pm, ysign, c);
    const double ts[3] = {t0, tm, t1}, ps[3] = {p0, pm, p1};
    for (int a = 0; a < 3; a += 1)
        for (int b = 0; b < 3; b += 1) {
            rect_dir(ts[a], ps[b], ysign, v);
            double cv = dot3(c, v);
            rad = fmax(rad, acos(cv > 1.0 ? 1.0 : cv));
        }
    double tmin = peak_angle(g, w, c) - rad;
    double h = fmax(0.5 * (t1 - t0), 0.5 * sin(fmin(t1, 0.5 * PPB_PI)) * (p1 - p0));
    double want = gauss_order_wanted(g, tmin > 0 ? cos(tmin) : 1.0, h);
    if (want > PP_QMAX && depth < RECT_DEPTH)
        return point_rect(g, w, t0, tm, p0, pm, ysign, depth + 1) +
               point_rect(g, w, t0, tm, pm, p1, ysign, depth + 1) +
               point_rect(g, w, tm, t1, p0, pm, ysign, depth + 1) +
               point_rect(g, w, tm, t1, pm, p1, ysign, depth + 1);
    int q = want < 2 ? 2 : (want > PP_QMAX ? PP_QMAX : (int)want);
    double x[PP_QMAX], wt[PP_QMAX], sum = 0.0;
    ppb_gauss_legendre(q, x, wt);
    for (int a = 0; a < q; a++) {
        double th = tm + 0.5 * (t1 - t0) * x[a], inner = 0.0;
        for (int b = 0; b < q; b++) {
            rect_dir(th, pm + 0.5 * (p1 - p0) * x[b], ysign, v);
            inner += wt[b] * pp_hg(g, dot3(w, v));
        }
        sum += wt[a] * sin(th) * inner;
    }
    return 0.25 * (t1 - t0) * (p1 - p0) * sum;
}

/* F by quadrature; the cell holding w is set by conservation. */
static int row_by_quadrature(pp_dirs *d, double g, const double w[3], double *F, ppb_err *err)
{
    int m = 2 * d->n, own = pp_dirs_cell_of(d, w);
    double point[4] = {w[0], w[1], w[2], 1.0}, rest = 0.0;
    for (int j = 0; j < m; j++) {
        if (j == own)
            continue;
        double tmin = peak_angle(g, w, d->centre + 3 * j) - cell_radius(d, j);
        double cmin = tmin > 0 ? cos(tmin) : 1.0;
        if (gauss_order_wanted(g, cmin, cell_half(d, j)) > PP_QMAX) {
            /* the peak is too close for one Gauss rule: bisect the cell's rectangle */
            double mu_lo, mu_hi, p0, p1;
            pp_dirs_bounds(d, j, &mu_lo, &mu_hi, &p0, &p1);
            /* theta from the pole of the cell's own hemisphere */
            int up = j < d->n;
            F[j] = point_rect(g, w, acos(up ? mu_hi : -mu_lo), acos(up ? mu_lo : -mu_hi), p0, p1,
                              up ? 1.0 : -1.0, 0);
            rest += F[j];
            continue;
        }
        int q = gauss_order(g, cmin, cell_half(d, j)), qz = azimuth_order(d, g, j, w);
        q = q > qz ? q : qz;
        const double *nj = pp_dirs_nodes(d, j, q, err);
        if (!nj)
            return -1;
        /* point-to-cell: one outer node of weight 1, q x q inner nodes; p factored as in
         * pair_sum */
        double c1 = ppb_hg_norm(g), sum = 0.0;
        for (int b = 0; b < q * q; b++) {
            double den = ppb_hg_base(g, dot3(point, nj + 4 * b));
            sum += nj[4 * b + 3] / (den * sqrt(den));
        }
        F[j] = c1 * sum;
        rest += F[j];
    }
    F[own] = 1.0 - rest;
    return 0;
}

/* F of the series: one q x q rule per cell (series_order), negative cells set to 0
 * (phase.h), the cell holding w by conservation. */
static int row_series(pp_dirs *d, const pp_phase_fn *ph, const double w[3], double *F,
                      double *clipped, ppb_err *err)
{
    int m = 2 * d->n, own = pp_dirs_cell_of(d, w);
    double c[PP_SERIES_MAX], rest = 0.0, neg = 0.0;
    series_coeffs(ph, c);
    for (int j = 0; j < m; j++) {
        if (j == own)
            continue;
        int q = series_order(ph->nmom, cell_half(d, j));
        const double *nj = pp_dirs_nodes(d, j, q, err);
        if (!nj)
            return -1;
        double sum = 0.0;
        for (int b = 0; b < q * q; b++)
            sum += nj[4 * b + 3] * series_sum(c, ph->nmom, dot3(w, nj + 4 * b));
        if (sum < 0.0)
            neg -= sum, sum = 0.0;
        F[j] = sum;
        rest += sum;
    }
    F[own] = 1.0 - rest;
    if (clipped)
        *clipped = neg;
    return 0;
}

int pp_phase_row_fn(pp_dirs *d, const pp_phase_fn *ph, const double w[3], double *F,
                    double *clipped, ppb_err *err)
{
    if (clipped)
        *clipped = 0.0;
    if (ph->nmom > 0)
        return check_series(ph, err) ? -1 : row_series(d, ph, w, F, clipped, err);
    double g = ph->g;
    if (check_g(g, err) != 0)
        return -1;
    if (g >= 0 || !antipodal(d))
        return row_by_quadrature(d, g, w, F, err);
    /* F_j(w; g) = F_antipode(j)(w; -g), as for the blocks */
    if (row_by_quadrature(d, -g, w, F, err) != 0)
        return -1;
    for (int j = 0; j < 2 * d->n; j++) {
        int aj = pp_dirs_antipode(d, j);
        if (aj > j) {
            double t = F[j];
            F[j] = F[aj], F[aj] = t;
        }
    }
    return 0;
}

int pp_phase_row(pp_dirs *d, double g, const double w[3], double *F, ppb_err *err)
{
    pp_phase_fn ph = {g, 0, {0}};
    return pp_phase_row_fn(d, &ph, w, F, NULL, err);
}
