/* _GNU_SOURCE: renameat2 (RENAME_EXCHANGE), the atomic swap of two directories. */
#define _GNU_SOURCE
#include "base/atomic_file.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdlib.h>
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

int ppb_afile_open_csv(ppb_afile *af, const char *dir, const char *name, const char *header,
                       ppb_err *err)
{
    char path[PPB_PATH_MAX + 256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (ppb_afile_open(af, path, err))
        return -1;
    fprintf(af->f, "%s\n", header);
    return 0;
}

/* Why a stream's earlier write failed. errno at the time is long gone (any call since, a sqrt of
 * a negative, may have set it), so the write is tried again: what is still buffered, or one
 * byte more (the temporary is removed anyway), fails with the OS's reason. */
static int write_errno(FILE *f)
{
    clearerr(f);
    errno = 0;
    if (fflush(f) != 0)
        return errno ? errno : EIO;
    if (fputc('\n', f) == EOF || fflush(f) != 0)
        return errno ? errno : EIO;
    return 0;
}

int ppb_afile_commit(ppb_afile *af, ppb_err *err)
{
    if (ppb_afile_close(af, err))
        return -1;
    return ppb_apath_commit(&af->name, err);
}

int ppb_afile_close(ppb_afile *af, ppb_err *err)
{
    int bad = ferror(af->f) != 0, e = bad ? write_errno(af->f) : 0;
    errno = 0;
    if (!bad && fflush(af->f) != 0)
        e = errno, bad = 1;
    if (fclose(af->f) != 0 && !bad)
        e = errno, bad = 1;
    af->f = NULL;
    if (bad) {
        ppb_apath_abort(&af->name);
        return ppb_fail(err, "%s: write failed: %s", af->name.path,
                        e ? strerror(e) : "an earlier write failed (the cause has passed)");
    }
    return 0;
}

int ppb_apaths_commit(ppb_apath *const *aps, int n, ppb_err *err)
{
    sigset_t hold, old;
    sigemptyset(&hold);
    sigaddset(&hold, SIGINT);
    sigaddset(&hold, SIGTERM);
    sigprocmask(SIG_BLOCK, &hold, &old);
    int rc = 0;
    for (int i = 0; i < n; i++)
        if (rc)
            ppb_apath_abort(aps[i]);
        else
            rc = ppb_apath_commit(aps[i], err);
    sigprocmask(SIG_SETMASK, &old, NULL); /* a signal held off arrives now */
    return rc;
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

/* A pid written in decimal, the whole of s; 0 if s is not one. */
static long parse_pid(const char *s)
{
    long pid = 0;
    int digits = 0;
    for (; *s; s++, digits++) {
        if (*s < '0' || *s > '9' || digits >= 9)
            return 0;
        pid = 10 * pid + (*s - '0');
    }
    return digits > 0 ? pid : 0;
}

long ppb_temp_pid(const char *name, int old)
{
    const char *tag = old ? ".old." : ".tmp.";
    const char *p = NULL;
    for (const char *q = strstr(name, tag); q; q = strstr(q + 1, tag))
        p = q;
    return p && p != name ? parse_pid(p + 5) : 0;
}

int ppb_pid_alive(long pid)
{
    if (pid <= 0 || pid > INT_MAX)
        return 0;
    return kill((pid_t)pid, 0) == 0 || errno != ESRCH;
}

/* rm -r of dirfd/name; shown is its path for messages. */
static int remove_at(int dirfd, const char *name, const char *shown, ppb_err *err)
{
    struct stat st;
    if (fstatat(dirfd, name, &st, AT_SYMLINK_NOFOLLOW) != 0)
        return errno == ENOENT ? 0 : ppb_fail(err, "%s: cannot remove: %s", shown, strerror(errno));
    if (S_ISDIR(st.st_mode)) {
        int fd = openat(dirfd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW);
        DIR *d = fd < 0 ? NULL : fdopendir(fd);
        if (!d) {
            int e = errno;
            if (fd >= 0)
                close(fd);
            return ppb_fail(err, "%s: cannot remove: %s", shown, strerror(e));
        }
        int rc = 0;
        struct dirent *de;
        while (rc == 0 && (de = readdir(d))) {
            if (!strcmp(de->d_name, ".") || !strcmp(de->d_name, ".."))
                continue;
            char sub[PPB_PATH_MAX];
            snprintf(sub, sizeof sub, "%s/%s", shown, de->d_name);
            rc = remove_at(fd, de->d_name, sub, err);
        }
        closedir(d);
        if (rc)
            return -1;
    }
    if (unlinkat(dirfd, name, S_ISDIR(st.st_mode) ? AT_REMOVEDIR : 0) != 0 && errno != ENOENT)
        return ppb_fail(err, "%s: cannot remove: %s", shown, strerror(errno));
    return 0;
}

int ppb_remove_tree(const char *path, ppb_err *err)
{
    return remove_at(AT_FDCWD, path, path, err);
}

/* The parent directory and last name of path (which has no trailing slash). */
static void split_path(const char *path, char *parent, size_t cap, const char **base)
{
    const char *slash = strrchr(path, '/');
    if (!slash) {
        snprintf(parent, cap, ".");
        *base = path;
    } else {
        snprintf(parent, cap, "%.*s", slash == path ? 1 : (int)(slash - path), path);
        *base = slash + 1;
    }
}

int ppb_adir_name(ppb_adir *ad, const char *dir, ppb_err *err)
{
    memset(ad, 0, sizeof *ad);
    char buf[PPB_PATH_MAX], parent[PPB_PATH_MAX], abs[PATH_MAX];
    if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf)
        return ppb_fail(err, "%.64s...: path too long", dir);
    size_t len = strlen(buf);
    while (len > 1 && buf[len - 1] == '/')
        buf[--len] = '\0';
    if (!len)
        return ppb_fail(err, "the output directory is empty");
    struct stat st;
    const char *base;
    if (stat(buf, &st) == 0) {
        if (!S_ISDIR(st.st_mode))
            return ppb_fail(err, "%s: not a directory", dir);
        if (!realpath(buf, abs))
            return ppb_fail(err, "%s: %s", dir, strerror(errno));
        snprintf(ad->path, sizeof ad->path, "%s", abs);
    } else if (errno != ENOENT) {
        return ppb_fail(err, "%s: %s", dir, strerror(errno));
    } else {
        split_path(buf, parent, sizeof parent, &base);
        if (!strcmp(base, ".") || !strcmp(base, ".."))
            return ppb_fail(err, "%s: does not exist", dir);
        /* Where the parent exists, the names are made absolute as above; otherwise mkdir -p
         * makes it and nothing of a previous run can be there. */
        if (realpath(parent, abs)) {
            if (snprintf(ad->path, sizeof ad->path, "%s%s%s", abs, strcmp(abs, "/") ? "/" : "",
                         base) >= (int)sizeof ad->path)
                return ppb_fail(err, "%.64s...: path too long", dir);
        } else {
            snprintf(ad->path, sizeof ad->path, "%s", buf);
        }
    }
    if (!strcmp(ad->path, "/"))
        return ppb_fail(err, "%s: the root directory cannot be an output directory", dir);
    char cwd[PATH_MAX];
    if (ad->path[0] == '/' && realpath(".", cwd)) {
        size_t n = strlen(ad->path);
        if (!strncmp(cwd, ad->path, n) && (cwd[n] == '\0' || cwd[n] == '/'))
            return ppb_fail(err,
                            "%s: is the working directory or holds it; it cannot be "
                            "replaced by a run's outputs",
                            dir);
    }
    if (strlen(ad->path) + 24 >= sizeof ad->path)
        return ppb_fail(err, "%.64s...: path too long", dir);
    snprintf(ad->tmp, sizeof ad->tmp, "%s.tmp.%d", ad->path, (int)getpid());
    snprintf(ad->old, sizeof ad->old, "%s.old.%d", ad->path, (int)getpid());
    return 0;
}

/* Temporaries under dirfd (shown: its path), at most depth levels down: with remove unset,
 * fails on the first one of a live process; with remove set, deletes those of dead ones. */
static int clean_inside(int dirfd, const char *shown, int depth, int remove, ppb_err *err)
{
    int fd = dup(dirfd);
    DIR *d = fd < 0 ? NULL : fdopendir(fd);
    if (!d) {
        if (fd >= 0)
            close(fd);
        return ppb_fail(err, "%s: cannot read: %s", shown, strerror(errno));
    }
    rewinddir(d); /* the dup shares dirfd's offset, at the end after an earlier pass */
    int rc = 0;
    struct dirent *de;
    while (rc == 0 && (de = readdir(d))) {
        const char *name = de->d_name;
        if (!strcmp(name, ".") || !strcmp(name, ".."))
            continue;
        char sub[PPB_PATH_MAX];
        snprintf(sub, sizeof sub, "%s/%s", shown, name);
        struct stat st;
        if (fstatat(dirfd, name, &st, AT_SYMLINK_NOFOLLOW) != 0)
            continue;
        long pid = ppb_temp_pid(name, 0);
        if (S_ISDIR(st.st_mode) && !pid) {
            int sfd = depth > 0 ? openat(dirfd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW) : -1;
            if (sfd >= 0) {
                rc = clean_inside(sfd, sub, depth - 1, remove, err);
                close(sfd);
            }
        } else if (pid && pid != getpid()) {
            if (ppb_pid_alive(pid)) {
                if (!remove)
                    rc = ppb_fail(err, "%s: process %ld is writing it (%s)", shown, pid, sub);
            } else if (remove) {
                rc = remove_at(dirfd, name, sub, err);
            }
        }
    }
    closedir(d);
    return rc;
}

/* The staging and aside directories of ad->path beside it (see clean_inside for remove). */
static int clean_beside(const ppb_adir *ad, int remove, ppb_err *err)
{
    char parent[PPB_PATH_MAX];
    const char *base;
    split_path(ad->path, parent, sizeof parent, &base);
    size_t nbase = strlen(base);
    DIR *d = opendir(parent);
    if (!d)
        return errno == ENOENT ? 0 : ppb_fail(err, "%s: cannot read: %s", parent, strerror(errno));
    int rc = 0;
    struct dirent *de;
    while (rc == 0 && (de = readdir(d))) {
        const char *name = de->d_name;
        if (strncmp(name, base, nbase) || strlen(name) < nbase + 6)
            continue;
        int old = !strncmp(name + nbase, ".old.", 5);
        if (!old && strncmp(name + nbase, ".tmp.", 5))
            continue;
        long pid = parse_pid(name + nbase + 5);
        if (!pid || pid == getpid())
            continue;
        char path[PPB_PATH_MAX + 300];
        snprintf(path, sizeof path, "%s/%s", parent, name);
        if (ppb_pid_alive(pid)) {
            if (!remove)
                rc = ppb_fail(err, "%s: process %ld is writing it (%s)", ad->path, pid, path);
        } else if (remove) {
            rc = ppb_remove_tree(path, err);
        }
    }
    closedir(d);
    return rc;
}

int ppb_adir_clean(const ppb_adir *ad, ppb_err *err)
{
    int fd = open(ad->path, O_RDONLY | O_DIRECTORY);
    if (fd < 0 && errno != ENOENT)
        return ppb_fail(err, "%s: cannot read: %s", ad->path, strerror(errno));
    /* First look for a live process's, so that a refusal has removed nothing. */
    int rc = clean_beside(ad, 0, err);
    if (rc == 0 && fd >= 0)
        rc = clean_inside(fd, ad->path, 8, 0, err);
    if (rc == 0)
        rc = clean_beside(ad, 1, err);
    if (rc == 0 && fd >= 0)
        rc = clean_inside(fd, ad->path, 8, 1, err);
    if (fd >= 0)
        close(fd);
    return rc;
}

int ppb_adir_begin(ppb_adir *ad, ppb_err *err)
{
    char parent[PPB_PATH_MAX];
    const char *base;
    split_path(ad->path, parent, sizeof parent, &base);
    if (ppb_mkdirs(parent, err))
        return -1;
    /* A leftover of this pid is a dead process's (pids are reused) or of this process's own
     * failed attempt: never a live writer's. */
    if (ppb_remove_tree(ad->tmp, err))
        return -1;
    if (mkdir(ad->tmp, 0777) != 0)
        return ppb_fail(err, "%s: cannot create directory: %s", ad->tmp, strerror(errno));
    ad->made = 1;
    /* The new directory keeps the previous one's permissions. */
    struct stat st;
    if (stat(ad->path, &st) == 0 && chmod(ad->tmp, st.st_mode & 07777) != 0) {
        int e = errno;
        ppb_adir_abort(ad);
        return ppb_fail(err, "%s: cannot set permissions: %s", ad->tmp, strerror(e));
    }
    return 0;
}

int ppb_adir_commit(ppb_adir *ad, ppb_err *err)
{
    struct stat st;
    int e = 0;
    if (lstat(ad->path, &st) != 0) {
        /* No previous directory: one rename. */
        if (rename(ad->tmp, ad->path) == 0) {
            ad->made = 0;
            return 0;
        }
        e = errno;
    } else if (renameat2(AT_FDCWD, ad->tmp, AT_FDCWD, ad->path, RENAME_EXCHANGE) == 0) {
        /* Swapped in one step; the staging name now holds the previous set. */
        ad->made = 0;
        ppb_err ignored;
        ppb_remove_tree(ad->tmp, &ignored); /* a leftover is a dead pid's: the next run's */
        return 0;
    } else if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP) {
        e = errno;
    } else if (rename(ad->path, ad->old) != 0) {
        /* The file system cannot exchange: the previous directory is put aside, then the new
         * one renamed in; the window between holds no directory at path, never a mix. */
        e = errno;
    } else if (rename(ad->tmp, ad->path) != 0) {
        e = errno;
        rename(ad->old, ad->path);
    } else {
        ad->made = 0;
        ppb_err ignored;
        ppb_remove_tree(ad->old, &ignored);
        return 0;
    }
    ppb_adir_abort(ad);
    return ppb_fail(err,
                    "%s: cannot put the new outputs in place: %s (the previous ones are "
                    "kept)",
                    ad->path, strerror(e));
}

void ppb_adir_abort(ppb_adir *ad)
{
    if (!ad->made)
        return;
    ppb_err ignored;
    ppb_remove_tree(ad->tmp, &ignored);
    ad->made = 0;
}

/* Whether s ends with suffix. */
static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && !strcmp(s + n - k, suffix);
}

/* The last n bytes of the file at fd (size bytes long) into buf; 0 on success. */
static int read_tail(int fd, off_t size, unsigned char *buf, size_t n)
{
    if (size < (off_t)n)
        return -1;
    return pread(fd, buf, n, size - (off_t)n) == (ssize_t)n ? 0 : -1;
}

/* Whether path names a file of kind ext (".png"), itself or as its temporary
 * ("x.png.tmp.<pid>", what ppb_apath hands gnuplot). */
static int is_kind(const char *path, const char *ext)
{
    if (ends_with(path, ext))
        return 1;
    const char *tmp = NULL;
    for (const char *q = strstr(path, ".tmp."); q; q = strstr(q + 1, ".tmp."))
        tmp = q;
    size_t k = strlen(ext);
    return tmp && ppb_temp_pid(path, 0) && (size_t)(tmp - path) >= k && !strncmp(tmp - k, ext, k);
}

int ppb_file_complete(const char *path, ppb_err *err)
{
    static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
    int fd = open(path, O_RDONLY | O_NOFOLLOW);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        int e = errno;
        if (fd >= 0)
            close(fd);
        return ppb_fail(err, "%s: cannot read it back: %s", path, strerror(e));
    }
    const char *bad = NULL;
    unsigned char tail[64];
    if (!S_ISREG(st.st_mode))
        bad = "not a regular file";
    else if (st.st_size == 0)
        bad = "0 bytes (a full disk?)";
    else if (is_kind(path, ".png") &&
             (read_tail(fd, st.st_size, tail, 12) || memcmp(tail, iend, 12)))
        bad = "a PNG cut short (no IEND chunk at its end; a full disk?)";
    else if (is_kind(path, ".pdf")) {
        size_t n = st.st_size < 64 ? (size_t)st.st_size : 64;
        if (read_tail(fd, st.st_size, tail, n) || !memmem(tail, n, "%%EOF", 5))
            bad = "a PDF cut short (no %%EOF at its end; a full disk?)";
    }
    close(fd);
    return bad ? ppb_fail(err, "%s: incomplete: %s", path, bad) : 0;
}

int ppb_pdf_fix_date(const char *path, ppb_err *err)
{
    static const char key[] = "/CreationDate (D:", fixed[] = "19700101000000";
    FILE *f = fopen(path, "r+b");
    if (!f)
        return ppb_fail(err, "%s: cannot open: %s", path, strerror(errno));
    /* cairo writes the date in the Info dictionary near the end; a PDF here is small (a
     * figure), so the whole file is read. */
    char *buf = NULL;
    size_t cap = 0, len = 0, got;
    int rc = 0;
    do {
        if (len + 65536 > cap) {
            char *grown = realloc(buf, cap = 2 * cap + 65536);
            if (!grown) {
                rc = ppb_fail(err, "%s: out of memory", path);
                break;
            }
            buf = grown;
        }
        got = fread(buf + len, 1, cap - len, f);
        len += got;
    } while (got > 0);
    char *at = rc ? NULL : memmem(buf, len, key, sizeof key - 1);
    if (at && (size_t)(at - buf) + sizeof key - 1 + 14 <= len) {
        long off = (long)(at - buf) + (long)sizeof key - 1;
        if (fseek(f, off, SEEK_SET) != 0 || fwrite(fixed, 1, 14, f) != 14)
            rc = ppb_fail(err, "%s: cannot fix its date: %s", path, strerror(errno));
    }
    free(buf);
    if (fclose(f) != 0 && rc == 0)
        rc = ppb_fail(err, "%s: cannot fix its date: %s", path, strerror(errno));
    return rc;
}

/* ppb_dir_verify below dir/rel (rel "" at the top). */
static int verify_at(const char *dir, const char *rel, ppb_bad_file_fn bad, void *ctx, ppb_err *err)
{
    char path[PPB_PATH_MAX + 512];
    snprintf(path, sizeof path, "%s%s%s", dir, rel[0] ? "/" : "", rel);
    DIR *d = opendir(path);
    if (!d)
        return ppb_fail(err, "%s: cannot read: %s", path, strerror(errno));
    int rc = 0;
    struct dirent *de;
    while (rc == 0 && (de = readdir(d))) {
        if (!strcmp(de->d_name, ".") || !strcmp(de->d_name, ".."))
            continue;
        char sub[512], full[PPB_PATH_MAX + 1024];
        snprintf(sub, sizeof sub, "%s%s%s", rel, rel[0] ? "/" : "", de->d_name);
        snprintf(full, sizeof full, "%s/%s", dir, sub);
        struct stat st;
        if (lstat(full, &st) == 0 && S_ISDIR(st.st_mode)) {
            rc = verify_at(dir, sub, bad, ctx, err);
            continue;
        }
        ppb_err why;
        if (ppb_file_complete(full, &why) == 0 &&
            (!ends_with(full, ".pdf") || ppb_pdf_fix_date(full, &why) == 0))
            continue;
        rc = bad(sub, why.msg, ctx, err);
    }
    closedir(d);
    return rc;
}

int ppb_dir_verify(const char *dir, ppb_bad_file_fn bad, void *ctx, ppb_err *err)
{
    return verify_at(dir, "", bad, ctx, err);
}
