/* plots.c: runs scripts/plots.sh on an output set (see plots.h; reference: Outputs). */
#include "io/plots.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <stdlib.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/child.h"

#ifndef PPB_SCRIPT_DIR
#define PPB_SCRIPT_DIR "scripts"
#endif

const char *ppb_plots_script_dir(void)
{
    const char *d = getenv("PPBENCH_SCRIPTS");
    return (d && *d) ? d : PPB_SCRIPT_DIR;
}

/* plots/rte2d_refinements.{png,pdf} from rte2d_refinements.csv (rows K,cell,rms_rel): one line
 * per summary cell (a gnuplot data block each), log-log, the 1 % target dashed, the key
 * outside. S3_all is drawn wide, as S4_all (the same at normal incidence) lies on it. */
#define REF_CELLS 6
#define REF_ROWS  64
static int draw_refinements(const char *dir, const char *name, ppb_err *err)
{
    static const char *const cells[REF_CELLS] = {"R_x0",   "T_x0",   "S1_all",
                                                 "S2_all", "S3_all", "S4_all"};
    static const char *const colour[REF_CELLS] = {"#0072B2", "#D55E00", "#009E73",
                                                  "#CC79A7", "#56B4E9", "#000000"};
    char csv[PPB_PATH_MAX], plots[PPB_PATH_MAX], path[PPB_PATH_MAX + 64], line[256];
    snprintf(csv, sizeof csv, "%s/rte2d_refinements.csv", dir);
    FILE *f = fopen(csv, "r");
    if (!f)
        return 0; /* no converged rte2d in this set */
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
    if (ppb_mkdirs(plots, err))
        return -1;
    for (int t = 0; t < 2; t++) {
        snprintf(path, sizeof path, "%s/rte2d_refinements.%s", plots, t ? "pdf" : "png");
        ppb_apath ap; /* gnuplot opens the file by name: it writes the temporary */
        if (ppb_apath_begin(&ap, path, err))
            return -1;
        fflush(NULL);
        FILE *gp = popen("gnuplot", "w");
        if (!gp) {
            ppb_apath_abort(&ap);
            return ppb_fail(err, "cannot start gnuplot for %s", path);
        }
        if (t)
            fprintf(gp, "set terminal pdfcairo size 8in,4.5in font ',7' noenhanced\n");
        else
            fprintf(gp, "set terminal pngcairo size 800,450 font ',10' noenhanced\n");
        fprintf(gp, "set output '%s'\nload '%s/plot_style.gp'\n", ap.tmp, ppb_plots_script_dir());
        for (int c = 0; c < REF_CELLS; c++) {
            fprintf(gp, "$c%d << EOD\n", c);
            for (int i = 0; i < n[c]; i++)
                fprintf(gp, "%d %.6g\n", K[c][i], 100.0 * v[c][i]);
            fprintf(gp, "EOD\n");
        }
        fprintf(gp,
                "set logscale xy\nset grid\nset xrange [0.8:*]\n"
                "set key outside right top vertical title 'cell'\n"
                "set title '%s: rte2d after K refinements of Eq. 5 from I_pp, RMS against "
                "the converged solve'\n"
                "set xlabel 'refinements K'\nset ylabel 'RMS (%%)'\n"
                "set arrow 1 from graph 0, first 1 to graph 1, first 1 nohead dt 2 "
                "lc rgb '#444444'\n"
                "plot keyentry with lines dt 2 lc rgb '#444444' title '1 %%'",
                name); /* config names are [A-Za-z0-9_.+-] */
        for (int c = 0; c < REF_CELLS; c++)
            if (n[c])
                fprintf(gp, ", $c%d using 1:2 with linespoints lw %g pt %d lc rgb '%s' title '%s'",
                        c, c == 4 ? 4.0 : 1.5, 4 + 2 * c, colour[c], cells[c]);
        fprintf(gp, "\n");
        if (pclose(gp) != 0) {
            ppb_apath_abort(&ap);
            return ppb_fail(err, "gnuplot failed drawing %s", path);
        }
        if (ppb_apath_commit(&ap, err))
            return -1;
    }
    return 0;
}

int ppb_plots_write(const char *dir, const char *name, ppb_err *err)
{
    char script[4096];
    snprintf(script, sizeof script, "%s/plots.sh", ppb_plots_script_dir());
    if (access(script, R_OK) != 0)
        return ppb_fail(err, "cannot read %s (the plot script; PPBENCH_SCRIPTS names its folder)",
                        script);
    /* The script's own messages go to stderr; stdout stays the caller's. Under a guard: the
     * script and what it starts die with ppbench (base/child.h). */
    char *argv[] = {"bash", script, (char *)dir, NULL};
    pid_t pid = ppb_child_spawn("bash", argv, 1, 0);
    if (pid < 0)
        return ppb_fail(err, "cannot start %s", script);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) /* an interrupt during plotting still waits for the script */
            return ppb_fail(err, "lost the plot script %s", script);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return ppb_fail(err, "%s %s failed (exit %d; is gnuplot installed?)", script, dir,
                        WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    return draw_refinements(dir, name, err);
}
