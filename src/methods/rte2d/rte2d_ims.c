/* rte2d_ims.c: the intensity correction of the exit radiance under delta-M (rte2d_ims.h). */
#include "methods/rte2d/rte2d_ims.h"

#include <cblas.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kernels/ppb_conventions.h"

/* Series terms at most, and the relative size of the first term left out (of e^x, the sum's
 * scale). */
#define IMS_KMAX       256
#define IMS_SERIES_TOL 1e-15
/* Legendre orders at most, and where the residual's moments (2l + 1) g^l / f stop counting. */
#define IMS_LMAX       20000
#define IMS_MOMENT_TOL 1e-13
/* Nodes whose scaled beam e^-(1 - a) s is below this get no correction. */
#define IMS_EXP_FLOOR 1e-16

double ppb_rte_ims_moment(double g, double f, const pp_phase_fn *ph, int l)
{
    double chi = ph->nmom > 0 ? (l < ph->nmom ? ph->chi[l] : 0.0) : pow(ph->g, l);
    return (pow(g, l) - (1.0 - f) * chi) / f;
}

/* Series terms for x up to xmax: the first k with xmax^k / k! below IMS_SERIES_TOL e^xmax. */
static int series_terms(double xmax)
{
    double t = 1.0, scale = exp(xmax);
    int k = 1;
    for (; k < IMS_KMAX; k++) {
        t *= xmax / k;
        if (t < IMS_SERIES_TOL * scale)
            break;
    }
    return k;
}

/* The beam's passes at a node: unscaled optical path s[p] from S1 and amplitude amp[p] (the
 * irradiance, 0 where unlit, or where the scaled beam e^-(1 - a) s is below IMS_EXP_FLOOR). */
static void node_passes(const ppb_rte_params *P, double a, int reflect, double x, double y,
                        double *s, double *amp)
{
    double D, DH = 0.0;
    int lit, litH;
    ppb_rte_light(P, x, y, &D, &lit);
    double e0 = 1.0;
    if (P->med.n > 1.0) {
        ppb_rte_light(P, x, -P->med.height, &DH, &litH);
        e0 = P->beam_in / (1.0 - P->beam_fb * P->beam_fb * exp(-2.0 * DH));
    }
    s[0] = D / (1.0 - a);
    amp[0] = lit ? e0 : 0.0;
    s[1] = (2.0 * DH - D) / (1.0 - a);
    amp[1] = lit && reflect ? e0 * P->beam_fb : 0.0;
    for (int p = 0; p < 2; p++)
        if (!(exp(-(1.0 - a) * s[p]) > IMS_EXP_FLOOR))
            amp[p] = 0.0;
}

/* Every node's passes, [nnodes][4] = s0, amp0, s1, amp1; *xmax the largest x = a s a pass with
 * light reaches. */
static void all_passes(const ppb_rte_grid *G, double a, int reflect, double *paths, double *xmax)
{
    const ppb_rte_params *P = &G->P;
    *xmax = 0.0;
    for (int j = 0; j < P->ny; j++)
        for (int i = 0; i < P->nx; i++) {
            double *q = paths + 4 * (size_t)(j * P->nx + i), s[2], amp[2];
            node_passes(P, a, reflect, ppb_rte_node_x(P, i), ppb_rte_node_y(P, j), s, amp);
            for (int p = 0; p < 2; p++) {
                q[2 * p] = s[p], q[2 * p + 1] = amp[p];
                if (amp[p] > 0.0)
                    *xmax = fmax(*xmax, a * s[p]);
            }
        }
}

/* B [m][nnodes], per unit scattering coefficient (the march multiplies by sigma_s'; sigma_s' =
 * albedo (1 - f) sigma_t, and S is per unit optical path): block p < npass, the series of pass p,
 * (x^k / k!) e^-s amp f / (1 - f); block 2 (the reflection), the down pass's peak light at S2,
 * amp e^-s_H (x_H^k / k!), spread along the up pass as e^-(1 - a)(s - s_H) / s_H so that it
 * reaches S1 as that light attenuated over the pass (rte2d_ims.h). */
static void depth_factors(const double *paths, int nn, double albedo, double f, int reflect, int K,
                          double *B)
{
    double a = f * albedo;
    int npass = reflect ? 2 : 1;
    for (int node = 0; node < nn; node++) {
        const double *q = paths + 4 * (size_t)node;
        for (int p = 0; p < npass; p++) {
            double s = q[2 * p], x = a * s, t = q[2 * p + 1] * f / (1.0 - f) * exp(-s);
            for (int k = 1; k <= K; k++) {
                t *= x / k;
                B[(size_t)(p * K + k - 1) * nn + node] = t;
            }
        }
        if (!reflect)
            continue;
        double sH = 0.5 * (q[0] + q[2]), xH = a * sH; /* S2: s1 = 2 s_H - s0 */
        double t = q[3] * exp(-sH - (1.0 - a) * (q[2] - sH)) / (sH * albedo * (1.0 - f));
        for (int k = 1; k <= K; k++) {
            t *= xH / k;
            B[(size_t)(2 * K + k - 1) * nn + node] = t;
        }
    }
}

/* A's row of one exit direction w: for each block (its beam direction b and its coefficient
 * table c) and k, sum_l (2l + 1) / 4 pi P_l(w . b) c[l][k]. */
static void angular_row(const double *const *c, int L, int K, int nblock, const double *w,
                        const double beams[3][3], double *row)
{
    for (int p = 0; p < nblock; p++) {
        double mu = w[0] * beams[p][0] + w[1] * beams[p][1] + w[2] * beams[p][2];
        double *r = row + p * K;
        memset(r, 0, sizeof(double) * K);
        double pm1 = 0.0, pl = 1.0; /* P_{l-1}, P_l */
        for (int l = 0; l <= L; l++) {
            double wl = (2.0 * l + 1.0) / (4.0 * PPB_PI) * pl;
            for (int k = 0; k < K; k++)
                r[k] += wl * c[p][(size_t)l * K + k];
            double pn = ((2.0 * l + 1.0) * mu * pl - l * pm1) / (l + 1.0);
            pm1 = pl;
            pl = pn;
        }
    }
}

int ppb_rte_ims_make(const ppb_rte_grid *G, double g, double albedo, double f, const double *w,
                     int ndir, ppb_rte_ims *m, ppb_err *err)
{
    memset(m, 0, sizeof *m);
    if (!(f > 0.0 && f < 1.0 && albedo > 0.0))
        return 0;
    const ppb_rte_params *P = &G->P;
    double a = f * albedo;
    int reflect = P->med.n > 1.0 && !ppb_rte_beam_images(P), nn = G->nnodes;
    double *paths = malloc(sizeof(double) * 4 * (size_t)nn), xmax;
    if (!paths)
        return ppb_fail(err, "rte2d: out of memory (the intensity correction)");
    all_passes(G, a, reflect, paths, &xmax);
    int K = series_terms(xmax);
    /* The residual's moments count while (2l + 1) g^l / f does (and through the retained
     * series' length). */
    int L = G->phase.nmom;
    while (L < IMS_LMAX && (2.0 * L + 1.0) * pow(g, L) / f > IMS_MOMENT_TOL)
        L++;
    int nblock = reflect ? 3 : 1;
    m->m = nblock * K;
    m->A = malloc(sizeof(double) * (size_t)ndir * m->m);
    m->B = malloc(sizeof(double) * (size_t)m->m * G->nnodes);
    double *c = malloc(sizeof(double) * (size_t)(L + 1) * K), *cp = NULL;
    if (reflect)
        cp = malloc(sizeof(double) * (size_t)(L + 1) * K);
    if (!m->A || !m->B || !c || (reflect && !cp)) {
        free(paths);
        free(c);
        free(cp);
        ppb_rte_ims_free(m);
        return ppb_fail(err, "rte2d: out of memory (the intensity correction)");
    }
    /* c: the source's c_{l,k} = gt^(k+1) - gt^k - gt; cp: the peak light's gt^k. */
    for (int l = 0; l <= L; l++) {
        double gt = ppb_rte_ims_moment(g, f, &G->phase, l), gk = gt; /* gt^k */
        for (int k = 0; k < K; k++) {
            c[(size_t)l * K + k] = gk * gt - gk - gt; /* c_{l, k+1} */
            if (cp)
                cp[(size_t)l * K + k] = gk;
            gk *= gt;
        }
    }
    const double *tables[3] = {c, c, cp};
    double beams[3][3] = {{P->sin_theta_l, -P->cos_theta_l, 0.0},
                          {P->sin_theta_l, P->cos_theta_l, 0.0},
                          {P->sin_theta_l, P->cos_theta_l, 0.0}};
    for (int d = 0; d < ndir; d++)
        angular_row(tables, L, K, nblock, w + 3 * d, beams, m->A + (size_t)d * m->m);
    depth_factors(paths, nn, albedo, f, reflect, K, m->B);
    free(paths);
    free(c);
    free(cp);
    return 0;
}

void ppb_rte_ims_free(ppb_rte_ims *m)
{
    free(m->A);
    free(m->B);
    memset(m, 0, sizeof *m);
}

void ppb_rte_ims_add(const ppb_rte_ims *m, int ndir, int nnodes, double *Jx)
{
    if (m->m > 0)
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, ndir, nnodes, m->m, 1.0, m->A, m->m,
                    m->B, nnodes, 1.0, Jx, nnodes);
}
