/* gmres.c: restarted GMRES with modified Gram-Schmidt and Givens rotations (gmres.h). */
#include "physics/gmres.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dot(size_t n, const double *a, const double *b)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

/* r = b - A x; returns ||r|| or -1 on a failed product. */
static double residual(size_t n, ppb_matvec_fn A, void *ctx, const double *b, const double *x,
                       double *r, ppb_err *err)
{
    if (A(ctx, x, r, err))
        return -1.0;
    for (size_t i = 0; i < n; i++)
        r[i] = b[i] - r[i];
    return sqrt(dot(n, r, r));
}

/* Column k of H for w = A v_k: modified Gram-Schmidt against v_1 .. v_(k+1), then w normalised
 * into v_(k+2). Returns h_(k+2,k+1) = ||w||; raw (when not NULL) receives the column as built. */
static double arnoldi_column(size_t n, int m, int k, double *V, double *H, double *raw)
{
    double *w = V + n * (k + 1);
    for (int j = 0; j <= k; j++) {
        double h = dot(n, w, V + n * j);
        H[j * m + k] = h;
        for (size_t i = 0; i < n; i++)
            w[i] -= h * V[n * j + i];
    }
    double hn = sqrt(dot(n, w, w));
    H[(k + 1) * m + k] = hn;
    if (hn > 0.0)
        for (size_t i = 0; i < n; i++)
            w[i] /= hn;
    if (raw)
        for (int j = 0; j <= k + 1; j++)
            raw[j * m + k] = H[j * m + k];
    return hn;
}

/* Hands the first cycle's relation to keep (gmres.h): V itself, shrunk to its k + 1 vectors,
 * and H compacted to [k + 1][k]. Returns whether V now belongs to keep. */
static int keep_basis(ppb_gmres_basis *keep, size_t n, int m, int k, double beta, double *V,
                      double *raw)
{
    keep->H = k > 0 ? malloc(sizeof(double) * (size_t)(k + 1) * k) : NULL;
    if (!keep->H)
        return 0; /* no steps, or no memory: nothing kept, the caller does without */
    for (int i = 0; i <= k; i++)
        for (int j = 0; j < k; j++)
            keep->H[i * k + j] = raw[i * m + j];
    double *Vk = realloc(V, sizeof(double) * n * (size_t)(k + 1));
    keep->k = k;
    keep->beta = beta;
    keep->V = Vk ? Vk : V;
    return 1;
}

int ppb_gmres(size_t n, ppb_matvec_fn A, void *ctx, const double *b, double *x,
              const ppb_gmres_opts *o, ppb_gmres_info *info, ppb_err *err)
{
    int m = o->restart < 1 ? 1 : o->restart;
    ppb_gmres_basis *keep = o->keep;
    memset(info, 0, sizeof *info);
    if (keep)
        memset(keep, 0, sizeof *keep);
    double bnorm = sqrt(dot(n, b, b));
    if (bnorm == 0.0) {
        memset(x, 0, n * sizeof *x);
        info->converged = 1;
        return 0;
    }
    /* Keeping the basis: one vector more, so the first cycle's closing residual does not
     * overwrite v_1, and the Hessenberg columns as built. */
    double *V = malloc(sizeof(double) * n * (size_t)(m + 1 + (keep != NULL)));
    double *H = calloc((size_t)(m + 1) * m, sizeof(double));
    double *raw = keep ? calloc((size_t)(m + 1) * m, sizeof(double)) : NULL;
    double *cs = malloc(sizeof(double) * m), *sn = malloc(sizeof(double) * m);
    double *gv = malloc(sizeof(double) * (m + 1)), *yv = malloc(sizeof(double) * m);
    if (!V || !H || !cs || !sn || !gv || !yv || (keep && !raw)) {
        free(V), free(H), free(raw), free(cs), free(sn), free(gv), free(yv);
        return ppb_fail(err, "gmres: out of memory (%d vectors of %zu)", m + 1, n);
    }
    int rc = 0, cycle = 0, steps = 0;
    double beta = residual(n, A, ctx, b, x, V, err), beta0 = beta;
    info->iters = 1;
    if (beta < 0.0)
        rc = -1;
    while (!rc) {
        info->resid = beta / bnorm;
        if (info->resid <= o->tol) {
            info->converged = 1;
            break;
        }
        if (info->iters >= o->max_iter)
            break;
        if (cycle == 1 && raw) { /* a restart: the first cycle's basis goes */
            memcpy(V, V + n * (m + 1), sizeof(double) * n);
            free(raw);
            raw = NULL;
        }
        cycle++;
        for (size_t i = 0; i < n; i++)
            V[i] /= beta;
        memset(gv, 0, sizeof(double) * (m + 1));
        gv[0] = beta;
        int k = 0;
        for (; k < m && info->iters < o->max_iter; k++) {
            if (A(ctx, V + n * k, V + n * (k + 1), err)) {
                rc = -1;
                break;
            }
            info->iters++;
            double hn = arnoldi_column(n, m, k, V, H, cycle == 1 ? raw : NULL);
            for (int j = 0; j < k; j++) { /* earlier rotations on the new column */
                double a = H[j * m + k], c = H[(j + 1) * m + k];
                H[j * m + k] = cs[j] * a + sn[j] * c;
                H[(j + 1) * m + k] = -sn[j] * a + cs[j] * c;
            }
            double a = H[k * m + k], c = H[(k + 1) * m + k], r = hypot(a, c);
            cs[k] = r > 0.0 ? a / r : 1.0;
            sn[k] = r > 0.0 ? c / r : 0.0;
            H[k * m + k] = r;
            H[(k + 1) * m + k] = 0.0;
            gv[k + 1] = -sn[k] * gv[k];
            gv[k] = cs[k] * gv[k];
            if (fabs(gv[k + 1]) <= o->tol * bnorm || hn == 0.0) {
                k++;
                break;
            }
        }
        if (rc)
            break;
        if (cycle == 1)
            steps = k;
        /* x += V y with H y = g (upper triangular k x k). */
        for (int j = k - 1; j >= 0; j--) {
            double s = gv[j];
            for (int l = j + 1; l < k; l++)
                s -= H[j * m + l] * yv[l];
            yv[j] = H[j * m + j] != 0.0 ? s / H[j * m + j] : 0.0;
        }
        for (int j = 0; j < k; j++)
            for (size_t i = 0; i < n; i++)
                x[i] += yv[j] * V[n * j + i];
        beta = residual(n, A, ctx, b, x, raw ? V + n * (m + 1) : V, err);
        info->iters++;
        if (beta < 0.0)
            rc = -1;
    }
    int kept = !rc && raw && cycle == 1 && keep_basis(keep, n, m, steps, beta0, V, raw);
    if (!kept)
        free(V);
    free(H), free(raw), free(cs), free(sn), free(gv), free(yv);
    return rc;
}
