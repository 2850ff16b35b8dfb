/* rte2d_figure.c: rte2d's own figure (method_rte2d.h: ppb_rte2d_draw), drawn from the
 * refinement study it writes beside the output set. */
#include "methods/rte2d/method_rte2d.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"

/* plots/rte2d_refinements.{png,pdf} from rte2d_refinements.csv (rows K,cell,rms_rel): one line
 * per summary cell (a gnuplot data block each), log-log, the 1 % target dashed, the key
 * outside. S3_all is drawn wide, as S4_all (the same at normal incidence) lies on it. */
#define REF_CELLS 6
#define REF_ROWS  64
void ppb_rte2d_draw(const char *dir, const char *name, ppb_figures *fig)
{
    static const char *const cells[REF_CELLS] = {"R_x0",   "T_x0",   "S1_all",
                                                 "S2_all", "S3_all", "S4_all"};
    static const char *const colour[REF_CELLS] = {"#0072B2", "#D55E00", "#009E73",
                                                  "#CC79A7", "#56B4E9", "#000000"};
    char csv[PPB_PATH_MAX], plots[PPB_PATH_MAX], path[PPB_PATH_MAX + 64], line[256];
    ppb_err err;
    snprintf(csv, sizeof csv, "%s/rte2d_refinements.csv", dir);
    FILE *f = fopen(csv, "r");
    if (!f)
        return; /* no converged rte2d in this set */
    int K[REF_CELLS][REF_ROWS], n[REF_CELLS] = {0};
    double v[REF_CELLS][REF_ROWS];
    while (fgets(line, sizeof line, f)) {
        char cell[32];
        int k;
        double e;
        if (sscanf(line, "%d,%31[^,],%lf", &k, cell, &e) != 3)
            continue; /* the header */
        for (int c = 0; c < REF_CELLS; c++)
            if (!strcmp(cell, cells[c]) && n[c] < REF_ROWS) {
                K[c][n[c]] = k;
                v[c][n[c]++] = e;
            }
    }
    fclose(f);
    snprintf(plots, sizeof plots, "%s/plots", dir);
    if (ppb_mkdirs(plots, &err)) {
        ppb_figures_fail(fig, "plots/rte2d_refinements", err.msg);
        return;
    }
    for (int t = 0; t < 2; t++) {
        snprintf(path, sizeof path, "%s/rte2d_refinements.%s", plots, t ? "pdf" : "png");
        char *text = NULL;
        size_t len = 0;
        FILE *gp = open_memstream(&text, &len);
        if (!gp) {
            ppb_figures_fail(fig, "plots/rte2d_refinements", "out of memory");
            return;
        }
        if (t)
            fprintf(gp, "set terminal pdfcairo size 8in,4.5in font ',7' noenhanced\n");
        else
            fprintf(gp, "set terminal pngcairo size 800,450 font ',10' noenhanced\n");
        fprintf(gp, "set output ARG1\nload ARG2\n");
        for (int c = 0; c < REF_CELLS; c++) {
            fprintf(gp, "$c%d << EOD\n", c);
            for (int i = 0; i < n[c]; i++)
                fprintf(gp, "%d %.6g\n", K[c][i], 100.0 * v[c][i]);
            fprintf(gp, "EOD\n");
        }
        fprintf(gp, "set logscale xy\nset grid\nset xrange [0.8:*]\n"
                    "set key outside right top vertical title 'cell'\n"
                    "set title ARG3.': rte2d after K refinements of Eq. 5 from I_pp, RMS against "
                    "the converged solve'\n"
                    "set xlabel 'refinements K'\nset ylabel 'RMS (%%)'\n"
                    "set arrow 1 from graph 0, first 1 to graph 1, first 1 nohead dt 2 "
                    "lc rgb '#444444'\n"
                    "plot keyentry with lines dt 2 lc rgb '#444444' title '1 %%'");
        for (int c = 0; c < REF_CELLS; c++)
            if (n[c])
                fprintf(gp, ", $c%d using 1:2 with linespoints lw %g pt %d lc rgb '%s' title '%s'",
                        c, c == 4 ? 4.0 : 1.5, 4 + 2 * c, colour[c], cells[c]);
        fprintf(gp, "\n");
        fclose(gp);
        char why[512];
        int rc = ppb_gnuplot_figure(path, text, len, name, why, sizeof why);
        free(text);
        if (rc) {
            ppb_figures_fail(fig, "plots/rte2d_refinements", why);
            return;
        }
    }
}
