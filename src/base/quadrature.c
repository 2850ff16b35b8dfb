#include "base/quadrature.h"

#include <math.h>

#include "kernels/ppb_conventions.h"

/* Newton on P_q (Golub-Welsch not needed for q <= 16; the iteration converges to machine
 * precision from the Chebyshev guesses), P_q and P_q' by the three-term recurrence. */
void ppb_gauss_legendre(int q, double *x, double *w)
{
    for (int i = 0; i < q; i++) {
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
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
}
