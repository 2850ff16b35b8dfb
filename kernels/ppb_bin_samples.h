/* ppb_bin_samples.h: the deterministic methods' exit samples (reference: Bins), for host and
 * kernels.
 *
 * Owns: the direction samples of a bin and their weights in its average (`pp`, `ss`, `ppslab`,
 * `rte2d`, `ss3d`, `pp3d` and what `ppbench scene` hands an external method), the Gauss-Legendre
 * rule they use (the one code of it: the host's ppb_gauss_legendre calls it too), the samples'
 * flat index, and the exit cells and samples of the tube's marchers (a segment's points times a
 * bin's directions).
 *
 * Apart from ppb_conventions.h and ppb_tube.h because the Monte Carlo, which tallies bins
 * exactly, includes those two and not this one: the reference cache's key hashes the Monte
 * Carlo kernel's source with its includes (docs/reference.md, Keys), so a change of how the
 * deterministic methods sample a bin leaves the shipped references valid. Plain C that is also
 * OpenCL C, like ppb_conventions.h. */
#ifndef PPB_BIN_SAMPLES_H
#define PPB_BIN_SAMPLES_H

#include "ppb_conventions.h"
#include "ppb_tube.h"

/* Node i of the q-point Gauss-Legendre rule on [-1, 1] (descending, x_0 nearest 1); *w its
 * weight. Newton on P_q from the Chebyshev guess, P_q and P_q' by the three-term recurrence; it
 * converges to machine precision for every q the project uses (at most 64). The one code of the
 * rule: the host's ppb_gauss_legendre (base/quadrature.h) and the bin samples below call it. */
PPB_FN double ppb_gauss_legendre_node(int q, int i, double *w)
{
    double z = cos(PPB_PI * (i + 0.75) / (q + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; it++) {
        double p0 = 1.0, p1 = z;
        for (int l = 2; l <= q; l++) {
            double p2 = ((2 * l - 1) * z * p1 - (l - 1) * p0) / l;
            p0 = p1;
            p1 = p2;
        }
        dp = q * (z * p1 - p0) / (z * z - 1.0);
        double dz = p1 / dp;
        z -= dz;
        if (fabs(dz) < 1e-16)
            break;
    }
    *w = 2.0 / ((1.0 - z * z) * dp * dp);
    return z;
}

/* Row a of the n sample rows of theta bin itheta (reference: Bins): *u, its position in the
 * bin's sin^2(theta) range as a fraction in (0, 1), and the return value, its weight in the bin's
 * average (the n rows' weights sum to n). The rows between the first and the last: the
 * midpoints, weight 1. The two end rows are graded toward their ends, with t on the n-point
 * Gauss-Legendre rule over [0, 1] (nodes (1 - x_a) / 2, weights W_a / 2) times the Jacobian:
 * - The last row reaches the tangent plane (mu = 0), where the exit radiance goes as a + b mu
 *   (the Fresnel transmittance 1 - F at n > 1 falls to 0 linearly in mu; a half-space's exit
 *   radiance rises about as a + b mu from its value at grazing, Chandrasekhar's H-function,
 *   whose mu log(mu) term the rule integrates well but not exactly), mu = sqrt(1 - sin^2),
 *   which midpoints in sin^2 integrate with an error of order n^-1.5 (1.1-1.4 % high at 4 x 4
 *   and n = 1.4). There u = 1 - (1 - t)^2, so mu = (1 - t) / sqrt(ntheta) and a + b mu is a
 *   polynomial in t, integrated exactly to degree 2n - 1 (du/dt = 2 (1 - t)).
 * - The first row reaches the normal, where a smooth field's part that turns with phi goes as
 *   sin(theta) = sqrt(sin^2), again a square root for midpoints, and where at normal light the
 *   beam's once-scattered light leaves in a peak of about (1 - g) rad: in sin^2 it goes as
 *   ((1 - g)^2 + g sin^2)^(-3/2), nearly singular at the row's end for g >= 0.8. There
 *   u = t^2 (du/dt = 2t), so sin(theta) is linear in t. The bin average of HG's peak over the
 *   first of 8 rows at 4 x 4: midpoints 2.3 % low at g = 0.8, 17 % at 0.9, 47 % at 0.95; graded
 *   within 0.04 %, 1.0 % and 2.9 % (8 x 8: 2e-5, 8e-4; tests/test_bins.c).
 * - A single row (ntheta = 1) reaches both and keeps the tangent plane's grading: the
 *   projected solid angle there is 1/mu times the solid angle, which that rule integrates
 *   exactly. */
PPB_FN double ppb_bin_sample_u(int itheta, int a, int n, int ntheta, double *u)
{
    if (itheta > 0 && itheta < ntheta - 1) {
        *u = (a + 0.5) / n;
        return 1.0;
    }
    double W, t = 0.5 * (1.0 - ppb_gauss_legendre_node(n, a, &W));
    if (itheta == 0 && ntheta > 1) {
        *u = t * t;
        return n * 0.5 * W * 2.0 * t;
    }
    *u = 1.0 - (1.0 - t) * (1.0 - t);
    return n * 0.5 * W * 2.0 * (1.0 - t);
}

/* The stratified direction samples of the deterministic methods (`pp`, `ss`, `ppslab`, `rte2d`,
 * `pp3d`; reference: Bins): sample (a, b) of bin `bin` on surface surf, in phi the midpoint of
 * column b of n, in sin^2(theta) row a of ppb_bin_sample_u. Returns the sample's weight in the
 * bin's average: a bin's value is sum(weight x radiance) / n^2 (the weights sum to n^2). */
PPB_FN double ppb_bin_sample_dir(int surf, int bin, int a, int b, int n, int ntheta, int nphi,
                                 double *wx, double *wy, double *wz)
{
    double u, weight = ppb_bin_sample_u(bin / nphi, a, n, ntheta, &u);
    ppb_bin_direction(surf, bin / nphi, bin % nphi, u, (b + 0.5) / n, ntheta, nphi, wx, wy, wz);
    return weight;
}

/* The samples' flat index (the marchers' tables and source planes are in this order). */
PPB_FN int ppb_bin_sample_index(int surf, int bin, int a, int b, int n, int nbins)
{
    return ((surf * nbins + bin) * n + a) * n + b;
}

/* Samples of every bin of nsurf surfaces. */
PPB_FN int ppb_bin_sample_count(int nsurf, int nbins, int n)
{
    return nsurf * nbins * n * n;
}

/* The inverse of ppb_bin_sample_index: surface, bin and sample (a, b) of index dir. */
PPB_FN void ppb_bin_sample_split(int dir, int n, int nbins, int *surf, int *bin, int *a, int *b)
{
    int per_bin = n * n, ab = dir % per_bin;
    *surf = dir / (nbins * per_bin);
    *bin = dir / per_bin % nbins;
    *a = ab / n;
    *b = ab % n;
}

/* The exit cells of the deterministic marchers (`pp`, `ss`, `rte2d`; reference: Bins): work-item
 * gid of a launch that starts at layout row row0 owns the (segment row, bin) cell
 * row0 + gid / nbins, bin gid % nbins. Returns the row's surface (-1 past the layout) with *seg
 * and *bin. */
PPB_FN int ppb_exit_cell(int gid, int row0, int nbins, const int *offset, const int *nseg, int *seg,
                         int *bin)
{
    *bin = gid % nbins;
    return ppb_row_surface(row0 + gid / nbins, offset, nseg, seg);
}

/* The samples of such a cell: npts points of its segment (slab: the face's one point) times the
 * bin's nsamp x nsamp directions. */
PPB_FN int ppb_exit_nsamples(const ppb_medium *M, int npts, int nsamp)
{
    return (M->tube ? npts : 1) * nsamp * nsamp;
}

/* Sample k of such a cell, k = (ip nsamp + a) nsamp + b in [0, ppb_exit_nsamples): the exit
 * point ip of the segment (ppb_segment_sample) in (*px, *py), the bin's direction sample (a, b)
 * in w[0..2] and its weight in *weight (ppb_bin_sample_dir: the cell's value is the sum of
 * weight x radiance over its samples / ppb_exit_nsamples). Returns the sample's index
 * (ppb_bin_sample_index), the order of the marchers' tables and source planes. */
PPB_FN int ppb_exit_sample(const ppb_medium *M, int surf, int seg, int nseg, int bin, int npts,
                           int nsamp, int ntheta, int nphi, int k, double *px, double *py,
                           double *w, double *weight)
{
    int b = k % nsamp, a = k / nsamp % nsamp, ip = k / (nsamp * nsamp);
    npts = M->tube ? npts : 1;
    ppb_segment_sample(M->tube, surf, seg, nseg, M->width, M->height, ip, npts, px, py);
    *weight = ppb_bin_sample_dir(surf, bin, a, b, nsamp, ntheta, nphi, &w[0], &w[1], &w[2]);
    return ppb_bin_sample_index(surf, bin, a, b, nsamp, ppb_bin_count(ntheta, nphi));
}

#endif
