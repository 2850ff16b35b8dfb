#include "base/atomic_file.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int ppb_apath_begin(ppb_apath *ap, const char *path, ppb_err *err)
{
    ap->tmp[0] = '\0';
    if (snprintf(ap->path, sizeof ap->path, "%s", path) >= (int)sizeof ap->path)
        return ppb_fail(err, "%.64s...: path too long", path);
    snprintf(ap->tmp, sizeof ap->tmp, "%s.tmp.%d", path, (int)getpid());
    return 0;
}

int ppb_apath_commit(ppb_apath *ap, ppb_err *err)
{
    if (rename(ap->tmp, ap->path) != 0) {
        int e = errno;
        remove(ap->tmp);
        return ppb_fail(err, "%s: cannot rename into place: %s", ap->path, strerror(e));
    }
    return 0;
}

void ppb_apath_abort(ppb_apath *ap)
{
    if (ap->tmp[0])
        remove(ap->tmp);
}

int ppb_afile_open(ppb_afile *af, const char *path, ppb_err *err)
{
    af->f = NULL;
    if (ppb_apath_begin(&af->name, path, err))
        return -1;
    af->f = fopen(af->name.tmp, "wb");
    if (!af->f)
        return ppb_fail(err, "%s: cannot write: %s", af->name.tmp, strerror(errno));
    return 0;
}

int ppb_afile_commit(ppb_afile *af, ppb_err *err)
{
    int bad = ferror(af->f);
    if (fclose(af->f) != 0)
        bad = 1;
    af->f = NULL;
    if (bad) {
        ppb_apath_abort(&af->name);
        return ppb_fail(err, "%s: write failed", af->name.path);
    }
    return ppb_apath_commit(&af->name, err);
}

void ppb_afile_abort(ppb_afile *af)
{
    if (af->f)
        fclose(af->f);
    af->f = NULL;
    ppb_apath_abort(&af->name);
}

int ppb_mkdirs(const char *dir, ppb_err *err)
{
    char buf[PPB_PATH_MAX];
    if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf)
        return ppb_fail(err, "%.64s...: path too long", dir);
    if (!buf[0])
        return 0;
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
