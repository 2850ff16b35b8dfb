#include "drivers/summary_table.h"

#include <math.h>
#include <string.h>

#include "model/metrics.h"

void ppb_summary_table_print(FILE *f, const char *name, const ppb_result *rs, int n,
                             const ppb_result *ref, const char *skip)
{
    if (!ref)
        return;
    const ppb_layout *lo = &ref->layout;
    int cap = lo->nseg[PPB_S1] > lo->nseg[PPB_S3] ? lo->nseg[PPB_S1] : lo->nseg[PPB_S3];
    if (lo->nseg[PPB_S2] > cap)
        cap = lo->nseg[PPB_S2];
    if (cap < 2)
        cap = 2;
    ppb_point pts[cap];
    int cells[PPB_NCELLS], ncells = 0, nmeasured = 0;
    for (int cell = 0; cell < PPB_NCELLS; cell++)
        if (ppb_cell_points(lo, cell, pts, cap) > 0)
            cells[ncells++] = cell;
    for (int m = 0; m < n; m++)
        nmeasured += &rs[m] != ref && !(skip && strcmp(rs[m].method, skip) == 0);
    if (nmeasured == 0 || ncells == 0)
        return;
    fprintf(f, "%s: rms_excess against %s in %% (noise_rel in parentheses; summary.csv)\n", name,
            ref->method);
    fprintf(f, "%-10s", "method");
    for (int c = 0; c < ncells; c++)
        fprintf(f, " %15s", ppb_cell_name(cells[c]));
    fputc('\n', f);
    for (int m = 0; m < n; m++) {
        if (&rs[m] == ref || (skip && strcmp(rs[m].method, skip) == 0))
            continue;
        fprintf(f, "%-10s", rs[m].method);
        for (int c = 0; c < ncells; c++) {
            int np = ppb_cell_points(lo, cells[c], pts, cap);
            ppb_rms e = ppb_rms_points(&rs[m], ref, pts, np);
            char v[64];
            snprintf(v, sizeof v, "%.2f (%.2f)", 100.0 * e.rms_excess, 100.0 * e.noise_rel);
            fprintf(f, " %15s", v);
        }
        fputc('\n', f);
    }
    fflush(f);
}
