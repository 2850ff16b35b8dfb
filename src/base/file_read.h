/* file_read.h: opening files that another program wrote (an external method's radiance.csv and
 * totals.csv, reference-cache entries, sweep grids, CSV read back by score) so that no such file
 * can block or exhaust ppbench: only a regular file is opened (a FIFO would block open() after
 * its writer exited, a link to /dev/zero never ends), and reading stops at a size bound
 * (docs/reference.md: Exit codes). */
#ifndef PPB_FILE_READ_H
#define PPB_FILE_READ_H

#include <stddef.h>
#include <stdio.h>

#include "base/err.h"

/* The most bytes ppbench reads from any one such file: 4 GiB, far above the largest output of
 * the study (a 10^6-cell radiance.csv is about 10^8 bytes). */
#define PPB_READ_MAX ((size_t)1 << 32)

/* A file descriptor open for reading on path, or -1 with "PATH: not a regular file (a FIFO):
 * not read" / "PATH: cannot open: ..." / "PATH: N bytes, more than the MAX bytes read from
 * one file". The check is on the opened file itself (fstat), and the open never waits
 * (O_NONBLOCK, cleared once the file is known to be regular). */
int ppb_open_regular(const char *path, size_t max, ppb_err *err);
/* ppb_open_regular as a stdio stream ("rb"). */
FILE *ppb_fopen_regular(const char *path, size_t max, ppb_err *err);

/* The file's bytes, NUL-terminated (not counted in *len, which may be NULL); NULL when it is
 * not a regular file, cannot be opened or read, is longer than PPB_READ_MAX, or memory runs
 * out. The caller frees it. */
char *ppb_read_file(const char *path, size_t *len);

#endif
