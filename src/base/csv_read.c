#include "base/csv_read.h"

#include "base/file_read.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

/* Appends one line to the record buffer and toggles *quoted for each '"' in it: 0, or 1 at the
 * end of the stream, or -1 (out of memory, or more than PPB_READ_MAX bytes: a stream that never
 * ends). Only the new line is scanned, so a record of any number of lines (a quote left open)
 * costs time linear in its length (docs/reference.md: Exit codes). */
static int append_line(ppb_csv *c, size_t *len, int *quoted)
{
    ssize_t n = getline(&c->ln, &c->ln_cap, c->f);
    if (n < 0)
        return 1;
    c->bytes += (size_t)n;
    if (memchr(c->ln, '\0', (size_t)n)) { /* the text after it would be lost */
        c->why = "a NUL byte: not a text file";
        return -1;
    }
    if (c->bytes > PPB_READ_MAX) {
        c->why = "more than the bytes read from one file";
        return -1;
    }
    if (*len + (size_t)n + 1 > c->rec_cap) {
        size_t want = 2 * (*len + (size_t)n + 1);
        char *p = realloc(c->rec, want);
        if (!p) {
            c->why = "out of memory";
            return -1;
        }
        c->rec = p;
        c->rec_cap = want;
    }
    memcpy(c->rec + *len, c->ln, (size_t)n + 1);
    for (const char *q = c->rec + *len; (q = memchr(q, '"', (size_t)(c->rec + *len + n - q))); q++)
        *quoted ^= 1;
    *len += (size_t)n;
    c->nread++;
    return 0;
}

static int push_field(ppb_csv *c, char *f)
{
    if (c->nfield == c->field_cap) {
        int want = c->field_cap ? 2 * c->field_cap : 16;
        char **p = realloc(c->field, sizeof *p * (size_t)want);
        if (!p)
            return -1;
        c->field = p;
        c->field_cap = want;
    }
    c->field[c->nfield++] = f;
    return 0;
}

/* Splits rec into fields in place: quotes removed, "" turned into ". */
static int split(ppb_csv *c)
{
    c->nfield = 0;
    char *r = c->rec, *w = c->rec, *start = w;
    int quoted = 0;
    for (;; r++) {
        if (quoted) {
            if (*r == '"' && r[1] == '"')
                *w++ = '"', r++;
            else if (*r == '"')
                quoted = 0;
            else
                *w++ = *r;
            continue;
        }
        if (*r == '"') {
            quoted = 1;
        } else if (*r == ',' || *r == '\0') {
            char end = *r;
            *w++ = '\0';
            if (push_field(c, start))
                return -1;
            start = w;
            if (end == '\0')
                return 0;
        } else {
            *w++ = *r;
        }
    }
}

int ppb_csv_next(ppb_csv *c, ppb_err *err)
{
    for (;;) {
        size_t len = 0;
        int quoted = 0, got;
        c->line = c->nread + 1;
        if ((got = append_line(c, &len, &quoted)) == 1)
            return 0;
        while (got == 0 && quoted)
            if ((got = append_line(c, &len, &quoted)) == 1)
                return ppb_fail(err, "%s:%ld: a quoted field is not closed", c->name, c->line);
        if (got < 0)
            return ppb_fail(err, "%s:%ld: %s", c->name, c->line, c->why);
        while (len > 0 && (c->rec[len - 1] == '\n' || c->rec[len - 1] == '\r'))
            c->rec[--len] = '\0';
        if (len == 0)
            continue; /* blank line */
        if (split(c))
            return ppb_fail(err, "%s:%ld: out of memory", c->name, c->line);
        return 1;
    }
}

int ppb_csv_open_stream(ppb_csv *c, FILE *f, const char *name, ppb_err *err)
{
    memset(c, 0, sizeof *c);
    c->f = f;
    snprintf(c->name, sizeof c->name, "%s", name);
    int rc = ppb_csv_next(c, err);
    if (rc <= 0) {
        if (rc == 0)
            ppb_fail(err, "%s: empty (no header line)", c->name);
        ppb_csv_close(c);
        return -1;
    }
    /* The header keeps its own copy: the record buffer is reused by every row. */
    c->head = c->rec, c->head_cap = c->rec_cap;
    c->col = c->field, c->ncol = c->nfield;
    c->rec = NULL, c->rec_cap = 0;
    c->field = NULL, c->nfield = c->field_cap = 0;
    return 0;
}

int ppb_csv_open(ppb_csv *c, const char *path, ppb_err *err)
{
    FILE *f = ppb_fopen_regular(path, PPB_READ_MAX, err);
    if (!f) {
        memset(c, 0, sizeof *c);
        return -1;
    }
    if (ppb_csv_open_stream(c, f, path, err)) {
        fclose(f);
        return -1;
    }
    c->owns_f = 1;
    return 0;
}

void ppb_csv_close(ppb_csv *c)
{
    if (c->owns_f && c->f)
        fclose(c->f);
    free(c->ln), free(c->rec), free(c->head), free(c->field), free(c->col);
    memset(c, 0, sizeof *c);
}

int ppb_csv_col(const ppb_csv *c, const char *name)
{
    for (int i = 0; i < c->ncol; i++)
        if (strcmp(c->col[i], name) == 0)
            return i;
    return -1;
}

int ppb_csv_need(const ppb_csv *c, const char *name, ppb_err *err)
{
    int i = ppb_csv_col(c, name);
    if (i < 0)
        return ppb_fail(err, "%s: no column '%s'", c->name, name);
    return i;
}

const char *ppb_csv_get(const ppb_csv *c, int col)
{
    return col >= 0 && col < c->nfield ? c->field[col] : "";
}

int ppb_csv_double(const ppb_csv *c, int col, double *v)
{
    const char *s = ppb_csv_get(c, col);
    char *end;
    *v = strtod(s, &end);
    return end != s;
}
