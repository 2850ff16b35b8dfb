/* result.h: what every method produces: radiance per (surface, segment, bin) with its standard
 * error, and the totals (reference: Bins). The runner, metrics and writers only ever see
 * this struct, whatever method filled it. */
#ifndef PPB_RESULT_H
#define PPB_RESULT_H

#include "base/err.h"
#include "model/scene.h"

typedef struct ppb_totals {
    double R, T, sides, absorbed, ballistic; /* fractions of the power incident on the lit S1 */
    double specular;      /* reflected by S1 at entry (n > 1), never in radiance; 0 at n = 1 */
    int absorbed_tracked; /* 0: the writer reports absorbed = 1 - the rest (reference: Bins) */
} ppb_totals;

/* Outputs a method makes beside the common set (rte2d's refinement study, reference: Outputs):
 * written into the output set's directory with the rest, released with the result. */
typedef struct ppb_result_extra {
    void *data; /* NULL: none */
    int (*write)(const void *data, const char *dir, ppb_err *err);
    void (*release)(void *data);
} ppb_result_extra;

typedef struct ppb_result {
    char method[32];
    ppb_layout layout;
    double *radiance; /* [layout.ncells], 1/sr per E_perp, scattered light only */
    double *se;       /* [layout.ncells], standard error; 0 for deterministic methods */
    ppb_totals totals;
    int partial;       /* 1: interrupted before the full budget (Monte Carlo) */
    long long photons; /* Monte Carlo photons traced; 0 otherwise */
    ppb_result_extra extra;
} ppb_result;

int ppb_result_init(ppb_result *r, const char *method, const ppb_layout *lo, ppb_err *err);
void ppb_result_free(ppb_result *r);
/* Writes r's extra outputs into dir (nothing when it has none). */
int ppb_result_write_extra(const ppb_result *r, const char *dir, ppb_err *err);

/* Sets absorbed = 1 - (R + T + sides + ballistic + specular) when the method does not track
 * it. */
void ppb_totals_complete(ppb_totals *t);

#endif
