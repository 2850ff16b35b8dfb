/* atomic_file.h: outputs are written under a temporary name and renamed into place only when
 * complete, so a reader (or a resumed sweep) never sees half a file.
 *
 * Owns the temporary name (path.tmp.<pid>: shards and jobs writing one directory never share
 * one) and the commit/abort rules. Two forms: ppb_afile for code that writes through a FILE *,
 * and ppb_apath for libraries that open the file by name themselves (OpenEXR, gnuplot): they
 * are handed apath.tmp, and the caller commits or aborts. A third, ppb_adir, does the same for
 * a whole directory (an experiment's output set): it is written under a staging name
 * beside it (dir.tmp.<pid>) and swapped into place when complete, so a reader sees the previous
 * set or the new one, never a mix. Also owns the clean-up of the temporaries a killed process
 * left (a name's <pid> no longer alive). Every failure message names the path and the OS's
 * reason. */
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
/* ppb_afile_open of dir/name, with the header line (and its newline) written: a method's own
 * CSV beside the output set's files. */
int ppb_afile_open_csv(ppb_afile *af, const char *dir, const char *name, const char *header,
                       ppb_err *err);
/* Flushes, checks for write errors, renames; on any failure removes the temporary. */
int ppb_afile_commit(ppb_afile *af, ppb_err *err);
void ppb_afile_abort(ppb_afile *af);
/* The first half of ppb_afile_commit: flushes, checks for write errors and closes, leaving the
 * complete temporary af->name.tmp for ppb_apath_commit (several files put in place together:
 * ppb_apaths_commit); on failure removes it. */
int ppb_afile_close(ppb_afile *af, ppb_err *err);
/* Renames n closed temporaries into place with SIGINT and SIGTERM held off meanwhile, so an
 * interrupt never leaves some files new and the others old; on a failure the rest are
 * removed. */
int ppb_apaths_commit(ppb_apath *const *aps, int n, ppb_err *err);

/* mkdir -p. */
int ppb_mkdirs(const char *dir, ppb_err *err);

/* A directory written whole. path is dir made absolute when it (or its parent) exists; tmp is
 * the staging directory <path>.tmp.<pid> and old <path>.old.<pid>, in the same parent so that
 * the final rename is atomic. */
typedef struct ppb_adir {
    char path[PPB_PATH_MAX], tmp[PPB_PATH_MAX + 32], old[PPB_PATH_MAX + 32];
    int made; /* tmp exists (ppb_adir_begin) */
} ppb_adir;

/* Names the directory's staging and aside names; creates nothing. Fails if dir names no
 * directory that can be replaced: a file, "/", the working directory or one above it. */
int ppb_adir_name(ppb_adir *ad, const char *dir, ppb_err *err);
/* Removes what dead processes left of this directory: staging and aside directories beside it
 * (<path>.tmp.<pid>, <path>.old.<pid>) and temporaries inside it (<name>.tmp.<pid>, at any
 * depth). A live process's are never touched: their presence fails (another run is writing
 * it), naming the process and the file. */
int ppb_adir_clean(const ppb_adir *ad, ppb_err *err);
/* Creates the parent directories and an empty staging directory ad->tmp. */
int ppb_adir_begin(ppb_adir *ad, ppb_err *err);
/* Puts the staging directory in place of path (atomically where the file system allows it:
 * renameat2 RENAME_EXCHANGE) and removes the previous directory. On failure the previous
 * directory stays as it was and the staging directory is removed. */
int ppb_adir_commit(ppb_adir *ad, ppb_err *err);
/* Removes the staging directory and all in it. */
void ppb_adir_abort(ppb_adir *ad);

/* Whether the file at path is complete, as far as its kind shows: a regular file of non-zero
 * size; a PNG ending with its IEND chunk; a PDF ending with %%EOF (the kind from the name, or
 * from the name a temporary "x.png.tmp.<pid>" stands for). A writer that ignores a
 * full disk (gnuplot's cairo) leaves a 0-byte or cut file with a success status: this finds
 * it (docs/reference.md: Outputs). Fails naming the path and what is wrong. */
int ppb_file_complete(const char *path, ppb_err *err);
/* A PDF made the same bytes by the same run: its /CreationDate (the one thing cairo writes
 * that changes from run to run) set to D:19700101000000Z, in place and of the same length, so
 * the cross-reference offsets stay true. A PDF without one is left as it is. */
int ppb_pdf_fix_date(const char *path, ppb_err *err);
/* Checks every file under dir (at any depth, never following a link) with ppb_file_complete
 * and fixes every PDF's date (ppb_pdf_fix_date). A bad file is handed to bad(rel, why, ctx)
 * (rel: its path under dir): it returns 0 when the file may be left out (it has then removed
 * it) and -1 to fail the whole check with its own message in err. */
typedef int (*ppb_bad_file_fn)(const char *rel, const char *why, void *ctx, ppb_err *err);
int ppb_dir_verify(const char *dir, ppb_bad_file_fn bad, void *ctx, ppb_err *err);

/* The pid in a temporary's name ("<name>.tmp.<pid>", or ".old.<pid>" when old is set), or 0
 * when name is no such temporary. */
long ppb_temp_pid(const char *name, int old);
/* Whether process pid exists (kill(pid, 0) succeeds or fails for a reason but ESRCH). */
int ppb_pid_alive(long pid);
/* rm -r path, never following a symbolic link; fails naming the first entry it could not
 * remove and why. */
int ppb_remove_tree(const char *path, ppb_err *err);

#endif
