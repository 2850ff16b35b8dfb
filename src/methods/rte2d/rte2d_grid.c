/* rte2d_grid.c: grid, folded cells, scattering, I_pp and absorption of `rte2d` (rte2d_grid.h). */
#include "methods/rte2d/rte2d_grid.h"
#include "model/config.h"

#include <cblas.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/quadrature.h"
#include "kernels/ppb_fresnel.h"
#include "physics/maps.h"
#include "physics/medium.h"
#include "physics/phase.h"
#include "physics/ppsolver.h"
#include "methods/rte2d/rte2d_beam.h"

/* x-node layout: a split at step_x when a step lies strictly inside the tube. */
static void grid_x(const ppb_scene *sc, double spacing, int *nl, int *nr, double *hxl, double *hxr)
{
    double a = -0.5 * sc->width, b = 0.5 * sc->width;
    int split = sc->step != PPB_STEP_NONE && sc->step_x > a + 1e-9 * sc->width &&
                sc->step_x < b - 1e-9 * sc->width;
    if (split) {
        *nl = (int)ceil((sc->step_x - a) / spacing - 1e-9);
        *nr = (int)ceil((b - sc->step_x) / spacing - 1e-9);
        *nl = *nl < 1 ? 1 : *nl;
        *nr = *nr < 1 ? 1 : *nr;
        *hxl = (sc->step_x - a) / *nl;
        *hxr = (b - sc->step_x) / *nr;
    } else {
        *nl = (int)ceil(sc->width / spacing - 1e-9);
        *nl = *nl < 1 ? 1 : *nl;
        *nr = 0;
        *hxl = *hxr = sc->width / *nl;
    }
}

/* y rows (rte2d_params.h): under S1 and over S2 a boundary layer of RTE_LAYER_LEVELS rows,
 * spacing / 16 doubling to spacing / 2 (depth 15/16 spacing), the middle at about spacing;
 * uniform when the layers would not leave a middle of at least one spacing. Chosen on the nodal
 * scheme rte2d had before its flat-source regions (at spacing 0.1 the layers took its
 * conservation error from -4.7e-3 to -3.3e-3, six levels gained nothing more); the regions are
 * the nodes' dual cells, so the layers refine them as well, where a grazing cell's radiance
 * rises from 0 within |mu| mfp. */
#define RTE_LAYER_LEVELS 4
static void grid_y(const ppb_scene *sc, double spacing, ppb_rte_params *P)
{
    int m = RTE_LAYER_LEVELS;
    double H = sc->height, hf = ldexp(spacing, -m), d = hf * (ldexp(1.0, m) - 1.0);
    if (m > 0 && H - 2.0 * d >= spacing) {
        P->nyl = m;
        P->hyf = hf;
        P->dlay = d;
        P->nym = (int)ceil((H - 2.0 * d) / spacing - 1e-9);
        P->hy = (H - 2.0 * d) / P->nym;
    } else {
        P->nyl = 0;
        P->dlay = 0.0;
        P->nym = (int)ceil(H / spacing - 1e-9);
        P->nym = P->nym < 1 ? 1 : P->nym;
        P->hy = P->hyf = H / P->nym;
    }
    P->ny = 2 * P->nyl + P->nym + 1;
}

/* |Omega| of class a's representative cell (the cells of a class are images of one another). */
static double cell_area(const ppb_rte_grid *G, int a)
{
    return G->dirs.area[G->rep[a] % G->dirs.n];
}

/* The tube's transported x components scaled by one factor, so that the cells' centres
 * integrate w_x^2 over the sphere exactly (4 pi / 3). The lateral spread of light, what carries
 * it from the lit part to a shadowed wall, goes with that moment (the diffusion coefficient of
 * isotropic scattering is its integral over 3 sigma_tr): the partition's centres overshoot it by
 * 3.5e-3 at 128 cells per hemisphere (1.4e-2 at 32), and shadow_step's S4 came out 0.70 % above
 * the 4e8-photon Monte Carlo (0.27 % with the factor 0.99827; the sides' total +0.36 % -> +0.11 %
 * in uniform_g0_normal). y is left as it is: there the cells are the slab solver's own, and
 * scaling it too took S1 from -0.06 % to -0.25 % against the Monte Carlo. */
static void lateral_scale(ppb_rte_grid *G)
{
    double s2 = 0.0;
    for (int a = 0; a < G->nc; a++)
        s2 += G->mult[a] * cell_area(G, a) * G->dir4[4 * a] * G->dir4[4 * a];
    double f = sqrt(4.0 * PPB_PI / 3.0 / s2);
    for (int a = 0; a < G->nc; a++)
        G->dir4[4 * a] *= f;
}

/* The walls at n > 1 (rte2d_grid.h): G->bnd. Fl is the row of p(w . w_L) cell integrals. */
static int grid_walls(ppb_rte_grid *G, const ppb_scene *sc, const double *Fl, ppb_err *err)
{
    (void)Fl;
    const ppb_rte_params *P = &G->P;
    int m = 2 * G->dirs.n;
    double *Fu = malloc(sizeof(double) * 3 * m);
    G->bnd = malloc(sizeof(double) * PPB_RTE_BND * G->nc);
    if (!Fu || !G->bnd) {
        free(Fu);
        return ppb_fail(err, "rte2d: out of memory (walls)");
    }
    /* The beam's other directions: (+sin, up), (-sin, down), (-sin, up). */
    double s = P->sin_theta_l, c = P->cos_theta_l;
    double wu[3][3] = {{s, c, 0.0}, {-s, -c, 0.0}, {-s, c, 0.0}};
    for (int k = 0; k < 3; k++)
        if (pp_phase_row_fn(&G->dirs, &G->phase, wu[k], Fu + (size_t)k * m, NULL, err)) {
            free(Fu);
            return -1;
        }
    const int q = 8;
    for (int a = 0; a < G->nc; a++) {
        int i = G->rep[a];
        double *b = G->bnd + PPB_RTE_BND * a;
        const double *c = G->dirs.centre + 3 * i;
        double my[3] = {c[0], -c[1], c[2]}, mx[3] = {-c[0], c[1], c[2]};
        b[PPB_S1] = b[PPB_S2] = G->slot[pp_dirs_cell_of(&G->dirs, my)];
        b[PPB_S3] = b[PPB_S4] = G->slot[pp_dirs_cell_of(&G->dirs, mx)];
        double lo, hi, plo, phi;
        pp_dirs_bounds(&G->dirs, i, &lo, &hi, &plo, &phi);
        double alo = fmin(fabs(lo), fabs(hi)), ahi = fmax(fabs(lo), fabs(hi));
        b[4 + PPB_S1] = b[4 + PPB_S2] = pp_fresnel_ring_mean(alo, ahi, sc->n);
        const double *nd = pp_dirs_nodes(&G->dirs, i, q, err);
        if (!nd) {
            free(Fu);
            return -1;
        }
        double num = 0.0, den = 0.0;
        for (int k = 0; k < q * q; k++) {
            double ax = fabs(nd[4 * k]), w = nd[4 * k + 3] * ax;
            num += w * ppb_fresnel(ax, 1.0 / sc->n);
            den += w;
        }
        b[4 + PPB_S3] = b[4 + PPB_S4] = den > 0.0 ? num / den : 1.0;
        for (int k = 0; k < 3; k++)
            b[8 + k] = Fu[(size_t)k * m + i] / cell_area(G, a);
    }
    free(Fu);
    return 0;
}

/* w . n, n the outward normal of face PPB_S1..S4. */
static double out_cos(int face, const double *w)
{
    return face == PPB_S1 ? w[1] : face == PPB_S2 ? -w[1] : face == PPB_S3 ? -w[0] : w[0];
}

/* Does a direction w enter the cross-section through face f (move inward there)? */
static int enters(int face, const double *w)
{
    return out_cos(face, w) < 0.0;
}

/* The walls' reflection map (rte2d_grid.h, G->refl): cell b's Gauss nodes mirrored in face f,
 * each into the cell holding it, weighted by its solid angle and |w . n|; a node whose cell's
 * centre does not enter through f (a cell straddling the face's plane: its centre carries its
 * radiance out, not in) gives its share to the cells that do, by renormalising. No share left:
 * the entering cell nearest the mirrored centre takes it all. Each row sums to 1, so what is
 * reflected is exactly what reaches the wall times F. */
static int grid_reflection(ppb_rte_grid *G, ppb_err *err)
{
    const int q = 8;
    int nc = G->nc;
    G->refl = calloc((size_t)4 * nc * nc, sizeof(double));
    if (!G->refl)
        return ppb_fail(err, "rte2d: out of memory (walls)");
    for (int face = 0; face < 4; face++)
        for (int b = 0; b < nc; b++) {
            double *row = G->refl + ((size_t)face * nc + b) * nc, tot = 0.0;
            const double *nd = pp_dirs_nodes(&G->dirs, G->rep[b], q, err);
            if (!nd)
                return -1;
            for (int k = 0; k < q * q; k++) {
                double m[3] = {nd[4 * k], nd[4 * k + 1], nd[4 * k + 2]};
                m[face < 2 ? 1 : 0] = -m[face < 2 ? 1 : 0];
                int c = G->slot[pp_dirs_cell_of(&G->dirs, m)];
                double wt = nd[4 * k + 3] * fabs(m[face < 2 ? 1 : 0]);
                if (enters(face, G->dir4 + 4 * c) && wt > 0.0) {
                    row[c] += wt;
                    tot += wt;
                }
            }
            if (tot > 0.0) {
                for (int c = 0; c < nc; c++)
                    row[c] /= tot;
                continue;
            }
            const double *w = G->dir4 + 4 * b;
            double m[3] = {w[0], w[1], w[2]}, best = -2.0;
            m[face < 2 ? 1 : 0] = -m[face < 2 ? 1 : 0];
            int bc = -1;
            for (int c = 0; c < nc; c++) {
                const double *v = G->dir4 + 4 * c;
                double dot = v[0] * m[0] + v[1] * m[1] + v[2] * m[2];
                if (enters(face, v) && dot > best)
                    best = dot, bc = c;
            }
            if (bc >= 0)
                row[bc] = 1.0;
        }
    return 0;
}

/* The FSRs (rte2d_grid.h): dual-cell edges at the midpoints between nodes, the faces, and
 * step_x where a node column lies on it. */
static int grid_fsr(ppb_rte_grid *G, ppb_err *err)
{
    const ppb_rte_params *P = &G->P;
    int split = P->med.tube && P->nx > P->nl + 1; /* node nl sits on step_x */
    G->nfx = P->med.tube ? P->nx + split : 1;
    G->nf = G->nfx * P->ny;
    G->nb = ppb_moc_nb(G->nfx, P->ny);
    G->fedge = malloc(sizeof(double) * (G->nfx + 1 + P->ny + 1));
    G->fsig = malloc(sizeof(double) * G->nfx);
    G->falb = malloc(sizeof(double) * G->nfx);
    G->fcol = malloc(sizeof(int) * G->nfx);
    G->farea = malloc(sizeof(double) * G->nf);
    if (!G->fedge || !G->fsig || !G->falb || !G->fcol || !G->farea)
        return ppb_fail(err, "rte2d: out of memory (regions)");
    double *fx = G->fedge, *fy = G->fedge + G->nfx + 1;
    if (!P->med.tube) {
        fx[0] = -0.5;
        fx[1] = 0.5;
        G->fcol[0] = 0;
    } else {
        int k = 0;
        fx[k] = ppb_face_line(PPB_S3, P->med.width, P->med.height);
        for (int i = 0; i < P->nx; i++) {
            if (split && i == P->nl) { /* the step column, in two */
                G->fcol[k] = i;
                fx[++k] = P->med.step_x;
            }
            G->fcol[k] = i;
            fx[++k] = i + 1 < P->nx ? 0.5 * (ppb_rte_node_x(P, i) + ppb_rte_node_x(P, i + 1))
                                    : ppb_face_line(PPB_S4, P->med.width, P->med.height);
        }
    }
    fy[0] = 0.0;
    for (int j = 1; j < P->ny; j++)
        fy[j] = 0.5 * (ppb_rte_node_y(P, j - 1) + ppb_rte_node_y(P, j));
    fy[P->ny] = ppb_face_line(PPB_S2, P->med.width, P->med.height);
    G->dmin[0] = G->dmin[1] = INFINITY;
    for (int k = 0; k < G->nfx; k++) {
        double xm = 0.5 * (fx[k] + fx[k + 1]);
        G->fsig[k] = ppb_medium_sigma_t(&P->med, xm);
        G->falb[k] = ppb_medium_albedo(&P->med, xm);
        G->dmin[0] = fmin(G->dmin[0], fx[k + 1] - fx[k]);
    }
    for (int j = 0; j < P->ny; j++) {
        G->dmin[1] = fmin(G->dmin[1], fy[j] - fy[j + 1]);
        for (int k = 0; k < G->nfx; k++)
            G->farea[j * G->nfx + k] = (fx[k + 1] - fx[k]) * (fy[j] - fy[j + 1]);
    }
    return 0;
}

size_t ppb_rte_nvec(const ppb_rte_grid *G)
{
    return (size_t)G->nc * (G->nf + G->nb + (G->P.ls ? 2 * G->nf : 0));
}

/* A face node's value from its region's average v1 (centroid d1 from the face) and the next
 * region's v2 (centroid d2): the line through both at the face, not below 0 (the radiance of a
 * direction entering there rises from 0). */
static double face_value(double v1, double v2, double d1, double d2)
{
    double v = v1 - (v2 - v1) * d1 / (d2 - d1);
    return v > 0.0 ? v : 0.0;
}

/* Node column i's dual-cell width (its FSR columns together). */
static double node_width(const ppb_rte_grid *G, int i)
{
    const double *fx = G->fedge;
    int k0 = -1, k1 = -1;
    for (int k = 0; k < G->nfx; k++)
        if (G->fcol[k] == i) {
            k0 = k0 < 0 ? k : k0;
            k1 = k;
        }
    return fx[k1 + 1] - fx[k0];
}

/* The rows' mean-preserving solve (ppb_rte_to_nodes): node values v in y such that the
 * linear interpolant's average over each node's dual cell (edges halfway between node rows, S1
 * and S2 the outer ones) is that cell's average; per row k, with d_k = |y_k - y_(k-1)| (0 past a
 * face) and len_k = (d_k + d_(k+1)) / 2 the dual cell's height, the tridiagonal system
 *     (d_k / 8) v_(k-1) + (3 (d_k + d_(k+1)) / 8) v_k + (d_(k+1) / 8) v_(k+1) = len_k avg_k
 * (diagonally dominant). The rows are the same in every column, so its elimination is done once
 * here: ymp = [a_k, len_k, 1 / den_k, c'_k] per row, Thomas's factors. */
static int rows_mean_preserving(ppb_rte_grid *G)
{
    const ppb_rte_params *P = &G->P;
    int ny = P->ny;
    G->ymp = malloc(sizeof(double) * 4 * (size_t)ny);
    if (!G->ymp)
        return -1;
    double cprev = 0.0;
    for (int k = 0; k < ny; k++) {
        double y = ppb_rte_node_y(P, k);
        double dl = k > 0 ? ppb_rte_node_y(P, k - 1) - y : 0.0;
        double dr = k < ny - 1 ? y - ppb_rte_node_y(P, k + 1) : 0.0;
        double *m = G->ymp + 4 * k, a = dl / 8.0, den = 3.0 * (dl + dr) / 8.0 - a * cprev;
        m[0] = a;
        m[1] = 0.5 * (dl + dr);
        m[2] = 1.0 / den;
        m[3] = cprev = (dr / 8.0) * m[2];
    }
    return 0;
}

/* The solve of rows_mean_preserving on column c of a node field (stride nx), in place: the
 * dual-cell averages in, the node values out, not below 0 (the radiance of a direction entering
 * at a face rises from 0 there). */
static void column_mean_preserving(const ppb_rte_grid *G, double *c, int nx)
{
    int ny = G->P.ny;
    double prev = 0.0;
    for (int k = 0; k < ny; k++) {
        const double *m = G->ymp + 4 * k;
        prev = c[(size_t)k * nx] = (m[1] * c[(size_t)k * nx] - m[0] * prev) * m[2];
    }
    for (int k = ny - 2; k >= 0; k--)
        c[(size_t)k * nx] -= G->ymp[4 * k + 3] * c[(size_t)(k + 1) * nx];
    for (int k = 0; k < ny; k++)
        c[(size_t)k * nx] = fmax(c[(size_t)k * nx], 0.0);
}

void ppb_rte_to_nodes(const ppb_rte_grid *G, const double *x, double *rad)
{
    const ppb_rte_params *P = &G->P;
    size_t stride = (size_t)G->nf + G->nb;
    int nx = P->nx, ny = P->ny;
    double wx0 = nx > 2 ? node_width(G, 0) : 0.0, wx1 = nx > 2 ? node_width(G, 1) : 0.0;
    double wxn = nx > 2 ? node_width(G, nx - 1) : 0.0, wxm = nx > 2 ? node_width(G, nx - 2) : 0.0;
    for (int a = 0; a < G->nc; a++) {
        double *r = rad + (size_t)a * G->nnodes;
        for (int j = 0; j < ny; j++) {
            const double *psi = x + a * stride + (size_t)j * G->nfx;
            const double *area = G->farea + (size_t)j * G->nfx;
            double *row = r + (size_t)j * nx;
            /* Node column i gathers FSR columns k .. m - 1 (two where i sits on the step): its
             * dual cell's average, the node's value to second order. */
            for (int k = 0, m; k < G->nfx; k = m) {
                double sum = 0.0, A = 0.0;
                for (m = k; m < G->nfx && G->fcol[m] == G->fcol[k]; m++) {
                    sum += area[m] * psi[m];
                    A += area[m];
                }
                row[G->fcol[k]] = sum / A;
            }
        }
        /* In y, where the boundary layers put the nodes off their dual cells' centres (and S1's
         * and S2's half cells' averages sit a quarter cell inside), the mean-preserving values:
         * the bilinear field the exit march reads then has the regions' own averages
         * (reference: Methods, `rte2d`). */
        for (int i = 0; ny > 1 && i < nx; i++)
            column_mean_preserving(G, r + i, nx);
        /* In x, S3's and S4's half cells: extrapolated to the face from the two regions next
         * to it (the mean-preserving values there made the sides converge slower at n > 1). */
        if (nx > 2)
            for (int j = 0; j < ny; j++) {
                double *row = r + (size_t)j * nx, v0 = row[0], vn = row[nx - 1];
                row[0] = face_value(v0, row[1], 0.5 * wx0, wx0 + 0.5 * wx1);
                row[nx - 1] = face_value(vn, row[nx - 2], 0.5 * wxn, wxn + 0.5 * wxm);
            }
    }
}

/* Edge k of face PPB_S1..S4 (rte2d_params.h's order): the FSR it borders and its length. */
static int face_edge(const ppb_rte_grid *G, int face, int k, double *len)
{
    const double *fx = G->fedge, *fy = G->fedge + G->nfx + 1;
    int nfx = G->nfx, ny = G->P.ny;
    *len = face < 2 ? fx[k + 1] - fx[k] : fy[k] - fy[k + 1];
    return face == PPB_S1   ? k
           : face == PPB_S2 ? (ny - 1) * nfx + k
           : face == PPB_S3 ? k * nfx
                            : k * nfx + nfx - 1;
}

void ppb_rte_from_nodes(const ppb_rte_grid *G, const double *rad, double *x)
{
    const ppb_rte_params *P = &G->P;
    size_t stride = (size_t)G->nf + G->nb;
    for (int a = 0; a < G->nc; a++) {
        const double *r = rad + (size_t)a * G->nnodes;
        double *psi = x + a * stride, *bout = psi + G->nf;
        for (int j = 0; j < P->ny; j++)
            for (int k = 0; k < G->nfx; k++)
                psi[j * G->nfx + k] = r[j * P->nx + G->fcol[k]];
        for (int e = 0; e < G->nb; e++)
            bout[e] = 0.0;
        for (int face = 0; face < (P->med.tube ? 4 : 2); face++) {
            int e0 = ppb_moc_edge0(G->nfx, P->ny, face), ne = ppb_moc_nedge(G->nfx, P->ny, face);
            double wn = out_cos(face, G->dir4 + 4 * a), len;
            for (int k = 0; wn > 0.0 && k < ne; k++) {
                int f = face_edge(G, face, k, &len);
                bout[e0 + k] = wn * len * psi[f];
            }
        }
    }
    /* The linear source's gradients: none (a start; the solve finds them). */
    if (P->ls)
        memset(x + (size_t)G->nc * stride, 0, sizeof(double) * 2 * (size_t)G->nc * G->nf);
}

/* Strips an FSR is cut into, along x and along y, for the beam source's first moments: each
 * strip's exact integral placed at its centre, exact for a density linear across the strips;
 * a curved one (e^{-sigma y / mu} under S1) leaves an error of order the strip's width squared
 * (ppb_rte_beam_sources). */
#define RTE_LS_STRIPS 4

/* The first moments about the rectangle's centre, x then y, of each beam pass's collision
 * integral over [x0, x1] x [y0, y1] (4 + 4 values), from RTE_LS_STRIPS strips each way. */
static void beam_moments(const ppb_rte_params *P, double x0, double x1, double y0, double y1,
                         double *mx, double *my)
{
    double hx = (x1 - x0) / RTE_LS_STRIPS, hy = (y1 - y0) / RTE_LS_STRIPS, e[4];
    for (int k = 0; k < 4; k++)
        mx[k] = my[k] = 0.0;
    for (int i = 0; i < RTE_LS_STRIPS; i++) {
        double dc = (i + 0.5 - 0.5 * RTE_LS_STRIPS);
        ppb_rte_beam_rect(P, x0 + i * hx, x0 + (i + 1) * hx, y0, y1, e);
        for (int k = 0; k < 4; k++)
            mx[k] += e[k] * dc * hx;
        ppb_rte_beam_rect(P, x0, x1, y0 + i * hy, y0 + (i + 1) * hy, e);
        for (int k = 0; k < 4; k++)
            my[k] += e[k] * dc * hy;
    }
}

int ppb_rte_beam_sources(const ppb_rte_grid *G, double *Qb, double *Qbg, double *absorbed,
                         ppb_err *err)
{
    const ppb_rte_params *P = &G->P;
    const double *fx = G->fedge, *fy = G->fedge + G->nfx + 1;
    int ls = Qbg && P->ls;
    double *E = malloc(sizeof(double) * (ls ? 12 : 4) * G->nf);
    if (!E)
        return ppb_fail(err, "rte2d: out of memory (beam sources)");
    double *Mx = E + 4 * G->nf, *My = E + 8 * G->nf;
    *absorbed = 0.0;
    for (int j = 0; j < P->ny; j++)
        for (int k = 0; k < G->nfx; k++) {
            int f = j * G->nfx + k;
            ppb_rte_beam_rect(P, fx[k], fx[k + 1], fy[j + 1], fy[j], E + 4 * f);
            double sum = E[4 * f] + E[4 * f + 1] + E[4 * f + 2] + E[4 * f + 3];
            *absorbed += (1.0 - G->falb[k]) * sum;
            if (ls)
                beam_moments(P, fx[k], fx[k + 1], fy[j + 1], fy[j], Mx + 4 * f, My + 4 * f);
        }
    for (int a = 0; a < G->nc; a++) {
        const double *bc = G->bnd ? G->bnd + PPB_RTE_BND * a : NULL;
        double cb[4] = {G->dir4[4 * a + 3], bc ? bc[8] : 0.0, bc ? bc[9] : 0.0, bc ? bc[10] : 0.0};
        for (int f = 0; f < G->nf; f++) {
            const double *e = E + 4 * f;
            double al = G->falb[f % G->nfx];
            size_t i = (size_t)a * G->nf + f;
            Qb[i] = al * (cb[0] * e[0] + cb[1] * e[1] + cb[2] * e[2] + cb[3] * e[3]) / G->farea[f];
            if (!ls)
                continue;
            /* The gradient of the linear fit: first moment over the rectangle's A w^2 / 12. */
            int k = f % G->nfx, j = f / G->nfx;
            double w = fx[k + 1] - fx[k], h = fy[j] - fy[j + 1], A = G->farea[f];
            const double *mx = Mx + 4 * f, *my = My + 4 * f;
            Qbg[2 * i] = al * (cb[0] * mx[0] + cb[1] * mx[1] + cb[2] * mx[2] + cb[3] * mx[3]) /
                         (A * w * w / 12.0);
            Qbg[2 * i + 1] = al * (cb[0] * my[0] + cb[1] * my[1] + cb[2] * my[2] + cb[3] * my[3]) /
                             (A * h * h / 12.0);
        }
    }
    free(E);
    return 0;
}

/* The first-moment correction of the cells' phase matrix (reference: Methods, `rte2d`): the
 * cell-averaged HG matrix P moves a cell's light along the cells' centres c_i with a mean
 * cosine gd = sum_i P_ij c_i.c_j (averaged over the columns j, equal cells) whose |gd| falls
 * short of |g| (averaging over cells blurs the peak): at 128 cells per hemisphere 0.49585 for
 * g = 0.5, so the transport coefficient sigma_s (1 - g) that the diffusion of light goes with
 * is 0.8 % too large. P is mixed with the identity (g > 0) or with the antipodal permutation
 * (g < 0, on the antipodal partition the solver builds there), P <- (1 - b) P + b A, with
 * b = (g - gd) / (1 - gd) or (gd - g) / (1 + gd): rows and columns still sum to 1, the
 * symmetries stay, and the mean cosine is g. b A is light scattered into its own cell (or its
 * antipode), as a delta-M truncation counts light unscattered. Returns b (0: nothing done). */
double ppb_rte_moment_fix(const pp_dirs *d, double g, double *P)
{
    int m = 2 * d->n;
    if (g == 0.0)
        return 0.0;
    double gd = 0.0;
    for (int j = 0; j < m; j++) {
        const double *cj = d->centre + 3 * j;
        for (int i = 0; i < m; i++) {
            const double *ci = d->centre + 3 * i;
            gd += P[(size_t)i * m + j] * (ci[0] * cj[0] + ci[1] * cj[1] + ci[2] * cj[2]);
        }
    }
    gd /= m;
    double b = g > 0.0 ? (g - gd) / (1.0 - gd) : (gd - g) / (1.0 + gd);
    if (!(b > 0.0 && b < 1.0))
        return 0.0;
    for (size_t k = 0; k < (size_t)m * m; k++)
        P[k] *= 1.0 - b;
    for (int j = 0; j < m; j++)
        P[(size_t)(g > 0.0 ? j : pp_dirs_antipode(d, j)) * m + j] += b;
    return b;
}

double ppb_rte_nodes(const ppb_scene *sc, double spacing)
{
    int nl = 0, nr = 0, nx = 1;
    double hl, hr;
    if (sc->geometry == PPB_GEOM_TUBE) {
        grid_x(sc, spacing, &nl, &nr, &hl, &hr);
        nx = nl + nr + 1;
    }
    ppb_rte_params Py;
    grid_y(sc, spacing, &Py);
    return (double)nx * Py.ny;
}

double ppb_rte_bytes(const ppb_scene *sc, double spacing, int directions, int restart, int ls)
{
    double nodes = ppb_rte_nodes(sc, spacing), nc = directions + sqrt(directions) + 2;
    /* Krylov vectors, the solve's work arrays (x, b, J, out x 2 for host and device) and the
     * phase matrix; the linear source triples the unknown and adds its gradients' arrays and
     * the tracks' sums. */
    double per = ls ? 3.0 * (restart + 8) + 6.0 + PPB_MOC_LS_ACC : restart + 8;
    return 8.0 * (nodes * nc * per + 4.0 * directions * directions);
}

/* The scaled medium of truncation f (ppb_rte_delta_m); 0 where not done. */
static double delta_m_scale(const ppb_scene *sc, double f, ppb_scene *out)
{
    *out = *sc;
    int albedo_step = sc->geometry == PPB_GEOM_TUBE && sc->step == PPB_STEP_ALBEDO &&
                      sc->albedo_right != sc->albedo;
    if (!(f >= 1e-12) || albedo_step)
        return 0.0;
    out->g = (sc->g - f) / (1.0 - f);
    out->sigma_t = (1.0 - sc->albedo * f) * sc->sigma_t;
    out->sigma_t_right = (1.0 - sc->albedo * f) * sc->sigma_t_right;
    out->albedo = sc->albedo * (1.0 - f) / (1.0 - sc->albedo * f);
    out->albedo_right = sc->albedo_right * (1.0 - f) / (1.0 - sc->albedo_right * f); /* unused */
    return f;
}

double ppb_rte_delta_m(const ppb_scene *sc, int directions, int order, ppb_scene *out)
{
    double L = order > 0 ? order : sqrt(2.0 * directions);
    return delta_m_scale(sc, sc->g > 0.0 ? pow(sc->g, L) : 0.0, out);
}

double ppb_rte_delta_m_series(const ppb_scene *sc, int L, ppb_scene *out, pp_phase_fn *ph)
{
    memset(ph, 0, sizeof *ph);
    ph->g = sc->g;
    L = L < 2 ? 2 : (L > PP_SERIES_MAX ? PP_SERIES_MAX : L);
    double f = ppb_rte_delta_m(sc, 0, L, out);
    if (f == 0.0)
        return 0.0;
    ph->nmom = L;
    for (int l = 0; l < L; l++)
        ph->chi[l] = (pow(sc->g, l) - f) / (1.0 - f);
    ph->chi[0] = 1.0;
    out->g = ph->chi[1];
    return f;
}

int ppb_rte_ls_applies(int source, const ppb_scene *sc)
{
    return source == PPB_RTE_SOURCE_LINEAR && sc->geometry == PPB_GEOM_TUBE;
}

int ppb_rte_moment_applies(int mode, const ppb_scene *sc, const pp_dirs *d)
{
    return mode == PPB_RTE_MOMENT_ON || (mode == PPB_RTE_MOMENT_AUTO && sc->g > 0.0 && !d->polar &&
                                         sc->geometry == PPB_GEOM_TUBE);
}

pp_dirs_spec ppb_rte_partition(const ppb_scene *sc, const pp_phase_fn *ph, int directions)
{
    pp_dirs_spec spec = {0};
    spec.antipodal = sc->g < 0;
    if (sc->n > 1.0) {
        spec.mu_snap = sqrt(1.0 - 1.0 / (sc->n * sc->n));
        spec.whole_snap = sc->geometry == PPB_GEOM_TUBE;
    }
    /* the retained function's first moment: g* of the HG, chi*_1 of a series */
    double gs = ph->nmom > 1 ? ph->chi[1] : ph->g;
    if (sc->theta_deg == 0.0 && gs > 0.0 && 1.0 - gs < sqrt(2.0 * PPB_PI / directions))
        spec.h_pole = 1.0 - gs;
    return spec;
}

int ppb_rte_grid_make(const ppb_scene *sc, double spacing, int directions, double hstep, int moment,
                      const pp_phase_fn *ph, ppb_rte_grid *G, ppb_err *err)
{
    memset(G, 0, sizeof *G);
    G->phase.g = sc->g;
    if (ph)
        G->phase = *ph;
    if (!(spacing > 0.0) || !(hstep > 0.0) || directions < 1)
        return ppb_fail(err, "rte2d: spacing, step and directions must be positive");
    int tube = sc->geometry == PPB_GEOM_TUBE;
    ppb_rte_params *P = &G->P;
    P->med = ppb_medium_of(sc);
    P->lit = ppb_lit_of(sc);
    P->sin_theta_l = ppb_scene_sin_theta_l(sc);
    P->cos_theta_l = ppb_scene_cos_theta_l(sc);
    P->tan_theta_l = ppb_scene_tan_theta_l(sc);
    if (sc->n > 1.0) { /* inside, the refracted beam (ppb_fresnel.h) */
        ppb_fresnel_beam b = ppb_fresnel_beam_in(P->cos_theta_l, sc->n);
        P->sin_theta_l = b.sin_t;
        P->cos_theta_l = b.cos_t;
        P->tan_theta_l = b.sin_t / b.cos_t;
        P->beam_in = b.irradiance;
        P->beam_fb = b.f_inside;
        P->beam_fs = ppb_fresnel(b.sin_t, 1.0 / sc->n);
        P->refl = 1;
    }
    P->hstep = hstep;
    P->d_cap = 40.0;
    P->ss_g = sc->g; /* the caller's under delta-M (ppb_rte_delta_m) */
    P->ss_w = 1.0;
    int nr = 0;
    P->nl = 0;
    P->nx = 1;
    P->hxl = P->hxr = 1.0;
    if (tube) {
        grid_x(sc, spacing, &P->nl, &nr, &P->hxl, &P->hxr);
        P->nx = P->nl + nr + 1;
    }
    grid_y(sc, spacing, P);
    G->nnodes = P->nx * P->ny;
    if (rows_mean_preserving(G))
        return ppb_fail(err, "rte2d: out of memory (grid rows)");

    pp_dirs_spec spec = ppb_rte_partition(sc, &G->phase, directions);
    if (pp_dirs_make_spec(directions, &spec, &G->dirs, err))
        return -1;
    int m = 2 * G->dirs.n;
    G->slot = malloc(sizeof(int) * m);
    G->rep = malloc(sizeof(int) * m);
    G->mult = calloc((size_t)m, sizeof(double));
    double *Pfull = malloc(sizeof(double) * m * m), *F = malloc(sizeof(double) * m);
    if (!G->slot || !G->rep || !G->mult || !Pfull || !F) {
        free(Pfull);
        free(F);
        ppb_rte_grid_free(G);
        return ppb_fail(err, "rte2d: out of memory (phase matrix, %d cells)", m);
    }
    /* One transported cell per z-mirror pair: the pair's lower index. */
    G->nc = 0;
    for (int i = 0; i < m; i++) {
        int z = pp_dirs_zmirror(&G->dirs, i);
        if (z >= i) {
            G->rep[G->nc] = i;
            G->mult[G->nc] = z == i ? 1.0 : 2.0;
            G->slot[i] = G->slot[z] = G->nc++;
        }
    }
    P->ncell = G->nc;
    G->dir4 = malloc(sizeof(double) * 4 * G->nc);
    G->Pf = calloc((size_t)G->nc * G->nc, sizeof(double));
    double wl[3] = {P->sin_theta_l, -P->cos_theta_l, 0.0};
    int rc = (G->dir4 && G->Pf) ? 0 : ppb_fail(err, "rte2d: out of memory");
    if (!rc)
        rc = pp_phase_matrix_fn(&G->dirs, &G->phase, Pfull, &G->clipped, err);
    if (!rc)
        rc = pp_phase_row_fn(&G->dirs, &G->phase, wl, F, NULL, err);
    if (!rc && ppb_rte_moment_applies(moment, sc, &G->dirs))
        G->moment_b = ppb_rte_moment_fix(&G->dirs, sc->g, Pfull);
    if (!rc) {
        for (int a = 0; a < G->nc; a++) {
            int i = G->rep[a];
            memcpy(G->dir4 + 4 * a, G->dirs.centre + 3 * i, 3 * sizeof(double));
            /* Cell average of p(w.w_L): the integral over the cell of p(w'.w_L) by symmetry. */
            G->dir4[4 * a + 3] = F[i] / cell_area(G, a);
            for (int j = 0; j < m; j++)
                G->Pf[(size_t)a * G->nc + G->slot[j]] += Pfull[(size_t)i * m + j];
        }
        if (tube)
            lateral_scale(G);
    }
    if (!rc && sc->n > 1.0)
        rc = grid_walls(G, sc, F, err);
    if (!rc)
        rc = grid_fsr(G, err);
    if (!rc && sc->n > 1.0)
        rc = grid_reflection(G, err);
    free(Pfull);
    free(F);
    if (rc)
        ppb_rte_grid_free(G);
    return rc;
}

void ppb_rte_grid_free(ppb_rte_grid *G)
{
    pp_dirs_free(&G->dirs);
    free(G->rep);
    free(G->slot);
    free(G->mult);
    free(G->dir4);
    free(G->Pf);
    free(G->bnd);
    free(G->fedge);
    free(G->refl);
    free(G->fsig);
    free(G->falb);
    free(G->fcol);
    free(G->farea);
    free(G->ymp);
    memset(G, 0, sizeof *G);
}

void ppb_rte_scatter(const ppb_rte_grid *G, const double *x, double *J, double *Jg)
{
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, G->nc, G->nf, G->nc, 1.0, G->Pf, G->nc,
                x, G->nf + G->nb, 0.0, J, G->nf);
    /* The gradients scatter as the averages do: J is linear in psi at every point. */
    if (Jg && G->P.ls)
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, G->nc, 2 * G->nf, G->nc, 1.0, G->Pf,
                    G->nc, x + (size_t)G->nc * (G->nf + G->nb), 2 * G->nf, 0.0, Jg, 2 * G->nf);
}

int ppb_rte_exit_coeffs(ppb_rte_grid *G, const double *w, int ndir, double *F, ppb_err *err)
{
    int m = 2 * G->dirs.n;
    double *row = malloc(sizeof(double) * m);
    if (!row)
        return ppb_fail(err, "rte2d: out of memory");
    memset(F, 0, sizeof(double) * (size_t)ndir * G->nc);
    for (int d = 0; d < ndir; d++) {
        if (pp_phase_row_fn(&G->dirs, &G->phase, w + 3 * d, row, NULL, err)) {
            free(row);
            return -1;
        }
        for (int j = 0; j < m; j++)
            F[(size_t)d * G->nc + G->slot[j]] += row[j];
    }
    free(row);
    return 0;
}

int ppb_rte_initial_pp(const ppb_rte_grid *G, const ppb_scene *sc, double *rad, ppb_err *err)
{
    const ppb_rte_params *P = &G->P;
    int m = 2 * G->dirs.n,
        two = P->med.tube && (P->med.step == PPB_STEP_DENSITY || P->med.step == PPB_STEP_ALBEDO);
    pp_solution *s[2] = {NULL, NULL};
    double tau0[2];
    for (int c = 0; c < 1 + two; c++) {
        double st =
            c ? (P->med.step == PPB_STEP_DENSITY ? sc->sigma_t_right : sc->sigma_t) : sc->sigma_t;
        double al =
            c ? (P->med.step == PPB_STEP_ALBEDO ? sc->albedo_right : sc->albedo) : sc->albedo;
        tau0[c] = st * sc->height;
        /* n > 1: the Fresnel slab, on the same snapped partition as the grid's. */
        pp_params pp = {tau0[c], al, sc->g,
                        sc->n > 1.0 ? ppb_scene_cos_theta_l(sc) : P->cos_theta_l, G->dirs.n};
        if (pp_solve_fresnel(&pp, sc->n > 1.0 ? sc->n : 1.0, c ? s[0] : NULL, &s[c], NULL, err)) {
            pp_free(s[0]);
            return -1;
        }
    }
    double *field = malloc(sizeof(double) * m);
    if (!field) {
        pp_free(s[0]);
        pp_free(s[1]);
        return ppb_fail(err, "rte2d: out of memory");
    }
    for (int j = 0; j < P->ny; j++)
        for (int i = 0; i < P->nx; i++) {
            int node = j * P->nx + i, lit;
            double x = ppb_rte_node_x(P, i), y = ppb_rte_node_y(P, j), D;
            ppb_rte_light(P, x, y, &D, &lit);
            int c = two && x >= P->med.step_x;
            if (lit) {
                double tau = D * P->cos_theta_l;
                pp_cell_field(s[c], tau < 0.0 ? 0.0 : (tau > tau0[c] ? tau0[c] : tau), field);
            }
            for (int a = 0; a < G->nc; a++)
                rad[(size_t)a * G->nnodes + node] = lit ? field[G->rep[a]] : 0.0;
        }
    free(field);
    pp_free(s[0]);
    pp_free(s[1]);
    return 0;
}

void ppb_rte_boundary_flux(const ppb_rte_grid *G, const double *x, double flux[4])
{
    int nfx = G->nfx, ny = G->P.ny;
    size_t stride = (size_t)G->nf + G->nb;
    for (int k = 0; k < 4; k++)
        flux[k] = 0.0;
    for (int a = 0; a < G->nc; a++) {
        const double *bout = x + a * stride + G->nf;
        const double *bc = G->bnd ? G->bnd + PPB_RTE_BND * a : NULL;
        double w = G->mult[a] * cell_area(G, a);
        for (int face = 0; face < 4; face++) {
            int e0 = ppb_moc_edge0(nfx, ny, face), ne = ppb_moc_nedge(nfx, ny, face);
            double sum = 0.0;
            for (int e = e0; e < e0 + ne; e++)
                sum += bout[e];
            /* n > 1: F of it is reflected back in (the solve's walls), 1 - F leaves. */
            flux[face] += w * (bc ? 1.0 - bc[4 + face] : 1.0) * sum;
        }
    }
}

double ppb_rte_absorbed_scattered(const ppb_rte_grid *G, const double *x)
{
    size_t stride = (size_t)G->nf + G->nb;
    double sum = 0.0;
    for (int a = 0; a < G->nc; a++) {
        const double *psi = x + a * stride;
        double s = 0.0;
        for (int f = 0; f < G->nf; f++) {
            int k = f % G->nfx;
            s += (1.0 - G->falb[k]) * G->fsig[k] * G->farea[f] * psi[f];
        }
        sum += G->mult[a] * cell_area(G, a) * s;
    }
    return sum;
}

/* Absorbed power of the beam entering at x_e, per unit power entering there. */
static double beam_path_absorbed(const ppb_scene *sc, double xe)
{
    double c = ppb_scene_cos_theta_l(sc), s = ppb_scene_sin_theta_l(sc);
    if (sc->geometry == PPB_GEOM_SLAB)
        return (1.0 - sc->albedo) * (1.0 - exp(-sc->sigma_t * sc->height / c));
    ppb_medium M = ppb_medium_of(sc);
    double lend = sc->height / c;
    if (s > 0.0) /* or through S4 first */
        lend = fmin(lend, ppb_tube_length_x(sc->width, xe, s));
    double ls = lend;
    if (s > 0.0 && xe < sc->step_x && (sc->step == PPB_STEP_DENSITY || sc->step == PPB_STEP_ALBEDO))
        ls = fmin(lend, (sc->step_x - xe) / s);
    double tau = 0.0, sum = 0.0, seg[2][2] = {{0.0, ls}, {ls, lend}};
    for (int k = 0; k < 2; k++) {
        double len = seg[k][1] - seg[k][0];
        if (len <= 0.0)
            continue;
        double st, al;
        ppb_piece_medium(&M, xe, s, seg[k][0], seg[k][1], &st, &al);
        sum += (1.0 - al) * exp(-tau) * -expm1(-st * len);
        tau += st * len;
    }
    return sum;
}

static double path_absorbed(const ppb_scene *sc, double x_entry, void *arg)
{
    (void)arg;
    return beam_path_absorbed(sc, x_entry);
}

/* n > 1: absorbed power of the refracted beam's passes in the column at x_e, per unit power
 * entering (rte2d_grid.h); arg: F_b and cos theta_t. */
static double fresnel_path_absorbed(const ppb_scene *sc, double xe, void *arg)
{
    const double *fc = arg;
    ppb_medium M = ppb_medium_of(sc); /* slab: no step, sigma_t and alpha everywhere */
    double st = ppb_medium_sigma_t(&M, xe), al = ppb_medium_albedo(&M, xe);
    double e = exp(-st * sc->height / fc[1]);
    return (1.0 - al) * (1.0 - e) / (1.0 - fc[0] * e);
}

/* n > 1, the tube at oblique incidence: the refracted beam from x_e followed through its
 * reflections off all four faces (as march.c's ballistic walk), adding on each leg (1 - alpha)
 * of what it loses, the leg split at the step plane (a straight leg crosses it at most once, so
 * each part has one sigma_t and one alpha), until what is left is below 1e-16; per unit power
 * entering. arg: the ppb_fresnel_beam. */
static double fresnel_walk_absorbed(const ppb_scene *sc, double x_e, void *arg)
{
    const ppb_fresnel_beam *b = arg;
    ppb_medium M = ppb_medium_of(sc);
    double W = sc->width, H = sc->height, fs = ppb_fresnel(b->sin_t, 1.0 / sc->n);
    double x = x_e, y = 0.0, dx = b->sin_t, dy = -b->cos_t, w = 1.0, out = 0.0;
    for (int hit = 0; hit < 100000 && w > 1e-16; hit++) {
        double l;
        int face = ppb_exit_face(1, W, H, x, y, dx, dy, &l);
        double f = ppb_face_is_side(face) ? fs : b->f_inside;
        double cut[3] = {0.0, l, l};
        int nc = 2;
        if ((sc->step == PPB_STEP_ALBEDO || sc->step == PPB_STEP_DENSITY) && dx != 0.0) {
            double ls = (sc->step_x - x) / dx;
            if (ls > 0.0 && ls < l)
                cut[1] = ls, nc = 3;
        }
        for (int k = 0; k + 1 < nc; k++) {
            double st, al;
            ppb_piece_medium(&M, x, dx, cut[k], cut[k + 1], &st, &al);
            double lost = -expm1(-st * (cut[k + 1] - cut[k]));
            out += w * (1.0 - al) * lost;
            w *= 1.0 - lost;
        }
        w *= f;
        ppb_tube_reflect(face, W, H, l, &x, &y, &dx, &dy);
    }
    return out;
}

double ppb_rte_absorbed_beam(const ppb_scene *sc)
{
    double c = ppb_scene_cos_theta_l(sc);
    if (sc->n > 1.0) {
        ppb_fresnel_beam b = ppb_fresnel_beam_in(c, sc->n);
        double fc[2] = {b.f_inside, b.cos_t}, width;
        if (sc->geometry == PPB_GEOM_SLAB)
            return c * (1.0 - b.specular) * fresnel_path_absorbed(sc, 0.0, fc);
        if (sc->theta_deg != 0.0) {
            /* By midpoints over the lit part of S1, as march.c's ballistic (maps.h). */
            const int np = PPB_LIT_MIDPOINTS;
            double sum = ppb_lit_midpoint_sum(sc, fresnel_walk_absorbed, &b, np, &width);
            return c * (1.0 - b.specular) * sum * width / np;
        }
        return c * (1.0 - b.specular) * ppb_lit_integral(sc, fresnel_path_absorbed, fc, &width);
    }
    if (sc->geometry == PPB_GEOM_SLAB)
        return c * beam_path_absorbed(sc, 0.0);
    /* Over the lit strip as ppb_ballistic_fraction integrates its own beam (maps.h). */
    double width;
    return c * ppb_lit_integral(sc, path_absorbed, NULL, &width);
}
