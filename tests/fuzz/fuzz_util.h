/* fuzz_util.h: what the fuzz targets share: the input as a file (the readers under test take a
 * path, as they do in a run). Header-only. */
#ifndef PPB_FUZZ_UTIL_H
#define PPB_FUZZ_UTIL_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

/* Writes data to one scratch file per process (under $TMPDIR) and returns its path. */
static const char *fuzz_file(const uint8_t *data, size_t size, const char *ext)
{
    static char path[512];
    if (!path[0]) {
        const char *tmp = getenv("TMPDIR");
        snprintf(path, sizeof path, "%s/ppb-fuzz-%d.%s", tmp && *tmp ? tmp : "/tmp", (int)getpid(),
                 ext);
    }
    FILE *f = fopen(path, "wb");
    if (!f)
        abort();
    if (size && fwrite(data, 1, size, f) != size)
        abort();
    fclose(f);
    return path;
}

#endif
