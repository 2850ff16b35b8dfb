/* sweep_failures.c: the failed points of a sweep (sweep_failures.h). */
#include "drivers/sweep_failures.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/csv_read.h"

/* The point's failure file: the name sweep.c gives its other point files (points/<hash>.EXT). */
static void failures_file(const char *dir, const char *hash, char *buf, size_t n)
{
    snprintf(buf, n, "%s/points/%s.failures.csv", dir, hash);
}

/* A CSV field: quoted, quotes doubled, line breaks as spaces (a record is one line). */
static void put_field(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"')
            fputs("\"\"", f);
        else
            fputc(*s == '\n' || *s == '\r' ? ' ' : *s, f);
    }
    fputc('"', f);
}

int ppb_sweep_failures_point(const char *out_dir, uint64_t h, const ppb_experiment *ex, int rc,
                             ppb_err *err)
{
    char hash[32], path[1300];
    snprintf(hash, sizeof hash, "%016llx", (unsigned long long)h);
    failures_file(out_dir, hash, path, sizeof path);
    if (ex->nfailed == 0) {
        unlink(path); /* a failure of an earlier run of this point, now computed */
        return rc;
    }
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    for (int i = 0; i < ex->nfailed; i++) {
        fprintf(af.f, "%s,", ex->failed[i]);
        put_field(af.f, ex->failed_why[i]);
        fputc('\n', af.f);
    }
    if (ppb_afile_commit(&af, err))
        return -1;
    /* Every method failed: ppb_experiment_compute failed with the first reason, recorded. */
    return rc && ex->n == 0 ? 0 : rc;
}

int ppb_sweep_failures_assemble(const char *const *dirs, int ndirs, const char *out, ppb_err *err)
{
    char gpath[1200], path[1300];
    snprintf(gpath, sizeof gpath, "%s/grid.txt", dirs[0]);
    ppb_csv g;
    ppb_err gerr;
    if (ppb_csv_open(&g, gpath, &gerr))
        return ppb_fail(err, "%s", gerr.msg);
    int nvalues = ppb_csv_col(&g, "method") - 1;
    if (nvalues < 1) {
        ppb_csv_close(&g);
        return ppb_fail(err, "%s: not a grid file (no method column)", gpath);
    }
    ppb_afile af;
    snprintf(path, sizeof path, "%s/failures.csv", out);
    if (ppb_afile_open(&af, path, err)) {
        ppb_csv_close(&g);
        return -1;
    }
    for (int c = 0; c <= nvalues + 1; c++)
        fprintf(af.f, "%s,", g.col[c]);
    fprintf(af.f, "reason\n");
    int rc;
    long long i = 0;
    while ((rc = ppb_csv_next(&g, err)) == 1) {
        if (g.nfield != nvalues + 1) {
            rc = ppb_fail(err, "%s:%ld: %d fields, the grid has %d swept keys", gpath, g.line,
                          g.nfield, nvalues);
            break;
        }
        for (int d = 0; d < ndirs; d++) {
            failures_file(dirs[d], ppb_csv_get(&g, 0), path, sizeof path);
            FILE *f = fopen(path, "rb");
            if (!f)
                continue;
            char *line = NULL;
            size_t cap = 0;
            while (getline(&line, &cap, f) > 0) {
                if (line[0] == '\n')
                    continue;
                fprintf(af.f, "%lld", i);
                for (int a = 1; a <= nvalues; a++)
                    fprintf(af.f, ",%s", ppb_csv_get(&g, a));
                fprintf(af.f, ",%s", line);
            }
            free(line);
            fclose(f);
            break;
        }
        i++;
    }
    ppb_csv_close(&g);
    if (rc < 0) {
        ppb_afile_abort(&af);
        return -1;
    }
    return ppb_afile_commit(&af, err);
}
