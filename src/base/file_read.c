/* file_read.c: see file_read.h. */
#include "base/file_read.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *kind_of(mode_t m)
{
    return S_ISFIFO(m)   ? "a FIFO"
           : S_ISCHR(m)  ? "a character device"
           : S_ISBLK(m)  ? "a block device"
           : S_ISDIR(m)  ? "a directory"
           : S_ISSOCK(m) ? "a socket"
                         : "not a plain file";
}

int ppb_open_regular(const char *path, size_t max, ppb_err *err)
{
    /* O_NONBLOCK: opening a FIFO for reading returns at once instead of waiting for a
     * writer that may never come; the mode is checked on what was opened, not on the name. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return ppb_fail(err, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0) {
        int e = errno;
        close(fd);
        return ppb_fail(err, "%s: cannot stat: %s", path, strerror(e));
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        return ppb_fail(err, "%s: not a regular file (%s): not read", path, kind_of(st.st_mode));
    }
    if ((unsigned long long)st.st_size > (unsigned long long)max) {
        close(fd);
        return ppb_fail(err, "%s: %lld bytes, more than the %zu bytes read from one file", path,
                        (long long)st.st_size, max);
    }
    int fl = fcntl(fd, F_GETFL);
    if (fl < 0 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) < 0) {
        int e = errno;
        close(fd);
        return ppb_fail(err, "%s: fcntl: %s", path, strerror(e));
    }
    return fd;
}

FILE *ppb_fopen_regular(const char *path, size_t max, ppb_err *err)
{
    int fd = ppb_open_regular(path, max, err);
    if (fd < 0)
        return NULL;
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        ppb_fail(err, "%s: fdopen: %s", path, strerror(errno));
        close(fd);
    }
    return f;
}

char *ppb_read_file(const char *path, size_t *len)
{
    FILE *f = ppb_fopen_regular(path, PPB_READ_MAX, NULL);
    if (!f)
        return NULL;
    char *buf = NULL;
    size_t cap = 0, n = 0, got;
    do {
        /* Grow while less than a block is free: the last fread, returning 0, leaves n < cap,
         * so the terminating NUL always fits. A file that grows past the bound while it is
         * read (st_size was checked at open) is refused too. */
        if (n > PPB_READ_MAX) {
            free(buf);
            fclose(f);
            return NULL;
        }
        if (cap - n < 65536) {
            char *nb = realloc(buf, cap = 2 * cap + 65536);
            if (!nb) {
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = nb;
        }
        got = fread(buf + n, 1, cap - n, f);
        n += got;
    } while (got > 0);
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        return NULL;
    }
    buf[n] = '\0';
    if (len)
        *len = n;
    return buf;
}
