/* atomic_file.h: outputs are written under a temporary name and renamed into place only when
 * complete, so a reader (or a resumed sweep) never sees half a file.
 *
 * Owns the temporary name (path.tmp.<pid>: shards and jobs writing one directory never share
 * one) and the commit/abort rules. Two forms: ppb_afile for code that writes through a FILE *,
 * and ppb_apath for libraries that open the file by name themselves (OpenEXR, gnuplot): they
 * are handed apath.tmp, and the caller commits or aborts. */
#ifndef PPB_ATOMIC_FILE_H
#define PPB_ATOMIC_FILE_H

#include <stdio.h>

#include "base/err.h"

enum { PPB_PATH_MAX = 4096 };

typedef struct ppb_apath {
    char path[PPB_PATH_MAX], tmp[PPB_PATH_MAX + 32];
} ppb_apath;

/* Names the temporary of path; fails only if path is too long. Creates nothing. */
int ppb_apath_begin(ppb_apath *ap, const char *path, ppb_err *err);
/* Renames the temporary into place; on failure removes it. */
int ppb_apath_commit(ppb_apath *ap, ppb_err *err);
/* Removes the temporary (if it was created). */
void ppb_apath_abort(ppb_apath *ap);

typedef struct ppb_afile {
    FILE *f;
    ppb_apath name;
} ppb_afile;

int ppb_afile_open(ppb_afile *af, const char *path, ppb_err *err);
/* Flushes, checks for write errors, renames; on any failure removes the temporary. */
int ppb_afile_commit(ppb_afile *af, ppb_err *err);
void ppb_afile_abort(ppb_afile *af);

/* mkdir -p. */
int ppb_mkdirs(const char *dir, ppb_err *err);

#endif
