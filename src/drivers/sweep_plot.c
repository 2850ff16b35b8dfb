/* sweep_plot.c: a sweep's plots, drawn by gnuplot (see sweep_plot.h; reference: Sweeps). */
#include "drivers/sweep_plot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"
#include "base/csv_read.h"
#include "io/plots.h"
#include "methods/registry.h"
#include "model/metrics.h"

#define MAX_ROWS_PANELS 6 /* panels of the third axis drawn; more are said in the title */

/* One row of sweep.csv reduced to what is plotted: the grid indices of the first three axes
 * and, in %, the RMS, the Monte Carlo's noise floor and the RMS beyond it (rms_excess,
 * model/metrics.h) of R_x0 and T_x0. */
typedef struct cell_row {
    int ix[3];
    double rms[2], noise[2], excess[2];
} cell_row;

static int value_index(const ppb_axis *a, double v)
{
    for (int k = 0; k < a->n; k++)
        if (a->values[k] == v)
            return k;
    return -1;
}

/* The rows of one method whose axes beyond the third sit at their first value. sweep.csv's
 * columns are found by name (sweep.c writes them); its values print each axis value exactly
 * (%.17g), so they are matched to the grid's. */
static int read_rows(const ppb_grid *grid, const char *csv, const char *method, cell_row **out,
                     int *nout, ppb_err *err)
{
    ppb_csv c;
    if (ppb_csv_open(&c, csv, err))
        return -1;
    int axis[PPB_MAX_AXES], col_method = -1, col[3][2] = {{-1, -1}, {-1, -1}, {-1, -1}}, rc = 0,
                            n = 0, cap = 0;
    static const char *const kinds[3] = {"rms", "noise", "excess"};
    cell_row *rows = NULL;
    char name[80];
    for (int a = 0; a < grid->naxes && rc == 0; a++) {
        ppb_config_key_name(grid->axes[a].key, name, sizeof name);
        rc = (axis[a] = ppb_csv_need(&c, name, err)) < 0;
    }
    for (int q = 0; q < 3; q++)
        for (int k = 0; k < 2 && rc == 0; k++) {
            snprintf(name, sizeof name, "%s_%s", kinds[q], ppb_cell_name(k));
            rc = (col[q][k] = ppb_csv_need(&c, name, err)) < 0;
        }
    if (rc == 0)
        rc = (col_method = ppb_csv_need(&c, "method", err)) < 0;
    while (rc == 0 && (rc = ppb_csv_next(&c, err)) == 1) {
        rc = 0;
        if (strcmp(ppb_csv_get(&c, col_method), method))
            continue;
        cell_row r = {{0, 0, 0}, {0, 0}, {0, 0}, {0, 0}};
        int keep = 1;
        for (int a = 0; a < grid->naxes && keep; a++) {
            int k = value_index(&grid->axes[a], strtod(ppb_csv_get(&c, axis[a]), NULL));
            keep = a < 3 ? k >= 0 : k == 0;
            if (a < 3)
                r.ix[a] = k;
        }
        if (!keep)
            continue;
        for (int k = 0; k < 2; k++) {
            r.rms[k] = 100 * strtod(ppb_csv_get(&c, col[0][k]), NULL);
            r.noise[k] = 100 * strtod(ppb_csv_get(&c, col[1][k]), NULL);
            r.excess[k] = 100 * strtod(ppb_csv_get(&c, col[2][k]), NULL);
        }
        if (n == cap) {
            cap = cap ? 2 * cap : 64;
            cell_row *grown = realloc(rows, (size_t)cap * sizeof *rows);
            if (!grown) {
                rc = ppb_fail(err, "sweep plot: out of memory");
                break;
            }
            rows = grown;
        }
        rows[n++] = r;
    }
    ppb_csv_close(&c);
    if (rc < 0 || rc == 1) {
        free(rows);
        return -1;
    }
    *out = rows;
    *nout = n;
    return 0;
}

/* gnuplot tics naming an axis's values at their grid indices (the cells are index-spaced, so a
 * non-uniform list such as 0.5, 0.9, 0.99 still gets equal cells). */
static void emit_tics(FILE *gp, const char *which, const ppb_axis *a)
{
    fprintf(gp, "set %s (", which);
    for (int k = 0; k < a->n; k++)
        fprintf(gp, "%s'%g' %d", k ? ", " : "", a->values[k], k);
    fprintf(gp, ")\n");
}

/* The heat map script of one method (its id is ARG3, data to gnuplot): a row of panels (R, T)
 * per value of the third axis. The colour and the number in a cell are the RMS beyond the Monte
 * Carlo's noise (rms_excess): an RMS within the noise is no measured error, so such a cell is
 * grey and says "noise" (the RMS alone read as an error of the method where it is the
 * reference's own noise). */
static void emit_heatmap(FILE *gp, const ppb_grid *grid, const cell_row *rows, int n)
{
    char xname[64], yname[64], zname[64] = "", rest[512] = "";
    ppb_config_key_name(grid->axes[0].key, xname, sizeof xname);
    ppb_config_key_name(grid->axes[1].key, yname, sizeof yname);
    int nz = grid->naxes >= 3 ? grid->axes[2].n : 1;
    int shown = nz <= MAX_ROWS_PANELS ? nz : MAX_ROWS_PANELS;
    if (grid->naxes >= 3)
        ppb_config_key_name(grid->axes[2].key, zname, sizeof zname);
    for (int a = 3; a < grid->naxes; a++) {
        char k[64];
        ppb_config_key_name(grid->axes[a].key, k, sizeof k);
        size_t len = strlen(rest);
        snprintf(rest + len, sizeof rest - len, "%s%s = %g", len ? ", " : "; slice: ", k,
                 grid->axes[a].values[0]);
    }
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 2; k++)
            if (rows[i].excess[k] > 0 && isfinite(rows[i].excess[k]) && rows[i].ix[2] < shown) {
                lo = fmin(lo, rows[i].excess[k]);
                hi = fmax(hi, rows[i].excess[k]);
            }
    if (!(hi >= lo))
        lo = 0, hi = 1;
    if (hi == lo)
        hi = lo + 1;
    for (int z = 0; z < shown; z++)
        for (int k = 0; k < 2; k++) {
            fprintf(gp, "$d%d_%d << EOD\n", z, k);
            for (int i = 0; i < n; i++)
                if (rows[i].ix[2] == z)
                    fprintf(gp, "%d %d %.6g %d\n", rows[i].ix[0], rows[i].ix[1], rows[i].excess[k],
                            isfinite(rows[i].rms[k]) && rows[i].excess[k] == 0);
            fprintf(gp, "EOD\n");
        }
    fprintf(gp,
            "@viridis\nset cbrange [%.6g:%.6g]\nset cblabel 'RMS beyond the MC noise (%%)' "
            "offset 1.5, 0\n",
            lo, hi);
    fprintf(gp,
            "set multiplot layout %d,2 title ARG3.': RMS against mc at x = 0 beyond the Monte "
            "Carlo noise (rms_excess, %%), values in the cells; grey: within the noise "
            "floor%s%s'\n",
            shown, rest, nz > shown ? "; the third key's first values only" : "");
    fprintf(gp, "set xrange [-0.5:%d.5]\nset yrange [-0.5:%d.5]\n", grid->axes[0].n - 1,
            grid->axes[1].n - 1);
    emit_tics(gp, "xtics", &grid->axes[0]);
    emit_tics(gp, "ytics", &grid->axes[1]);
    fprintf(gp, "set xlabel '%s'\nset ylabel '%s'\nunset key\nset tics out nomirror\n", xname,
            yname);
    /* labels white on the dark half of viridis, black on the light half */
    double mid = 0.5 * (lo + hi);
    for (int z = 0; z < shown; z++)
        for (int k = 0; k < 2; k++) {
            char zt[128] = "";
            if (grid->naxes >= 3)
                snprintf(zt, sizeof zt, ", %s = %g", zname, grid->axes[2].values[z]);
            fprintf(gp, "set title '%s%s'\n", k == 0 ? "R (S1)" : "T (S2)", zt);
            fprintf(gp,
                    "plot $d%d_%d using 1:2:3 with image, "
                    "$d%d_%d using ($4 != 0 ? $1 : NaN):2:(0.5):(0.5) with boxxyerror fs solid "
                    "noborder fc rgb '#BBBBBB', "
                    "$d%d_%d using 1:2:($4 != 0 ? 'noise' : sprintf('%%.1f', $3)):"
                    "($4 != 0 || $3 > %.6g ? 0 : 0xffffff) with labels tc rgb variable\n",
                    z, k, z, k, z, k, mid);
        }
    fprintf(gp, "unset multiplot\n");
}

/* The 1-D sweep's script: the RMS of R and T beyond the Monte Carlo's noise (rms_excess)
 * against the swept value, a line per method, and the noise floor itself dashed ($floor_k:
 * the noise is the reference's, the same in every method's row). The x range is padded so a
 * point at the first or last value is not drawn on the frame. */
static int emit_lines(FILE *gp, const ppb_config *cfg, const ppb_grid *grid, const char *csv,
                      ppb_err *err)
{
    char xname[64];
    ppb_config_key_name(grid->axes[0].key, xname, sizeof xname);
    int nm = 0;
    for (int m = 0; m < cfg->nmethods; m++) {
        const char *id = cfg->methods[m];
        if (ppb_method_find(cfg, id)->reference == 1)
            continue;
        cell_row *rows = NULL;
        int n = 0;
        if (read_rows(grid, csv, id, &rows, &n, err))
            return -1;
        for (int k = 0; k < 2; k++) {
            fprintf(gp, "$m%d_%d << EOD\n", nm, k);
            for (int i = 0; i < n; i++)
                fprintf(gp, "%.17g %.6g\n", grid->axes[0].values[rows[i].ix[0]], rows[i].excess[k]);
            fprintf(gp, "EOD\n");
            if (nm > 0)
                continue;
            fprintf(gp, "$floor%d << EOD\n", k);
            for (int i = 0; i < n; i++)
                fprintf(gp, "%.17g %.6g\n", grid->axes[0].values[rows[i].ix[0]], rows[i].noise[k]);
            fprintf(gp, "EOD\n");
        }
        free(rows);
        nm++;
    }
    fprintf(gp,
            "set multiplot layout 1,2 title 'RMS against mc at x = 0 beyond the Monte Carlo "
            "noise (rms_excess) over %s; dashed: the noise floor'\nset grid\n"
            "set xlabel '%s'\nset ylabel 'RMS beyond the MC noise (%%)'\n"
            "set key outside right top vertical\nset offsets graph 0.06, graph 0.06, graph "
            "0.06, 0\nset yrange [0:*]\n",
            xname, xname);
    for (int k = 0; k < 2; k++) {
        fprintf(gp, "set title '%s'\nplot ", k == 0 ? "R (S1)" : "T (S2)");
        int j = 0;
        for (int m = 0; m < cfg->nmethods; m++) {
            const char *id = cfg->methods[m];
            if (ppb_method_find(cfg, id)->reference == 1)
                continue;
            fprintf(gp,
                    "%s$m%d_%d using 1:2 with linespoints pt mpoint('%s') lc rgb mcolor('%s') "
                    "title '%s'",
                    j ? ", " : "", j, k, id, id, id);
            j++;
        }
        if (nm > 0)
            fprintf(gp,
                    ", $floor%d using 1:2 with lines dt 2 lw 1.5 lc rgb 'black' title 'MC "
                    "noise floor'",
                    k);
        fprintf(gp, "%s\n", j ? "" : "NaN notitle");
    }
    fprintf(gp, "unset multiplot\n");
    return 0;
}

/* Draws one figure as <base>.png and <base>.pdf: method NULL is the 1-D line plot. A figure
 * that cannot be drawn is added to fig and left out (reference: Sweeps). */
static void draw(const ppb_config *cfg, const ppb_grid *grid, const char *dir, const char *base,
                 const char *method, ppb_figures *fig)
{
    char csv[1200], why[2048];
    snprintf(csv, sizeof csv, "%s/sweep.csv", dir);
    cell_row *rows = NULL;
    int n = 0;
    ppb_err err;
    if (method && read_rows(grid, csv, method, &rows, &n, &err)) {
        ppb_figures_fail(fig, base, err.msg);
        return;
    }
    int nz = grid->naxes >= 3 ? grid->axes[2].n : 1;
    int shown = nz <= MAX_ROWS_PANELS ? nz : MAX_ROWS_PANELS;
    int failed_before = fig->nfailed;
    for (int t = 0; t < 2; t++) {
        char path[1300];
        snprintf(path, sizeof path, "%s/%s.%s", dir, base, t ? "pdf" : "png");
        char *text = NULL;
        size_t len = 0;
        FILE *gp = open_memstream(&text, &len);
        if (!gp) {
            ppb_figures_fail(fig, base, "out of memory");
            break;
        }
        int h = method ? 60 + 330 * shown : 420;
        if (t)
            fprintf(gp, "set terminal pdfcairo size %.2fin,%.2fin font ',7' noenhanced\n", 10.0,
                    h / 100.0);
        else
            fprintf(gp, "set terminal pngcairo size 1000,%d font ',10' noenhanced\n", h);
        fprintf(gp, "set output ARG1\nload ARG2\n");
        int rc = 0;
        if (method)
            emit_heatmap(gp, grid, rows, n);
        else
            rc = emit_lines(gp, cfg, grid, csv, &err);
        fclose(gp);
        if (rc)
            snprintf(why, sizeof why, "%s", err.msg);
        else
            rc = ppb_gnuplot_figure(path, text, len, method ? method : cfg->name, why, sizeof why);
        free(text);
        if (rc) {
            ppb_figures_fail(fig, base, why);
            break;
        }
    }
    if (fig->nfailed > failed_before) /* no earlier figure of the name, of other data, stays */
        for (int t = 0; t < 2; t++) {
            char path[1300];
            snprintf(path, sizeof path, "%s/%s.%s", dir, base, t ? "pdf" : "png");
            remove(path);
        }
    free(rows);
}

void ppb_sweep_heatmaps(const ppb_config *cfg, const ppb_grid *grid, const char *dir,
                        ppb_figures *fig)
{
    if (grid->naxes < 1)
        return;
    int has_reference = 0, compared = 0;
    for (int m = 0; m < cfg->nmethods; m++) {
        int ref = ppb_method_find(cfg, cfg->methods[m])->reference == 1;
        has_reference |= ref;
        compared += !ref;
    }
    /* No Monte Carlo: sweep.csv holds no RMS to draw, only totals. The Monte Carlo alone: no
     * method is measured against it, so there is no curve (gnuplot refuses an empty plot). */
    if (!has_reference || compared == 0)
        return;
    if (grid->naxes == 1) {
        draw(cfg, grid, dir, "sweep_rms", NULL, fig);
        return;
    }
    for (int m = 0; m < cfg->nmethods; m++) {
        const char *id = cfg->methods[m];
        if (ppb_method_find(cfg, id)->reference == 1)
            continue; /* the reference: its RMS against itself is empty */
        char base[128];
        snprintf(base, sizeof base, "heatmap_%s", id);
        draw(cfg, grid, dir, base, id, fig);
    }
}
