/* sort.h: ascending sort of a short array of doubles (the break points of piecewise
 * quadratures, a few benchmark timings). Insertion sort: stable, no allocation, and the fastest
 * for the handful of values it is given. NaNs are not expected. */
#ifndef PPB_SORT_H
#define PPB_SORT_H

#include <stddef.h>

void ppb_sort_doubles(double *v, size_t n);

#endif
