#define _XOPEN_SOURCE 700 /* nftw */
#include "methods/external/method_external.h"

#include <errno.h>
#include <ftw.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/child.h"
#include "base/clock.h"
#include "base/csv_read.h"
#include "base/progress.h"
#include "io/scene_json.h"
#include "methods/result_check.h"

int ppb_external_check(const ppb_config *cfg, const ppb_external_def *d, ppb_err *err)
{
    char where[1200];
    if (!strstr(d->command, "{out}"))
        return ppb_fail(err, "%s: holds no {out} (the directory its radiance.csv goes to)",
                        ppb_config_external_where(cfg, d, "command", where, sizeof where));
    return 0;
}

/* Appends s to buf in single quotes for /bin/sh ('\'' for a quote). */
static int put_quoted(char *buf, size_t cap, size_t *n, const char *s)
{
    const char *parts[] = {"'", NULL, "'"};
    for (int k = 0; k < 3; k++) {
        const char *p = parts[k] ? parts[k] : s;
        for (; *p; p++) {
            const char *q = (!parts[k] && *p == '\'') ? "'\\''" : NULL;
            size_t len = q ? 4 : 1;
            if (*n + len >= cap)
                return -1;
            memcpy(buf + *n, q ? q : p, len);
            *n += len;
        }
    }
    buf[*n] = '\0';
    return 0;
}

/* The command with {scene}, {out} and {name} (the method's NAME: docs/external.md, The
 * config) replaced, each shell-quoted. */
static int expand(const char *cmd, const char *scene, const char *out, const char *name, char *buf,
                  size_t cap)
{
    size_t n = 0;
    buf[0] = '\0';
    for (const char *c = cmd; *c;) {
        const char *what = !strncmp(c, "{scene}", 7)  ? scene
                           : !strncmp(c, "{out}", 5)  ? out
                           : !strncmp(c, "{name}", 6) ? name
                                                      : NULL;
        if (what) {
            if (put_quoted(buf, cap, &n, what))
                return -1;
            c = strchr(c, '}') + 1;
            continue;
        }
        if (n + 1 >= cap)
            return -1;
        buf[n++] = *c++;
        buf[n] = '\0';
    }
    return 0;
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* Runs cmd under /bin/sh in its own process group, under a guard that kills whatever the
 * command leaves running when it ends, times out or ppbench dies (base/child.h); 0 when it
 * exited with status 0. */
static int run_command(const char *cmd, double timeout, ppb_err *err)
{
    char *argv[] = {"sh", "-c", (char *)cmd, NULL};
    pid_t pid = ppb_child_spawn("/bin/sh", argv, 1, 1); /* ppbench's stdout stays its own */
    if (pid < 0)
        return ppb_fail(err, "cannot start its command: %s", strerror(errno));
    double t0 = ppb_now();
    int st = 0, why = 0; /* why: 1 timeout, 2 interrupted */
    for (int ms = 1;;) {
        pid_t r = waitpid(pid, &st, WNOHANG);
        if (r == pid)
            break;
        if (r < 0 && errno != EINTR)
            return ppb_fail(err, "waitpid: %s", strerror(errno));
        if (!why && (ppb_now() - t0 > timeout || ppb_interrupted())) {
            why = ppb_interrupted() ? 2 : 1;
            kill(-pid, SIGTERM);
            double t1 = ppb_now();
            while (waitpid(pid, &st, WNOHANG) == 0 && ppb_now() - t1 < 2.0)
                sleep_ms(20);
            kill(-pid, SIGKILL); /* whatever of the group is left */
            while (waitpid(pid, &st, 0) < 0 && errno == EINTR)
                ;
            break;
        }
        sleep_ms(ms);
        ms = ms < 50 ? 2 * ms : 50;
    }
    if (why == 1)
        return ppb_fail(err, "its command ran past its timeout of %g s: killed", timeout);
    if (why == 2)
        return ppb_fail(err, "interrupted: its command was killed");
    if (WIFSIGNALED(st))
        return ppb_fail(err, "its command was killed by signal %d", WTERMSIG(st));
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0)
        return ppb_fail(err, "its command exited with status %d",
                        WIFEXITED(st) ? WEXITSTATUS(st) : -1);
    return 0;
}

static const char *const columns[] = {"method",    "surface", "segment",  "s",
                                      "theta_bin", "phi_bin", "radiance", "stderr"};
enum { NCOLUMNS = sizeof columns / sizeof columns[0] };

/* A whole number in [lo, hi], nothing else. */
static int parse_index(const char *s, int lo, int hi, int *v)
{
    char *end;
    errno = 0;
    long x = strtol(s, &end, 10);
    if (!*s || *end || errno || x < lo || x > hi)
        return -1;
    *v = (int)x;
    return 0;
}

static int parse_real(const char *s, double *v)
{
    char *end;
    *v = strtod(s, &end);
    return (!*s || *end) ? -1 : 0;
}

static int surface_of(const char *name, int nsurf)
{
    for (int k = 0; k < nsurf; k++)
        if (strcmp(name, ppb_surface_name(k)) == 0)
            return k;
    return -1;
}

int ppb_external_read_radiance(const char *path, const char *id, int others_ok, const ppb_scene *sc,
                               ppb_result *r, ppb_err *err)
{
    return ppb_external_read_radiance_on(path, id, others_ok, sc, 0, r, err);
}

int ppb_external_read_radiance_on(const char *path, const char *id, int others_ok,
                                  const ppb_scene *sc, unsigned surfaces, ppb_result *r,
                                  ppb_err *err)
{
    ppb_csv c;
    if (ppb_csv_open(&c, path, err))
        return -1;
    const ppb_layout *lo = &r->layout;
    int rc = -1;
    long *seen = calloc(lo->ncells, sizeof *seen); /* line of each cell's row, 0 = none yet */
    if (!seen) {
        ppb_fail(err, "%s: out of memory", path);
        goto done;
    }
    for (int k = 0; k < NCOLUMNS; k++)
        if (k >= c.ncol || strcmp(c.col[k], columns[k]) != 0) {
            ppb_fail(err,
                     "%s:1: the columns must begin method,surface,segment,s,theta_bin,phi_bin,"
                     "radiance,stderr (docs/reference.md: Outputs); column %d is '%s'",
                     path, k + 1, k < c.ncol ? c.col[k] : "(none)");
            goto done;
        }
    int got;
    while ((got = ppb_csv_next(&c, err)) == 1) {
        int surf, seg, it, ip;
        double s, L, se;
        if (others_ok && strcmp(ppb_csv_get(&c, 0), id) != 0)
            continue;
        if (strcmp(ppb_csv_get(&c, 0), id) != 0) {
            ppb_fail(err, "%s:%ld: method '%s', expected '%s'", path, c.line, ppb_csv_get(&c, 0),
                     id);
            goto done;
        }
        if (c.nfield < NCOLUMNS) {
            ppb_fail(err, "%s:%ld: %d fields, expected %d", path, c.line, c.nfield, c.ncol);
            goto done;
        }
        if ((surf = surface_of(ppb_csv_get(&c, 1), lo->nsurf)) < 0) {
            ppb_fail(err, "%s:%ld: surface '%s' is not one of S1..S%d", path, c.line,
                     ppb_csv_get(&c, 1), lo->nsurf);
            goto done;
        }
        if (parse_index(ppb_csv_get(&c, 2), 0, lo->nseg[surf] - 1, &seg) ||
            parse_index(ppb_csv_get(&c, 4), 0, sc->ntheta - 1, &it) ||
            parse_index(ppb_csv_get(&c, 5), 0, sc->nphi - 1, &ip)) {
            ppb_fail(err,
                     "%s:%ld: segment, theta_bin, phi_bin must be whole numbers in [0, %d], "
                     "[0, %d], [0, %d] on %s",
                     path, c.line, lo->nseg[surf] - 1, sc->ntheta - 1, sc->nphi - 1,
                     ppb_surface_name(surf));
            goto done;
        }
        if (parse_real(ppb_csv_get(&c, 3), &s) || parse_real(ppb_csv_get(&c, 6), &L) ||
            parse_real(ppb_csv_get(&c, 7), &se)) {
            ppb_fail(err, "%s:%ld: s, radiance and stderr must be numbers", path, c.line);
            goto done;
        }
        if (!isfinite(L) || !isfinite(se) || L < 0 || se < 0) {
            ppb_fail(err, "%s:%ld: radiance %s, stderr %s: each must be finite and >= 0", path,
                     c.line, ppb_csv_get(&c, 6), ppb_csv_get(&c, 7));
            goto done;
        }
        double x, y;
        double s_want = ppb_scene_sample_point(sc, surf, seg, &x, &y);
        if (!(fabs(s - s_want) <= 0.25 * ppb_scene_segment_length(sc, surf))) {
            ppb_fail(err, "%s:%ld: s = %s, but %s segment %d is centred at s = %.17g", path, c.line,
                     ppb_csv_get(&c, 3), ppb_surface_name(surf), seg, s_want);
            goto done;
        }
        if (surfaces && surfaces != PPB_SURFACES_FROM_ROWS && !(surfaces & (1u << surf))) {
            ppb_fail(err, "%s:%ld: a row of %s, which its surfaces key leaves out", path, c.line,
                     ppb_surface_name(surf));
            goto done;
        }
        size_t cell = ppb_cell(lo, surf, seg, ppb_bin_index(it, ip, sc->nphi));
        if (seen[cell]) {
            ppb_fail(err,
                     "%s:%ld: a second row for %s segment %d bin (%d, %d) (the first: line %ld)",
                     path, c.line, ppb_surface_name(surf), seg, it, ip, seen[cell]);
            goto done;
        }
        seen[cell] = c.line;
        r->radiance[cell] = L;
        r->se[cell] = se;
    }
    if (got < 0)
        goto done;
    unsigned answered = ppb_external_answered(lo, seen, surfaces);
    for (int surf = 0; surf < lo->nsurf; surf++)
        for (int seg = 0; seg < lo->nseg[surf] && (answered & (1u << surf)); seg++)
            for (int bin = 0; bin < lo->nbins; bin++)
                if (!seen[ppb_cell(lo, surf, seg, bin)]) {
                    ppb_fail(err,
                             "%s: missing row: %s segment %d theta_bin %d phi_bin %d (one row "
                             "per sample point and bin of scene.json)",
                             path, ppb_surface_name(surf), seg, bin / sc->nphi, bin % sc->nphi);
                    goto done;
                }
    ppb_external_not_computed(r, answered);
    rc = 0;
done:
    free(seen);
    ppb_csv_close(&c);
    return rc;
}

int ppb_external_totals(const char *path, const ppb_scene *sc, ppb_result *r, ppb_err *err)
{
    ppb_totals *t = &r->totals;
    memset(t, 0, sizeof *t);
    if (access(path, F_OK) != 0) {
        /* No totals.csv: the scattered exits integrated from the radiance; the ballistic part
         * is not radiance (reference: Bins), so it stays 0 and absorbed is the rest. */
        const ppb_layout *lo = &r->layout;
        double P = ppb_scene_power_in(sc);
        for (int surf = 0; surf < lo->nsurf; surf++) {
            double e = 0.0, m = ppb_scene_cell_measure(sc, surf);
            for (int seg = 0; seg < lo->nseg[surf]; seg++)
                for (int bin = 0; bin < lo->nbins; bin++)
                    e += r->radiance[ppb_cell(lo, surf, seg, bin)] * m;
            *(surf == PPB_S1 ? &t->R : surf == PPB_S2 ? &t->T : &t->sides) += e / P;
        }
        ppb_totals_complete(t);
        return 0;
    }
    ppb_csv c;
    if (ppb_csv_open(&c, path, err))
        return -1;
    static const char *const names[] = {"R", "T", "sides", "absorbed", "ballistic"};
    double *dst[] = {&t->R, &t->T, &t->sides, &t->absorbed, &t->ballistic};
    int col[5], mcol = ppb_csv_need(&c, "method", err), found = 0, got, rc = -1;
    for (int k = 0; k < 5 && mcol >= 0; k++)
        if ((col[k] = ppb_csv_need(&c, names[k], err)) < 0)
            mcol = -1;
    if (mcol < 0)
        goto done;
    while ((got = ppb_csv_next(&c, err)) == 1) {
        if (strcmp(ppb_csv_get(&c, mcol), r->method) != 0)
            continue;
        if (found) {
            ppb_fail(err, "%s:%ld: a second row for %s", path, c.line, r->method);
            goto done;
        }
        found = 1;
        for (int k = 0; k < 5; k++)
            /* nan: not computed (a partial method's own totals.csv, docs/external.md) */
            if (parse_real(ppb_csv_get(&c, col[k]), dst[k]) || isinf(*dst[k])) {
                ppb_fail(err, "%s:%ld: %s = '%s': not a number (nan: not computed)", path, c.line,
                         names[k], ppb_csv_get(&c, col[k]));
                goto done;
            } else if (*dst[k] < 0.0 && k != 3) { /* absorbed may be 1 - the rest */
                ppb_fail(err, "%s:%ld: %s = '%s': a fraction of the power, must be >= 0", path,
                         c.line, names[k], ppb_csv_get(&c, col[k]));
                goto done;
            }
    }
    if (got < 0)
        goto done;
    if (!found) {
        ppb_fail(err, "%s: no row for method %s", path, r->method);
        goto done;
    }
    t->absorbed_tracked = 1;
    rc = 0;
done:
    ppb_csv_close(&c);
    return rc;
}

static int remove_one(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st;
    (void)flag;
    (void)ftw;
    return remove(path);
}

int ppb_method_external(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    const char *id = out->method;
    const ppb_external_def *d = ppb_config_external(cfg, id);
    if (!d)
        return ppb_fail(err, "no [method.%s] in %s", id, cfg->path);
    const char *tmp = getenv("TMPDIR");
    char dir[PPB_PATH_MAX], scene[PPB_PATH_MAX + 16], odir[PPB_PATH_MAX + 16];
    if (snprintf(dir, sizeof dir, "%s/ppbench-%s-XXXXXX", tmp && *tmp ? tmp : "/tmp", id) >=
        (int)sizeof dir)
        return ppb_fail(err, "$TMPDIR too long");
    if (!mkdtemp(dir))
        return ppb_fail(err, "cannot make a directory %s: %s", dir, strerror(errno));
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    snprintf(odir, sizeof odir, "%s/out", dir);
    if (mkdir(odir, 0777) < 0)
        return ppb_fail(err, "cannot make %s: %s", odir, strerror(errno));
    if (ppb_scene_json_write(cfg, scene, err))
        return -1;
    size_t cap = sizeof d->command + 4 * (sizeof scene + sizeof odir) * 4;
    char *cmd = malloc(cap);
    if (!cmd)
        return ppb_fail(err, "out of memory");
    if (expand(d->command, scene, odir, id, cmd, cap)) {
        free(cmd);
        return ppb_fail(err, "its command is too long once expanded");
    }
    if (!ctx->quiet)
        fprintf(stderr, "%s: %s: running: %s\n", cfg->name, id, cmd);
    double timeout = d->timeout > 0 ? d->timeout : PPB_EXTERNAL_TIMEOUT;
    int rc = run_command(cmd, timeout, err);
    free(cmd);
    char rad[PPB_PATH_MAX + 64], tot[PPB_PATH_MAX + 64];
    snprintf(rad, sizeof rad, "%s/radiance.csv", odir);
    snprintf(tot, sizeof tot, "%s/totals.csv", odir);
    if (rc == 0 && access(rad, F_OK) != 0)
        rc = ppb_fail(err, "its command wrote no %s", rad);
    if (rc == 0)
        rc = ppb_external_read_radiance_on(rad, id, 0, &cfg->scene, d->surfaces, out, err);
    if (rc == 0)
        rc = ppb_external_totals(tot, &cfg->scene, out, err);
    /* A partial method's surfaces not computed are NaN: the reader checked the others. */
    int partial = ppb_external_is_partial(&out->layout, d->surfaces);
    if (rc == 0 && !partial)
        rc = ppb_radiance_check(cfg->name, out, NULL, err);
    if (rc == 0 && !partial)
        rc = ppb_totals_check(cfg->name, out, err);
    if (rc) {
        size_t n = strlen(err->msg);
        snprintf(err->msg + n, sizeof err->msg - n, " (its files are kept in %s)", dir);
        return -1;
    }
    if (nftw(dir, remove_one, 16, FTW_DEPTH | FTW_PHYS) != 0)
        fprintf(stderr, "%s: %s: could not remove %s: %s\n", cfg->name, id, dir, strerror(errno));
    return 0;
}
