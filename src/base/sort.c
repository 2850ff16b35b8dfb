#include "base/sort.h"

void ppb_sort_doubles(double *v, size_t n)
{
    for (size_t i = 1; i < n; i++)
        for (size_t k = i; k > 0 && v[k] < v[k - 1]; k--) {
            double s = v[k];
            v[k] = v[k - 1];
            v[k - 1] = s;
        }
}
