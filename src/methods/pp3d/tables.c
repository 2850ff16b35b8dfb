/* tables.c: the local slabs' integral tables of pp3d (pp3d.h; paper Eq. 14-15, Sec. 3.3). One
 * slab solution (physics/ppsolver.h) per (thickness node, albedo node), lit at normal incidence,
 * its modes' angular integrals at every angle node and their sum at every tau node. */
#include "methods/pp3d/pp3d.h"

/* ppsolver.h before anything that pulls in complex.h (march_tables.c says why). */
#include "physics/ppsolver.h"

#include <cblas.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/memory.h"
#include "base/progress.h"
#include "kernels/ppb_conventions.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The thickness nodes: the medium voxels' tau0 sorted and cut into runs of ratio at most
 * PPB_PP3D_THICK_RATIO, a node at each run's geometric middle; every voxel gets its run's node. */
static int plan_thickness(const ppb_object *o, const ppb_pp3d_map *m, ppb_pp3d_tables *t,
                          ppb_err *err)
{
    size_t nvox = (size_t)o->nx * o->ny * o->nz, nmed = 0;
    double *s = malloc((nvox ? nvox : 1) * sizeof *s);
    t->vox_thick = malloc((nvox ? nvox : 1) * sizeof *t->vox_thick);
    if (!s || !t->vox_thick) {
        free(s);
        return ppb_fail(err, "%s: pp3d: out of memory for the thickness nodes", o->name);
    }
    for (size_t v = 0; v < nvox; v++)
        if (o->mat[v])
            s[nmed++] = m->tau0[v];
    qsort(s, nmed, sizeof *s, cmp_double);
    int cap = 16;
    t->thick = malloc((size_t)cap * sizeof *t->thick);
    double *hi = malloc((size_t)cap * sizeof *hi);
    if (!t->thick || !hi) {
        free(s), free(hi);
        return ppb_fail(err, "%s: pp3d: out of memory for the thickness nodes", o->name);
    }
    t->nthick = 0;
    for (size_t i = 0; i < nmed;) {
        size_t j = i;
        while (j + 1 < nmed && s[j + 1] <= s[i] * PPB_PP3D_THICK_RATIO)
            j++;
        if (t->nthick == cap) {
            cap *= 2;
            double *a = realloc(t->thick, (size_t)cap * sizeof *a);
            double *b = a ? realloc(hi, (size_t)cap * sizeof *b) : NULL;
            if (!a || !b) {
                free(s), free(b ? b : hi);
                if (a)
                    t->thick = a;
                return ppb_fail(err, "%s: pp3d: out of memory for the thickness nodes", o->name);
            }
            t->thick = a, hi = b;
        }
        t->thick[t->nthick] = s[i] == s[j] ? s[i] : sqrt(s[i] * s[j]);
        hi[t->nthick++] = s[j];
        i = j + 1;
    }
    for (size_t v = 0; v < nvox; v++) {
        t->vox_thick[v] = 0;
        if (!o->mat[v])
            continue;
        int lo = 0, up = t->nthick - 1; /* the first run whose top reaches tau0 */
        while (lo < up) {
            int mid = (lo + up) / 2;
            if (hi[mid] >= m->tau0[v])
                up = mid;
            else
                lo = mid + 1;
        }
        t->vox_thick[v] = lo;
    }
    free(s), free(hi);
    return 0;
}

/* The albedo nodes over the range of abar (one node for one albedo: exact), as the tube's
 * (march_tables.c: plan). */
static void plan_albedo(const ppb_object *o, const ppb_pp3d_map *m, const ppb_pp_settings *pp,
                        ppb_pp3d_tables *t)
{
    size_t nvox = (size_t)o->nx * o->ny * o->nz;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t v = 0; v < nvox; v++)
        if (o->mat[v])
            lo = fmin(lo, m->abar[v]), hi = fmax(hi, m->abar[v]);
    /* One albedo: abar = (sum alpha l) / (sum l) is that albedo to rounding, one node. */
    if (!(hi - lo > 1e-12 * fabs(hi))) {
        t->nalb = 1, t->alb0 = isfinite(lo) ? lo : 0.0, t->alb_h = 1.0;
        return;
    }
    t->nalb = pp->albedos < 2 ? 2 : pp->albedos;
    t->alb0 = lo;
    t->alb_h = (hi - lo) / (t->nalb - 1);
}

/* One (thickness, albedo) block: its slab solve, A_k and b at the angle nodes, R at the tau
 * nodes. *first keeps the first solution, whose phase matrix every later solve shares. */
static int build_block(const ppb_object *o, const ppb_pp_settings *pp, ppb_pp3d_tables *t, int it,
                       int ia, pp_solution **first, ppb_err *err)
{
    double alb = t->alb0 + ia * t->alb_h, tau0 = t->thick[it];
    int ntau = t->ntau[it], nang = t->nang;
    double *R = t->R + t->off[it] + (size_t)ia * nang * ntau;
    double *Cb = t->Cb + ((size_t)it * t->nalb + ia) * nang;
    if (alb <= 0.0 || tau0 <= 0.0)
        return 0; /* no scattering, or no slab: no diffuse field */
    pp_params prm = {.tau0 = tau0,
                     .albedo = alb > 1.0 ? 1.0 : alb,
                     .g = o->g,
                     .mu0 = 1.0,
                     .directions = pp->directions};
    pp_solution *sol = NULL;
    if (pp_solve_delta_m(&prm, 1.0, pp->delta_m, *first, &sol, NULL, err))
        return -1;
    int nm = pp_nmodes(sol), cap = pp_mode_capacity(sol);
    int ne = pp->modes > 0 && pp->modes < nm ? pp->modes : nm;
    t->modes = nm, t->modes_kept = ne;
    double *lambda = malloc((size_t)cap * sizeof *lambda);
    double *tref = malloc((size_t)cap * sizeof *tref);
    double *a = malloc((size_t)cap * sizeof *a);
    double *A = malloc((size_t)nang * ne * sizeof *A);
    double *E = malloc((size_t)ntau * ne * sizeof *E);
    int rc = 0;
    if (!lambda || !tref || !a || !A || !E) {
        rc = ppb_fail(err, "%s: pp3d: out of memory for a slab's tables", o->name);
        goto done;
    }
    pp_modes(sol, lambda, tref);
    double dtau = tau0 / (ntau - 1);
    for (int i = 0; i < ntau; i++)
        for (int k = 0; k < ne; k++)
            E[(size_t)i * ne + k] = exp(lambda[k] * (i * dtau - tref[k]));
    /* The slab's J carries its albedo; the march multiplies by the local sigma_s. */
    for (int j = 0; j < nang; j++) {
        double psi = ppb_pp3d_angle_node(j, nang);
        /* The slab's frame: y is its outward normal, -w_L (ppsolver.h); w's azimuth is free. */
        double w[3] = {sin(psi), -cos(psi), 0.0}, b;
        pp_source_coeffs(sol, w, a, &b);
        Cb[j] = b / alb;
        for (int k = 0; k < ne; k++)
            A[(size_t)j * ne + k] = a[k] / alb;
    }
    /* Eq. 15: R[j][i] = sum_k A_k(theta_j) e_k(tau_i), one matrix product, and at alpha = 1 the
     * diffusion mode's linear part. */
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, nang, ntau, ne, 1.0, A, ne, E, ne, 0.0, R,
                ntau);
    double lin = pp_source_linear(sol) / alb;
    if (lin != 0.0)
        for (int j = 0; j < nang; j++)
            for (int i = 0; i < ntau; i++)
                R[(size_t)j * ntau + i] += lin * i * dtau;
done:
    free(lambda), free(tref), free(a), free(A), free(E);
    if (!*first)
        *first = sol;
    else
        pp_free(sol);
    return rc;
}

int ppb_pp3d_tables_build(const ppb_object *o, const ppb_pp3d_map *m, const ppb_pp_settings *pp,
                          double memory_limit, double held, int quiet, ppb_pp3d_tables *t,
                          ppb_err *err)
{
    memset(t, 0, sizeof *t);
    t->nang = PPB_PP3D_NANG;
    if (plan_thickness(o, m, t, err)) {
        ppb_pp3d_tables_free(t);
        return -1;
    }
    plan_albedo(o, m, pp, t);
    t->ntau = malloc((size_t)(t->nthick ? t->nthick : 1) * sizeof *t->ntau);
    t->off = malloc((size_t)(t->nthick ? t->nthick : 1) * sizeof *t->off);
    if (!t->ntau || !t->off) {
        ppb_pp3d_tables_free(t);
        return ppb_fail(err, "%s: pp3d: out of memory for the tables", o->name);
    }
    size_t total = 0;
    for (int it = 0; it < t->nthick; it++) {
        int nint = (int)ceil(t->thick[it] * PPB_PP3D_TAU_PER_MFP - 1e-9);
        t->ntau[it] = (nint < 1 ? 1 : nint) + 1;
        t->off[it] = total;
        total += (size_t)t->nalb * t->nang * t->ntau[it];
    }
    /* The tables, and a block's build: its slab solution (about 24 of M/2 x M/2 doubles,
     * march_tables.h) and the A and E matrices. */
    double n = pp->directions, ntmax = 0.0;
    for (int it = 0; it < t->nthick; it++)
        ntmax = t->ntau[it] > ntmax ? t->ntau[it] : ntmax;
    double bytes = ((double)total + (double)t->nthick * t->nalb * t->nang + 24.0 * n * n +
                    2.0 * n * (t->nang + ntmax)) *
                   sizeof(double);
    char detail[160];
    snprintf(detail, sizeof detail, "%d thickness x %d albedo nodes x %d angles, the map %.3g GB",
             t->nthick, t->nalb, t->nang, held / 1e9);
    if (ppb_memory_check(bytes + held, memory_limit, "pp3d's tables", detail, err)) {
        ppb_pp3d_tables_free(t);
        return -1;
    }
    t->R = calloc(total ? total : 1, sizeof *t->R);
    t->Cb = calloc((size_t)(t->nthick ? t->nthick : 1) * t->nalb * t->nang, sizeof *t->Cb);
    if (!t->R || !t->Cb) {
        ppb_pp3d_tables_free(t);
        return ppb_fail(err, "%s: pp3d: out of memory for %zu table entries", o->name, total);
    }
    pp_solution *first = NULL;
    ppb_progress pr;
    ppb_progress_begin(&pr, "pp3d tables", "slabs", (double)t->nthick * t->nalb, quiet);
    int rc = 0;
    for (int it = 0; it < t->nthick && !rc; it++)
        for (int ia = 0; ia < t->nalb && !rc; ia++) {
            if (ppb_interrupted())
                rc = ppb_fail(err, "%s: pp3d: interrupted", o->name);
            else
                rc = build_block(o, pp, t, it, ia, &first, err);
            ppb_progress_update(&pr, (double)it * t->nalb + ia + 1);
        }
    ppb_progress_end(&pr, (double)t->nthick * t->nalb);
    if (first)
        pp_free(first);
    if (rc)
        ppb_pp3d_tables_free(t);
    return rc;
}

void ppb_pp3d_tables_free(ppb_pp3d_tables *t)
{
    free(t->thick), free(t->ntau), free(t->off), free(t->R), free(t->Cb), free(t->vox_thick);
    memset(t, 0, sizeof *t);
}
