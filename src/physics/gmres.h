/* gmres.h: restarted GMRES (Saad and Schultz 1986; Saad, "Iterative Methods for Sparse Linear
 * Systems", 2nd ed., Alg. 6.9 with Givens rotations) for A x = b with A given as a product.
 *
 * Used by `rte2d` for (I - T S) I = I_1 (reference: Methods): T the march, S the scattering.
 * Why a Krylov solve and not diffusion synthetic acceleration: it needs nothing but the operator
 * the marcher already applies (DSA needs a diffusion discretisation consistent with the
 * long-characteristic march on every grid, step and boundary, or it diverges in optically thin
 * cells), it is insensitive to g, and its cost, restart vectors of the unknown, fits in memory.
 * Modified Gram-Schmidt; the residual the Givens rotations report is checked against the true
 * one at every restart. */
#ifndef PPB_GMRES_H
#define PPB_GMRES_H

#include <stddef.h>

#include "base/err.h"

/* y = A x; returns nonzero (with err set) to stop the solve. */
typedef int (*ppb_matvec_fn)(void *ctx, const double *x, double *y, ppb_err *err);

/* The first cycle's Arnoldi relation A V_k = V_(k+1) H_k, r_0 = b - A x_0 = beta v_1, H_k the
 * (k + 1) x k Hessenberg matrix as the Gram-Schmidt built it (before the Givens rotations):
 * with it a caller applies polynomials in A to r_0 without further products (rte2d's refinement
 * study: (I - A)^j r_0 for j <= k). Kept only when the solve ends in its first cycle (a restart
 * overwrites V); else k = 0 and V = H = NULL. */
typedef struct ppb_gmres_basis {
    int k;       /* Arnoldi steps */
    double beta; /* ||r_0|| */
    double *V;   /* [k + 1][n], orthonormal v_1 .. v_(k+1); the caller frees it */
    double *H;   /* [k + 1][k] row-major; the caller frees it */
} ppb_gmres_basis;

typedef struct ppb_gmres_opts {
    int restart;           /* Krylov vectors per cycle */
    int max_iter;          /* products A x at most */
    double tol;            /* stop when ||b - A x|| <= tol ||b|| */
    ppb_gmres_basis *keep; /* NULL, or receives the first cycle's relation (above) */
} ppb_gmres_opts;

typedef struct ppb_gmres_info {
    int iters;    /* products A x taken */
    double resid; /* ||b - A x|| / ||b|| at the end (true residual) */
    int converged;
} ppb_gmres_info;

/* Solves A x = b from the initial guess in x. Not converging within max_iter is no error (info
 * says); only a failing product or memory is. */
int ppb_gmres(size_t n, ppb_matvec_fn A, void *ctx, const double *b, double *x,
              const ppb_gmres_opts *o, ppb_gmres_info *info, ppb_err *err);

#endif
