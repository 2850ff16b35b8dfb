#include "base/quadrature.h"

#include <math.h>

#include "kernels/ppb_bin_samples.h"

/* The nodes of ppb_gauss_legendre_node (kernels/ppb_conventions.h), the one code of the rule. */
void ppb_gauss_legendre(int q, double *x, double *w)
{
    for (int i = 0; i < q; i++)
        x[i] = ppb_gauss_legendre_node(q, i, &w[i]);
}
