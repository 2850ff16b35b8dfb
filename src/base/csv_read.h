/* csv_read.h: reading the project's CSV files (and CSV from a pipe) by column name.
 *
 * Owns the reading side of the CSV convention (the writers are io/csv.c and the drivers): the
 * first record is the header; a reader asks for the columns it needs by name, so adding or
 * moving a column never breaks it. Records are RFC 4180: fields separated by commas, a field in
 * double quotes may hold commas, newlines and doubled quotes (""); "\r\n" ends a line like
 * "\n"; blank lines are skipped. No line length limit (getline) below the bound of any file
 * read (file_read.h: PPB_READ_MAX); ppb_csv_open opens only a regular file. Reading is linear
 * in the input, a quote left open included. */
#ifndef PPB_CSV_READ_H
#define PPB_CSV_READ_H

#include <stdio.h>

#include "base/err.h"

typedef struct ppb_csv {
    FILE *f;
    int owns_f;      /* opened by ppb_csv_open: closed by ppb_csv_close */
    char name[256];  /* for messages: the path, shortened */
    long line;       /* line where the current record starts (the header is line 1) */
    long nread;      /* lines read so far */
    size_t bytes;    /* bytes read so far (bounded by PPB_READ_MAX) */
    const char *why; /* why the last read failed */
    char *ln;        /* getline's buffer */
    size_t ln_cap;
    char *rec; /* the current record, fields unquoted in place */
    size_t rec_cap;
    char *head; /* the header record */
    size_t head_cap;
    char **col; /* [ncol]: header names, pointing into head */
    int ncol;
    char **field; /* [nfield]: the current record's fields, pointing into rec */
    int nfield, field_cap;
} ppb_csv;

/* Opens path and reads its header. */
int ppb_csv_open(ppb_csv *c, const char *path, ppb_err *err);
/* Reads the header from an open stream (a pipe); name is used in messages; f stays open. */
int ppb_csv_open_stream(ppb_csv *c, FILE *f, const char *name, ppb_err *err);
void ppb_csv_close(ppb_csv *c);

/* Index of the column called name, or -1. */
int ppb_csv_col(const ppb_csv *c, const char *name);
/* Index of the column called name; a missing one is an error ("path: no column 'name'"). */
int ppb_csv_need(const ppb_csv *c, const char *name, ppb_err *err);

/* Reads the next record: 1, or 0 at the end, or -1 (a quote left open at the end, more than
 * PPB_READ_MAX bytes, out of memory). */
int ppb_csv_next(ppb_csv *c, ppb_err *err);
/* Field col of the current record; "" past its end or for col < 0. */
const char *ppb_csv_get(const ppb_csv *c, int col);
/* Field col as a number (strtod: "nan" and "inf" included); 0 when it is not a number. */
int ppb_csv_double(const ppb_csv *c, int col, double *v);

#endif
