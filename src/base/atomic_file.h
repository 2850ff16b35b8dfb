/* atomic_file.h: outputs are written under a temporary name and renamed into place only when
 * complete, so a reader (or a resumed sweep) never sees half a file. */
#ifndef PPB_ATOMIC_FILE_H
#define PPB_ATOMIC_FILE_H

#include <stdio.h>

#include "base/err.h"

typedef struct ppb_afile {
    FILE *f;
    char path[1100], tmp[1200];
} ppb_afile;

int ppb_afile_open(ppb_afile *af, const char *path, ppb_err *err);
/* Flushes, checks for write errors, renames; on any failure removes the temporary. */
int ppb_afile_commit(ppb_afile *af, ppb_err *err);
void ppb_afile_abort(ppb_afile *af);

/* mkdir -p. */
int ppb_mkdirs(const char *dir, ppb_err *err);

#endif
