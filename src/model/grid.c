#include "model/grid.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

ppb_grid *ppb_grid_new(void)
{
    return calloc(1, sizeof(ppb_grid));
}

void ppb_grid_clear(ppb_grid *g)
{
    for (int a = 0; a < g->naxes; a++)
        free(g->axes[a].values);
    g->naxes = 0;
}

void ppb_grid_free(ppb_grid *g)
{
    if (!g)
        return;
    ppb_grid_clear(g);
    free(g);
}

int ppb_grid_add(ppb_grid *g, int key, const double *values, int n)
{
    if (g->naxes == PPB_MAX_AXES || n < 2 || n > PPB_MAX_LIST ||
        ppb_grid_npoints(g) > PPB_GRID_MAX_POINTS / n)
        return -1;
    double *copy = malloc((size_t)n * sizeof *copy);
    if (!copy)
        return -1;
    memcpy(copy, values, (size_t)n * sizeof *copy);
    g->axes[g->naxes++] = (ppb_axis){.key = key, .n = n, .values = copy};
    return 0;
}

void ppb_grid_remove(ppb_grid *g, int key)
{
    for (int a = 0; a < g->naxes; a++)
        if (g->axes[a].key == key) {
            free(g->axes[a].values);
            memmove(&g->axes[a], &g->axes[a + 1], (size_t)(g->naxes - a - 1) * sizeof g->axes[0]);
            g->naxes--;
            return;
        }
}

long long ppb_grid_npoints(const ppb_grid *g)
{
    long long n = 1;
    for (int a = 0; g && a < g->naxes; a++) {
        if (g->axes[a].n > 0 && n > LLONG_MAX / g->axes[a].n)
            return LLONG_MAX;
        n *= g->axes[a].n;
    }
    return n;
}

double ppb_grid_value(const ppb_grid *g, int a, long long i)
{
    /* Row-major: the last axis varies fastest, so axis a's index is i divided by the sizes of
     * the axes after it, modulo its own size. */
    for (int b = g->naxes - 1; b > a; b--)
        i /= g->axes[b].n;
    return g->axes[a].values[i % g->axes[a].n];
}
