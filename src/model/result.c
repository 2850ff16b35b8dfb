#include "model/result.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ppb_result_init(ppb_result *r, const char *method, const ppb_layout *lo, ppb_err *err)
{
    memset(r, 0, sizeof *r);
    snprintf(r->method, sizeof r->method, "%s", method);
    r->layout = *lo;
    r->radiance = calloc(lo->ncells, sizeof *r->radiance);
    r->se = calloc(lo->ncells, sizeof *r->se);
    if (!r->radiance || !r->se) {
        ppb_result_free(r);
        return ppb_fail(err, "%s: out of memory for %zu radiance cells", method, lo->ncells);
    }
    return 0;
}

int ppb_result_write_extra(const ppb_result *r, const char *dir, ppb_err *err)
{
    return r->extra.data && r->extra.write ? r->extra.write(r->extra.data, dir, err) : 0;
}

void ppb_result_free(ppb_result *r)
{
    free(r->radiance);
    free(r->se);
    r->radiance = r->se = NULL;
    if (r->extra.data && r->extra.release)
        r->extra.release(r->extra.data);
    r->extra.data = NULL;
}

void ppb_totals_complete(ppb_totals *t)
{
    if (!t->absorbed_tracked)
        t->absorbed = 1.0 - (t->R + t->T + t->sides + t->ballistic + t->specular);
}
