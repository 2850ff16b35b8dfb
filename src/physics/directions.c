/* directions.c: the equal-area zonal partition of directions.h and its quadrature nodes. */
#include "physics/directions.h"

#include "kernels/ppb_conventions.h"

#include "base/quadrature.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Cells per ring below a polar ring of `pole` cells (one cap, or four quarter-cap wedges for
 * the antipodal partition of even N). Every cumulative count below the polar ring has the parity
 * of N, so every collar is even except the first when the polar ring's parity differs from N's
 * (a cap with even N): with an even polar ring, or a cap and odd N, the partition is closed
 * under w -> -w (the up/down mirror times a half turn; phase.h uses it for g < 0), and nearly
 * every ring pair is symmetric under a half turn. Collars have equal polar-angle width; as many
 * as fit below a one-cell cap at about the side of a square cell (sqrt(2 pi / N)), also under
 * the wedges (with one collar fewer the M = 668 radiance against PythonicDISORT was 8% worse:
 * 0.152% against 0.131% RMS); their counts are rounded cumulatively, in steps of two, so that
 * they sum to N exactly. theta_snap > 0 (pp_dirs_make_snap) puts the collar edge nearest it at
 * theta_snap (the collars above and below it of equal width each), up to that rounding, and cuts
 * the two collars beside it into SNAP_SPLIT each (ppsolver.h: there the radiance varies like the
 * Fresnel reflectance within a cell, and the error of a cell average scales with its width). */
#define SNAP_SPLIT 4

/* Lower edge of coarse collar r: equal widths, or equal on either side of theta_snap. */
static double coarse_theta(int r, int collars, int r_snap, double theta_cap, double theta_snap)
{
    if (r_snap <= 0)
        return theta_cap + (0.5 * PPB_PI - theta_cap) * r / collars;
    return r <= r_snap
               ? theta_cap + (theta_snap - theta_cap) * r / r_snap
               : theta_snap + (0.5 * PPB_PI - theta_snap) * (r - r_snap) / (collars - r_snap);
}

/* Lower edge of collar f after the two collars beside theta_snap are cut into `split`. */
static double fine_theta(int f, int collars, int r_snap, int split, double theta_cap,
                         double theta_snap)
{
    if (f <= r_snap - 1 || split == 1)
        return coarse_theta(f, collars, r_snap, theta_cap, theta_snap);
    if (f > r_snap - 1 + 2 * split)
        return coarse_theta(f - 2 * (split - 1), collars, r_snap, theta_cap, theta_snap);
    int piece = f - (r_snap - 1), c = r_snap - 1 + (piece - 1) / split + 1;
    double a = coarse_theta(c - 1, collars, r_snap, theta_cap, theta_snap);
    double b = coarse_theta(c, collars, r_snap, theta_cap, theta_snap);
    return a + (b - a) * ((piece - 1) % split + 1) / split;
}

/* The most rings per hemisphere with at least two cells each below a polar ring of `pole`. */
static int most_rings(int n, int pole)
{
    int first_min = pole % 2 != n % 2 ? 1 : 2;
    return 1 + (n - pole - first_min) / 2;
}

/* Cumulative cell count above a collar edge, rounded in steps of two from the target x (so it
 * keeps the parity of n) and clamped so that every ring keeps its minimum (ring_counts). */
static int cumulative(int n, int r, int rings, int done, int first_min, double x)
{
    int base = n % 2, left = rings - 1 - r; /* later collars need at least two cells each */
    int cum = r == rings - 1 ? n : base + 2 * (int)lround(0.5 * (x - base));
    if (cum > n - 2 * left)
        cum = n - 2 * left;
    if (cum < done + (r == 1 ? first_min : 2))
        cum = done + (r == 1 ? first_min : 2);
    return cum;
}

/* The equal-area partition: a polar ring of `pole` cells, then collars whose cell counts are
 * rounded from the equal-area cells above each edge (the edges are moved afterwards, make()). */
static int ring_counts(int n, int pole, double theta_snap, int want, int whole, int *count)
{
    count[0] = pole;
    if (n == pole)
        return 1;
    double theta_cap = acos(1.0 - (double)pole / n), side = sqrt(2.0 * PPB_PI / n);
    int collars = want > 0 ? want : (int)lround((0.5 * PPB_PI - acos(1.0 - 1.0 / n)) / side);
    int first_min = pole % 2 != n % 2 ? 1 : 2, most = most_rings(n, pole);
    if (collars < 1)
        collars = 1;
    if (collars > most)
        collars = most;
    int done = pole, r_snap = 0, split = 1, coarse = collars;
    if (theta_snap > theta_cap && theta_snap < 0.5 * PPB_PI && collars >= 2) {
        r_snap = (int)lround((theta_snap - theta_cap) / (0.5 * PPB_PI - theta_cap) * collars);
        r_snap = r_snap < 1 ? 1 : (r_snap > collars - 1 ? collars - 1 : r_snap);
        if (!whole && collars + 2 * (SNAP_SPLIT - 1) <= most)
            split = SNAP_SPLIT, collars += 2 * (SNAP_SPLIT - 1);
    }
    for (int r = 1; r <= collars; r++) {
        double theta = r_snap > 0 ? fine_theta(r, coarse, r_snap, split, theta_cap, theta_snap)
                                  : theta_cap + (0.5 * PPB_PI - theta_cap) * r / collars;
        int cum = cumulative(n, r, collars + 1, done, first_min, n * (1.0 - cos(theta)));
        count[r] = cum - done;
        done = cum;
    }
    return collars + 1;
}

/* Cells per ring for ring edges theta [rings + 1]: the cap `pole`, below it in proportion to
 * the rings' areas, rounded cumulatively in steps of two (cumulative), first_min in the first
 * ring and two at least in every other. */
static void area_counts(int n, int pole, int rings, int first_min, const double *theta, int *count)
{
    count[0] = pole;
    double below_cap = cos(theta[1]);
    for (int r = 1, done = pole; r < rings; r++) {
        double x = pole + (n - pole) * (below_cap - cos(theta[r + 1])) / below_cap;
        int cum = cumulative(n, r, rings, done, first_min, x);
        count[r] = cum - done;
        done = cum;
    }
}

/* The polar-ring partition (directions.h, pp_dirs_make_collars): `want` + 1 rings of equal
 * polar-angle width from the pole, the cap (`pole` cells) the first of them, snapped and split
 * at theta_snap as above; theta[r] is ring r's upper edge (theta[0] = 0, theta[rings] = pi / 2).
 * Below the cap the cells follow the rings' areas, rounded cumulatively in steps of two, two
 * at least a ring. */
static int polar_counts(int n, int pole, double theta_snap, int want, int *count, double *theta)
{
    /* the first collar odd where the cap's parity differs from N's: three cells, not one, so
     * that no ring but the cap is a whole annulus */
    int most = most_rings(n, pole) - 1, first_min = pole % 2 != n % 2 ? 3 : 2;
    int coarse = want + 1 > most ? most : want + 1, rings = coarse, r_snap = 0, split = 1;
    if (theta_snap > 0.0 && theta_snap < 0.5 * PPB_PI && coarse >= 2) {
        r_snap = (int)lround(theta_snap / (0.5 * PPB_PI) * coarse);
        r_snap = r_snap < 1 ? 1 : (r_snap > coarse - 1 ? coarse - 1 : r_snap);
        if (coarse + 2 * (SNAP_SPLIT - 1) <= most)
            split = SNAP_SPLIT, rings += 2 * (SNAP_SPLIT - 1);
    }
    for (int r = 0; r <= rings; r++)
        theta[r] = r == rings   ? 0.5 * PPB_PI
                   : r_snap > 0 ? fine_theta(r, coarse, r_snap, split, 0.0, theta_snap)
                                : 0.5 * PPB_PI * r / coarse;
    area_counts(n, pole, rings, first_min, theta, count);
    return rings;
}

/* The graded polar rings (directions.h, pp_dirs_spec.h_pole): a cap of `pole` cells and of
 * radius h / sqrt(pi) (one near-square cell of side h), then rings whose polar widths grow
 * geometrically from h at the cap to the square cell's side sqrt(2 pi / N) at the equator;
 * theta_snap, if any, moves the edge nearest it onto it, the edges on either side rescaled
 * (nothing split). The cells follow the rings' areas (area_counts). */
static int graded_counts(int n, int pole, double theta_snap, double h, int *count, double *theta)
{
    int most = most_rings(n, pole) - 1, first_min = pole % 2 != n % 2 ? 3 : 2;
    double side = sqrt(2.0 * PPB_PI / n), t1 = h / sqrt(PPB_PI), span = 0.5 * PPB_PI - t1;
    double k = (side - h) / span; /* width growth per radian of polar angle */
    int rings = 1 + (int)lround(k > 1e-9 ? log(side / h) / k : span / h);
    rings = rings < 2 ? 2 : (rings > most ? most : rings);
    theta[0] = 0.0;
    for (int r = 1; r <= rings; r++)
        theta[r] = t1 + span * (k > 1e-9 ? expm1(k * (r - 1)) / expm1(k * (rings - 1))
                                         : (double)(r - 1) / (rings - 1));
    if (theta_snap > t1 && theta_snap < 0.5 * PPB_PI && rings > 2) {
        int b = 2;
        for (int r = 2; r < rings; r++)
            if (fabs(theta[r] - theta_snap) < fabs(theta[b] - theta_snap))
                b = r;
        double tb = theta[b];
        for (int r = 2; r < rings; r++)
            theta[r] = r <= b ? t1 + (theta[r] - t1) * (theta_snap - t1) / (tb - t1)
                              : theta_snap + (theta[r] - tb) * (0.5 * PPB_PI - theta_snap) /
                                                 (0.5 * PPB_PI - tb);
    }
    area_counts(n, pole, rings, first_min, theta, count);
    return rings;
}

static int alloc_all(pp_dirs *d, int n, int nrings)
{
    d->ring_first = calloc((size_t)nrings + 1, sizeof(int));
    d->mu_edge = calloc((size_t)nrings + 1, sizeof(double));
    d->ring = calloc((size_t)n, sizeof(int));
    d->phi_lo = calloc((size_t)n, sizeof(double));
    d->phi_hi = calloc((size_t)n, sizeof(double));
    d->k = calloc(2 * (size_t)n, sizeof(double));
    d->centre = calloc(6 * (size_t)n, sizeof(double));
    d->radius = calloc((size_t)n, sizeof(double));
    d->half = calloc((size_t)n, sizeof(double));
    d->area = calloc((size_t)n, sizeof(double));
    return (d->area && d->ring_first && d->mu_edge && d->ring && d->phi_lo && d->phi_hi && d->k &&
            d->centre && d->radius && d->half)
               ? 0
               : -1;
}

static void set_dir(double mu, double phi, double *w)
{
    double s = sqrt(fmax(0.0, 1.0 - mu * mu));
    w[0] = s * cos(phi);
    w[1] = mu;
    w[2] = s * sin(phi);
}

static double angle_between(const double *a, const double *b)
{
    double c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return acos(c > 1.0 ? 1.0 : (c < -1.0 ? -1.0 : c));
}

/* A ring of one cell (the cap) spans all azimuths: its phi rule is the periodic trapezoid,
 * which converges exponentially there, where Gauss over [-pi, pi] converges slowly. */
static int full_circle(const pp_dirs *d, int i)
{
    int r = d->ring[i];
    return d->ring_first[r + 1] - d->ring_first[r] == 1;
}

/* Centre, mean cosine and corner radius of up cell i and its mirror N + i. */
static void cell_geometry(pp_dirs *d, int i)
{
    int r = d->ring[i], n = d->n;
    double mu_hi = d->mu_edge[r], mu_lo = d->mu_edge[r + 1];
    double *c = d->centre + 3 * i, *cm = d->centre + 3 * (n + i);
    d->k[i] = 0.5 * (mu_hi + mu_lo);
    d->k[n + i] = -d->k[i];
    if (r == 0 && full_circle(d, i)) {
        set_dir(1.0, 0.0, c); /* the cap: centred on the pole */
    } else {
        set_dir(0.5 * (mu_hi + mu_lo), 0.5 * (d->phi_lo[i] + d->phi_hi[i]), c);
    }
    cm[0] = c[0], cm[1] = -c[1], cm[2] = c[2];
    double rad = 0.0, corner[3];
    for (int a = 0; a < 4; a++) {
        set_dir(a & 1 ? mu_hi : mu_lo, a & 2 ? d->phi_hi[i] : d->phi_lo[i], corner);
        rad = fmax(rad, angle_between(c, corner));
    }
    /* the bottom edge's midpoint can lie farther than the corners on wide sectors */
    set_dir(mu_lo, 0.5 * (d->phi_lo[i] + d->phi_hi[i]), corner);
    d->radius[i] = fmax(rad, angle_between(c, corner));
    double t0 = acos(mu_hi), t1 = acos(mu_lo), sin_max = sin(t1);
    /* the cap's periodic trapezoid gains about a factor 10 per node next to the rim, which
     * the Gauss estimate of phase.c reproduces with a half-length of 3 theta_cap (measured
     * against order 16 in tests/test_phase.c) */
    d->half[i] = full_circle(d, i)
                     ? 3.0 * (t1 - t0)
                     : fmax(0.5 * (t1 - t0), 0.5 * sin_max * (d->phi_hi[i] - d->phi_lo[i]));
}

int pp_dirs_max_collars(int n)
{
    return n < 6 ? 0 : (n - 4) / 2; /* below every partition's own limit (ring_counts) */
}

/* Whether spec asks for the graded rings: h_pole below the square cell's side and rings to
 * spare (two cells each below the cap). */
static int graded(int n, const pp_dirs_spec *spec)
{
    return spec->collars == 0 && spec->h_pole > 0.0 && spec->h_pole < sqrt(2.0 * PPB_PI / n) &&
           n >= 8;
}

int pp_dirs_make_spec(int n, const pp_dirs_spec *spec, pp_dirs *d, ppb_err *err)
{
    memset(d, 0, sizeof *d);
    int collars = spec->collars, antipodal = spec->antipodal;
    double theta_snap = spec->mu_snap > 0.0 && spec->mu_snap < 1.0 ? acos(spec->mu_snap) : 0.0;
    if (n < 1 || n > PP_DIRS_MAX)
        return ppb_fail(err, "pp directions: %d cells per hemisphere, need 1..%d", n, PP_DIRS_MAX);
    if (collars < 0 || collars > pp_dirs_max_collars(n))
        return ppb_fail(err, "pp directions: %d collars, need 0..%d for %d cells per hemisphere",
                        collars, pp_dirs_max_collars(n), n);
    int *count = calloc((size_t)n + 1, sizeof(int));
    double *theta = calloc((size_t)n + 1, sizeof(double));
    if (!count || !theta) {
        free(count), free(theta);
        return ppb_fail(err, "pp directions: out of memory");
    }
    int pole = antipodal && n % 2 == 0 ? (n < 4 ? n : 4) : 1, grade = graded(n, spec);
    int polar = collars > 0 || grade;
    int nrings = grade   ? graded_counts(n, pole, theta_snap, spec->h_pole, count, theta)
                 : polar ? polar_counts(n, pole, theta_snap, collars, count, theta)
                         : ring_counts(n, pole, theta_snap, collars, spec->whole_snap, count);
    d->n = n;
    d->nrings = nrings;
    d->polar = polar;
    d->solid = 2.0 * PPB_PI / n;
    if (alloc_all(d, n, nrings) != 0) {
        free(count), free(theta);
        pp_dirs_free(d);
        return ppb_fail(err, "pp directions: out of memory");
    }
    d->mu_edge[0] = 1.0;
    for (int r = 0, cell = 0; r < nrings; r++) {
        d->ring_first[r] = cell;
        double dphi = 2.0 * PPB_PI / count[r];
        for (int j = 0; j < count[r]; j++, cell++) {
            d->ring[cell] = r;
            d->phi_lo[cell] = (j - 0.5) * dphi;
            d->phi_hi[cell] = (j + 0.5) * dphi;
        }
        d->ring_first[r + 1] = cell + 0;
        /* equal areas: mu = 1 - C/N makes each ring's area exactly count * 2 pi / N; polar
         * rings keep their edges, and their cells' areas follow */
        d->mu_edge[r + 1] = r + 1 == nrings ? 0.0
                            : polar         ? cos(theta[r + 1])
                                            : 1.0 - (double)(cell) / n;
        for (int j = d->ring_first[r]; j < cell; j++)
            d->area[j] =
                polar ? 2.0 * PPB_PI * (d->mu_edge[r] - d->mu_edge[r + 1]) / count[r] : d->solid;
    }
    free(count), free(theta);
    for (int i = 0; i < n; i++)
        cell_geometry(d, i);
    return 0;
}

int pp_dirs_make(int n, pp_dirs *d, ppb_err *err)
{
    return pp_dirs_make_spec(n, &(pp_dirs_spec){0}, d, err);
}

int pp_dirs_make_snap(int n, int antipodal, double mu_snap, pp_dirs *d, ppb_err *err)
{
    return pp_dirs_make_spec(n, &(pp_dirs_spec){.antipodal = antipodal, .mu_snap = mu_snap}, d,
                             err);
}

int pp_dirs_make_antipodal(int n, pp_dirs *d, ppb_err *err)
{
    return pp_dirs_make_spec(n, &(pp_dirs_spec){.antipodal = 1}, d, err);
}

int pp_dirs_make_collars(int n, int antipodal, double mu_snap, int collars, pp_dirs *d,
                         ppb_err *err)
{
    pp_dirs_spec spec = {.antipodal = antipodal, .mu_snap = mu_snap, .collars = collars};
    return pp_dirs_make_spec(n, &spec, d, err);
}

void pp_dirs_free(pp_dirs *d)
{
    free(d->ring_first);
    free(d->mu_edge);
    free(d->ring);
    free(d->phi_lo);
    free(d->phi_hi);
    free(d->k);
    free(d->centre);
    free(d->radius);
    free(d->half);
    free(d->area);
    for (int q = 0; q <= PP_QMAX; q++)
        free(d->nodes[q]);
    memset(d, 0, sizeof *d);
}

int pp_dirs_cell_of(const pp_dirs *d, const double w[3])
{
    double mu = fabs(w[1]);
    int lo = 0, hi = d->nrings - 1; /* ring r holds mu_edge[r+1] <= mu <= mu_edge[r] */
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (mu >= d->mu_edge[mid + 1])
            hi = mid;
        else
            lo = mid + 1;
    }
    int count = d->ring_first[lo + 1] - d->ring_first[lo];
    double phi = atan2(w[2], w[0]), dphi = 2.0 * PPB_PI / count;
    int j = (int)floor(phi / dphi + 0.5);
    j = ((j % count) + count) % count;
    int cell = d->ring_first[lo] + j;
    return w[1] < 0.0 ? d->n + cell : cell;
}

int pp_dirs_zmirror(const pp_dirs *d, int cell)
{
    int up = cell < d->n ? cell : cell - d->n, r = d->ring[up];
    int count = d->ring_first[r + 1] - d->ring_first[r], j = up - d->ring_first[r];
    int mirror = d->ring_first[r] + (count - j) % count;
    return cell < d->n ? mirror : d->n + mirror;
}

int pp_dirs_antipode(const pp_dirs *d, int cell)
{
    int up = cell < d->n ? cell : cell - d->n, r = d->ring[up];
    int count = d->ring_first[r + 1] - d->ring_first[r], j = up - d->ring_first[r];
    if (count > 1 && count % 2)
        return -1;
    int anti = d->ring_first[r] + (count > 1 ? (j + count / 2) % count : 0);
    return cell < d->n ? d->n + anti : anti;
}

void pp_dirs_bounds(const pp_dirs *d, int cell, double *mu_lo, double *mu_hi, double *phi_lo,
                    double *phi_hi)
{
    int up = cell < d->n ? cell : cell - d->n, r = d->ring[up];
    double top = d->mu_edge[r], bottom = d->mu_edge[r + 1];
    *mu_lo = cell < d->n ? bottom : -top;
    *mu_hi = cell < d->n ? top : -bottom;
    *phi_lo = d->phi_lo[up];
    *phi_hi = d->phi_hi[up];
}

/* Nodes of every cell for one q: Gauss in theta (weight sin theta) times Gauss in phi. The
 * theta parametrisation keeps the integrand smooth at the pole, where it is not smooth in mu;
 * the weights are then rescaled so that they sum to the exact |Omega|. The product form needs
 * only q cosines and sines per axis and cell. */
static int build_nodes(pp_dirs *d, int q)
{
    int n = d->n, nq = q * q;
    double *out = malloc(sizeof(double) * 4 * (size_t)nq * 2 * (size_t)n);
    if (!out)
        return -1;
    double x[PP_QMAX], w[PP_QMAX];
    double ct[PP_QMAX], st[PP_QMAX], wt[PP_QMAX], cp[PP_QMAX], sp[PP_QMAX], wp[PP_QMAX];
    ppb_gauss_legendre(q, x, w);
    for (int i = 0; i < n; i++) {
        int r = d->ring[i];
        double t0 = acos(d->mu_edge[r]), t1 = acos(d->mu_edge[r + 1]);
        double p0 = d->phi_lo[i], p1 = d->phi_hi[i], sum = 0.0;
        int trap = full_circle(d, i);
        for (int a = 0; a < q; a++) {
            double th = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * x[a];
            double ph =
                trap ? p0 + (a + 0.5) * (p1 - p0) / q : 0.5 * (p0 + p1) + 0.5 * (p1 - p0) * x[a];
            ct[a] = cos(th), st[a] = sin(th), wt[a] = 0.5 * (t1 - t0) * w[a] * st[a];
            cp[a] = cos(ph), sp[a] = sin(ph), wp[a] = trap ? (p1 - p0) / q : 0.5 * (p1 - p0) * w[a];
        }
        double *row = out + 4 * (size_t)nq * i, *mir = out + 4 * (size_t)nq * (n + i);
        for (int a = 0; a < q; a++) {
            for (int b = 0; b < q; b++) {
                double *node = row + 4 * (a * q + b);
                node[0] = st[a] * cp[b], node[1] = ct[a], node[2] = st[a] * sp[b];
                node[3] = wt[a] * wp[b];
                sum += node[3];
            }
        }
        for (int m = 0; m < nq; m++) {
            row[4 * m + 3] *= d->area[i] / sum;
            mir[4 * m] = row[4 * m], mir[4 * m + 1] = -row[4 * m + 1];
            mir[4 * m + 2] = row[4 * m + 2], mir[4 * m + 3] = row[4 * m + 3];
        }
    }
    d->nodes[q] = out;
    return 0;
}

const double *pp_dirs_nodes(pp_dirs *d, int cell, int q, ppb_err *err)
{
    if (q < 1 || q > PP_QMAX) {
        ppb_fail(err, "pp directions: quadrature order %d outside 1..%d", q, PP_QMAX);
        return NULL;
    }
    if (!d->nodes[q] && build_nodes(d, q) != 0) {
        ppb_fail(err, "pp directions: out of memory for order-%d nodes", q);
        return NULL;
    }
    return d->nodes[q] + 4 * (size_t)q * q * cell;
}
