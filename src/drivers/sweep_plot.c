#include "drivers/sweep_plot.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/registry.h"

/* Columns of sweep.csv: point, one per axis, method, rms per summary cell, ... */
#define COL_METHOD(naxes) ((naxes) + 2)
#define COL_RMS_R(naxes)  ((naxes) + 3)

/* Rows of one method whose axes beyond the first two sit at their first value, as
 * "x y rms_R rms_T" lines for gnuplot. */
static void emit_data(FILE *gp, const ppb_grid *grid, const char *csv, const char *method)
{
    FILE *f = fopen(csv, "r");
    char line[8192];
    if (!f)
        return;
    if (!fgets(line, sizeof line, f)) {
        fclose(f);
        return;
    }
    while (fgets(line, sizeof line, f)) {
        char *fields[64];
        int n = 0;
        char *rest = line;
        for (char *t = strsep(&rest, ","); t && n < 64; t = strsep(&rest, ","))
            fields[n++] = t;
        if (n <= COL_RMS_R(grid->naxes) + 1 || strcmp(fields[COL_METHOD(grid->naxes) - 1], method))
            continue;
        int keep = 1;
        for (int a = 2; a < grid->naxes; a++)
            keep &= strtod(fields[1 + a], NULL) == grid->axes[a].values[0];
        if (keep)
            fprintf(gp, "%s %s %s %s\n", fields[1], fields[2], fields[COL_RMS_R(grid->naxes) - 1],
                    fields[COL_RMS_R(grid->naxes)]);
    }
    fclose(f);
}

static int plot_method(const ppb_grid *grid, const char *dir, const char *method, ppb_err *err)
{
    char csv[1200], xname[64], yname[64];
    snprintf(csv, sizeof csv, "%s/sweep.csv", dir);
    ppb_config_key_name(grid->axes[0].key, xname, sizeof xname);
    ppb_config_key_name(grid->axes[1].key, yname, sizeof yname);
    FILE *gp = popen("gnuplot 2>/dev/null", "w");
    if (!gp)
        return ppb_fail(err, "cannot start gnuplot for the sweep heat map");
    fprintf(gp,
            "set terminal pngcairo size 900,380 noenhanced\n"
            "set output '%s/heatmap_%s.png.tmp'\n"
            "set multiplot layout 1,2 title '%s: RMS against mc at x = 0 (%%)'\n"
            "set xlabel '%s'\nset ylabel '%s'\nset palette rgb 33,13,10\nset view map\n",
            dir, method, method, xname, yname);
    for (int col = 3; col <= 4; col++) {
        fprintf(gp, "set title '%s'\n", col == 3 ? "R (S1)" : "T (S2)");
        fprintf(gp, "plot '-' using 1:2:(100*$%d) with points pt 5 ps 4 palette notitle\n", col);
        emit_data(gp, grid, csv, method);
        fprintf(gp, "e\n");
    }
    fprintf(gp, "unset multiplot\n");
    int rc = pclose(gp);
    char tmp[1300], png[1300];
    snprintf(tmp, sizeof tmp, "%s/heatmap_%s.png.tmp", dir, method);
    snprintf(png, sizeof png, "%s/heatmap_%s.png", dir, method);
    if (rc != 0 || rename(tmp, png) != 0) {
        remove(tmp);
        return ppb_fail(err, "gnuplot failed drawing %s", png);
    }
    return 0;
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
