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

int ppb_gmres(size_t n, ppb_matvec_fn A, void *ctx, const double *b, double *x,
              const ppb_gmres_opts *o, ppb_gmres_info *info, ppb_err *err)
{
    int m = o->restart < 1 ? 1 : o->restart;
    memset(info, 0, sizeof *info);
    double bnorm = sqrt(dot(n, b, b));
    if (bnorm == 0.0) {
        memset(x, 0, n * sizeof *x);
        info->converged = 1;
        return 0;
    }
    double *V = malloc(sizeof(double) * n * (size_t)(m + 1));
    double *H = calloc((size_t)(m + 1) * m, sizeof(double));
    double *cs = malloc(sizeof(double) * m), *sn = malloc(sizeof(double) * m);
    double *gv = malloc(sizeof(double) * (m + 1)), *yv = malloc(sizeof(double) * m);
    if (!V || !H || !cs || !sn || !gv || !yv) {
        free(V), free(H), free(cs), free(sn), free(gv), free(yv);
        return ppb_fail(err, "gmres: out of memory (%d vectors of %zu)", m + 1, n);
    }
    int rc = 0;
    double beta = residual(n, A, ctx, b, x, V, err);
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
        for (size_t i = 0; i < n; i++)
            V[i] /= beta;
        memset(gv, 0, sizeof(double) * (m + 1));
        gv[0] = beta;
        int k = 0;
        for (; k < m && info->iters < o->max_iter; k++) {
            double *w = V + n * (k + 1);
            if (A(ctx, V + n * k, w, err)) {
                rc = -1;
                break;
            }
            info->iters++;
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
        beta = residual(n, A, ctx, b, x, V, err);
        info->iters++;
        if (beta < 0.0)
            rc = -1;
    }
    free(V), free(H), free(cs), free(sn), free(gv), free(yv);
    return rc;
}
