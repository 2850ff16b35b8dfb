/* file_read.h: a whole file into memory, however long, for the readers that compare or hash
 * files byte for byte (sweep grids, the Slurm job's binary stamp). */
#ifndef PPB_FILE_READ_H
#define PPB_FILE_READ_H

#include <stddef.h>

/* The file's bytes, NUL-terminated (not counted in *len, which may be NULL); NULL when it
 * cannot be opened or read, or memory runs out. The caller frees it. */
char *ppb_read_file(const char *path, size_t *len);

#endif
