#include "base/atomic_file.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int ppb_afile_open(ppb_afile *af, const char *path, ppb_err *err)
{
    snprintf(af->path, sizeof af->path, "%s", path);
    snprintf(af->tmp, sizeof af->tmp, "%s.tmp.%d", path, (int)getpid());
    af->f = fopen(af->tmp, "wb");
    if (!af->f)
        return ppb_fail(err, "%s: cannot write: %s", af->tmp, strerror(errno));
    return 0;
}

int ppb_afile_commit(ppb_afile *af, ppb_err *err)
{
    int bad = ferror(af->f);
    if (fclose(af->f) != 0)
        bad = 1;
    af->f = NULL;
    if (bad) {
        remove(af->tmp);
        return ppb_fail(err, "%s: write failed", af->path);
    }
    if (rename(af->tmp, af->path) != 0) {
        int e = errno;
        remove(af->tmp);
        return ppb_fail(err, "%s: cannot rename into place: %s", af->path, strerror(e));
    }
    return 0;
}

void ppb_afile_abort(ppb_afile *af)
{
    if (af->f)
        fclose(af->f);
    af->f = NULL;
    remove(af->tmp);
}

int ppb_mkdirs(const char *dir, ppb_err *err)
{
    char buf[1100];
    snprintf(buf, sizeof buf, "%s", dir);
    for (char *p = buf + 1;; p++) {
        char c = *p;
        if (c != '/' && c != '\0')
            continue;
        *p = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            return ppb_fail(err, "%s: cannot create directory: %s", buf, strerror(errno));
        *p = c;
        if (c == '\0')
            break;
    }
    return 0;
}
