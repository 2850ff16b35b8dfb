/* plots.h: an output set's figures (reference: Outputs): runs scripts/plots.sh, which draws them
 * with gnuplot from the set's CSVs and images into <dir>/plots/ and <dir>/images/ (PNG and PDF).
 * Owns the running of the script (what it plots and how is the script's) and the one way
 * ppbench runs gnuplot from C (ppb_gnuplot_run, ppb_gnuplot_figure), which a method's own
 * figures use (method.h: draw). Found as $PPBENCH_SCRIPTS/plots.sh,
 * else PPB_SCRIPT_DIR/plots.sh (the Makefile sets the source tree's scripts/), as the kernels
 * are found.
 *
 * Figures are the last and least important output (reference: Outputs, "Figures"): one that
 * cannot be drawn is said on stderr, listed in a ppb_figures and left out; it never fails the
 * run. Paths and names reach gnuplot only as data (its ARG1.. variables), never as script
 * text, so no file or experiment name can run a command through it. */
#ifndef PPB_PLOTS_H
#define PPB_PLOTS_H

#include <stddef.h>

#include "base/err.h"

/* The figures of one output set left out, for provenance.txt and stderr. */
typedef struct ppb_figures {
    const char *who; /* the prefix of the stderr lines: the experiment's name */
    /* A reason naming a file under staged (the staging directory, gone by the time it is
     * read) names it under final instead; either NULL: as it is. */
    const char *staged, *final;
    int nfailed;
    char text[4096]; /* provenance lines "figure.<path> = not drawn: <why>\n" */
} ppb_figures;

/* Records that figure (its path under the output directory, without extension) was not
 * drawn and why, and says so on stderr; a figure already recorded (its PDF after its PNG) is
 * not recorded again. */
void ppb_figures_fail(ppb_figures *f, const char *figure, const char *why);

/* The folder holding plots.sh and plot_style.gp (the style every gnuplot script loads). */
const char *ppb_plots_script_dir(void);

/* Runs gnuplot on the script text (len bytes) as `gnuplot -c`, with args[0..nargs) as its
 * ARG1..ARGn: the script takes every path and name from them. 0 when gnuplot exited 0, else
 * -1 with gnuplot's reason (its last message, or the signal that ended it) in why. */
int ppb_gnuplot_run(const char *script, size_t len, const char *const *args, int nargs, char *why,
                    size_t cap);

/* One figure drawn by gnuplot into path, atomically (ppb_apath): the script must begin with
 * its `set terminal` and then take `set output ARG1` and `load ARG2` (plot_style.gp); ARG3 is
 * name (the experiment's, for titles). The file is checked complete (ppb_file_complete)
 * before it is put in place. 0, or -1 with the reason in why (nothing left at path). */
int ppb_gnuplot_figure(const char *path, const char *script, size_t len, const char *name,
                       char *why, size_t cap);

/* Draws the figures of the output set in dir (already holding its CSVs, provenance.txt, which
 * names the experiment, and images), ref the id of the result the others were measured
 * against (NULL: none); each one not drawn is added to fig. */
void ppb_plots_write(const char *dir, const char *ref, ppb_figures *fig);

#endif
