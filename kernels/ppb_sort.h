/* ppb_sort.h: ascending sort of a short array of doubles, for host and kernels alike: the break
 * points of a ray piece (kernels/march.cl, src/physics/maps.c) and a few benchmark timings.
 * Insertion sort: stable, no allocation, and the fastest for the handful of values it is given.
 * NaNs are not expected. */
#ifndef PPB_SORT_H
#define PPB_SORT_H

#include "ppb_conventions.h"

PPB_FN void ppb_sort_doubles(double *v, int n)
{
    for (int i = 1; i < n; i++)
        for (int k = i; k > 0 && v[k] < v[k - 1]; k--) {
            double s = v[k];
            v[k] = v[k - 1];
            v[k - 1] = s;
        }
}

#endif
