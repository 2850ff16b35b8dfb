/* selftest.cl: a tiny kernel the OpenCL layer's test runs: it evaluates the shared conventions
 * on the device so the test can check host and kernel bin the same directions the same way. */
#include "ppb_conventions.h"

__kernel void bins_of(__global const double *mu, __global const double *wt,
                      __global const double *wb, __global int *theta_bin, __global int *phi_bin,
                      int ntheta, int nphi)
{
    size_t i = get_global_id(0);
    theta_bin[i] = ppb_theta_bin(mu[i], ntheta);
    phi_bin[i] = ppb_phi_bin(wt[i], wb[i], nphi);
}
