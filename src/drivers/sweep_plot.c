#include "drivers/sweep_plot.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"
#include "base/csv_read.h"
#include "methods/registry.h"
#include "model/metrics.h"

/* Rows of one method whose axes beyond the first two sit at their first value, as
 * "x y rms_R rms_T" lines for gnuplot (the RMS of summary cells 0 and 1, R and T at x = 0).
 * sweep.csv's columns are found by name (sweep.c writes them). */
static int emit_data(FILE *gp, const ppb_grid *grid, const char *csv, const char *method,
                     ppb_err *err)
{
    ppb_csv c;
    if (ppb_csv_open(&c, csv, err))
        return -1;
    int axis[PPB_MAX_AXES], col_method = -1, col_rms[2] = {-1, -1}, rc = 0;
    char name[80];
    for (int a = 0; a < grid->naxes && rc == 0; a++) {
        ppb_config_key_name(grid->axes[a].key, name, sizeof name);
        rc = (axis[a] = ppb_csv_need(&c, name, err)) < 0;
    }
    for (int k = 0; k < 2 && rc == 0; k++) {
        snprintf(name, sizeof name, "rms_%s", ppb_cell_name(k));
        rc = (col_rms[k] = ppb_csv_need(&c, name, err)) < 0;
    }
    if (rc == 0)
        rc = (col_method = ppb_csv_need(&c, "method", err)) < 0;
    while (rc == 0 && (rc = ppb_csv_next(&c, err)) == 1) {
        rc = 0;
        if (strcmp(ppb_csv_get(&c, col_method), method))
            continue;
        int keep = 1;
        for (int a = 2; a < grid->naxes; a++)
            keep &= strtod(ppb_csv_get(&c, axis[a]), NULL) == grid->axes[a].values[0];
        if (keep)
            fprintf(gp, "%s %s %s %s\n", ppb_csv_get(&c, axis[0]), ppb_csv_get(&c, axis[1]),
                    ppb_csv_get(&c, col_rms[0]), ppb_csv_get(&c, col_rms[1]));
    }
    ppb_csv_close(&c);
    return rc < 0 || rc == 1 ? -1 : 0;
}

static int plot_method(const ppb_grid *grid, const char *dir, const char *method, ppb_err *err)
{
    char csv[1200], png[1300], xname[64], yname[64];
    snprintf(csv, sizeof csv, "%s/sweep.csv", dir);
    snprintf(png, sizeof png, "%s/heatmap_%s.png", dir, method);
    ppb_config_key_name(grid->axes[0].key, xname, sizeof xname);
    ppb_config_key_name(grid->axes[1].key, yname, sizeof yname);
    ppb_apath ap; /* gnuplot opens the file by name: it writes the temporary */
    if (ppb_apath_begin(&ap, png, err))
        return -1;
    FILE *gp = popen("gnuplot 2>/dev/null", "w");
    if (!gp)
        return ppb_fail(err, "cannot start gnuplot for the sweep heat map");
    fprintf(gp,
            "set terminal pngcairo size 900,380 noenhanced\n"
            "set output '%s'\n"
            "set multiplot layout 1,2 title '%s: RMS against mc at x = 0 (%%)'\n"
            "set xlabel '%s'\nset ylabel '%s'\nset palette rgb 33,13,10\nset view map\n",
            ap.tmp, method, xname, yname);
    for (int col = 3; col <= 4; col++) {
        fprintf(gp, "set title '%s'\n", col == 3 ? "R (S1)" : "T (S2)");
        fprintf(gp, "plot '-' using 1:2:(100*$%d) with points pt 5 ps 4 palette notitle\n", col);
        if (emit_data(gp, grid, csv, method, err)) {
            pclose(gp);
            ppb_apath_abort(&ap);
            return -1;
        }
        fprintf(gp, "e\n");
    }
    fprintf(gp, "unset multiplot\n");
    if (pclose(gp) != 0) {
        ppb_apath_abort(&ap);
        return ppb_fail(err, "gnuplot failed drawing %s", png);
    }
    return ppb_apath_commit(&ap, err);
}

int ppb_sweep_heatmaps(const ppb_config *cfg, const ppb_grid *grid, const char *dir, ppb_err *err)
{
    if (grid->naxes < 2)
        return 0;
    for (int m = 0; m < cfg->nmethods; m++) {
        const char *id = cfg->methods[m];
        if (ppb_method_find(id)->reference == 1)
            continue; /* the reference: its RMS against itself is empty */
        if (plot_method(grid, dir, id, err))
            return -1;
    }
    return 0;
}
