/* method_external.h: a method that is not ppbench's (docs/external.md): a config's
 * [method.NAME] command, run on the experiment's scene.json, its radiance.csv validated and
 * turned into a result like any built-in method's.
 *
 * The run: scene.json (io/scene_json.h) into a fresh directory under $TMPDIR, the command run
 * by /bin/sh -c with {scene} and {out} replaced by the (shell-quoted) paths of scene.json and of
 * an empty output directory, in its own process group, its stdout and stderr on ppbench's
 * stderr; a time limit (timeout, default 3600 s) and an interrupt kill the whole group. A
 * non-zero exit, a signal, or a radiance.csv that is not exactly one finite, non-negative row
 * per (sample point, bin) fails the method with file:line, and the directory is kept for
 * inspection; on success it is removed. */
#ifndef PPB_METHOD_EXTERNAL_H
#define PPB_METHOD_EXTERNAL_H

#include "methods/method.h"

#define PPB_EXTERNAL_TIMEOUT 3600.0 /* seconds, when [method.NAME] gives no timeout */

/* The registry's run function for every config-defined method: runs the [method.NAME] of
 * ctx->cfg whose NAME is out[0].method. */
int ppb_method_external(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* The form of a definition, checked when the config is loaded: its command holds {out}. */
int ppb_external_check(const ppb_config *cfg, const ppb_external_def *d, ppb_err *err);

/* Reads a radiance.csv (the columns of reference: Outputs, in order; more may follow) whose rows
 * are those of method `id` (others_ok: rows of other methods are passed over; 0: refused), into r
 * (initialised with the scene's layout): every (surface, segment, bin) once, radiance and stderr
 * finite and >= 0, s the sample point's (within a quarter segment). Fails with "path:line: reason",
 * or "path: missing row ..." naming the first missing one. Also used by `ppbench score`. */
int ppb_external_read_radiance(const char *path, const char *id, int others_ok, const ppb_scene *sc,
                               ppb_result *r, ppb_err *err);

/* ppb_external_read_radiance for a method that answers only some surfaces (docs/external.md,
 * "Partial coverage"): surfaces is a mask (bit k: S(k+1)) of those it answers, 0 for all, or
 * PPB_SURFACES_FROM_ROWS: those with at least one row (`ppbench score`, which has no config of the
 * method). A row of a surface outside the mask is refused; every row of a surface answered is
 * required; the cells of the others are NaN (not computed) in r. */
#define PPB_SURFACES_FROM_ROWS 0x100u
int ppb_external_read_radiance_on(const char *path, const char *id, int others_ok,
                                  const ppb_scene *sc, unsigned surfaces, ppb_result *r,
                                  ppb_err *err);

/* The surfaces answered (a mask of the layout's), given the line of each cell's row (seen, 0:
 * none) and the surfaces argument above. */
unsigned ppb_external_answered(const ppb_layout *lo, const long *seen, unsigned surfaces);
/* Sets every cell of the surfaces not in answered to NaN, radiance and stderr. */
void ppb_external_not_computed(ppb_result *r, unsigned answered);
/* Whether a surfaces mask leaves out a surface of the layout. */
int ppb_external_is_partial(const ppb_layout *lo, unsigned surfaces);

/* Totals of r: from totals.csv at path when it exists (the row of r's method), otherwise R, T
 * and sides integrated from the radiance (cell energy = radiance x ppb_scene_cell_measure),
 * ballistic 0 and absorbed the rest. */
int ppb_external_totals(const char *path, const ppb_scene *sc, ppb_result *r, ppb_err *err);

#endif
