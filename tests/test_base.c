/* test_base.c: the base layer's utilities (src/base/): the CSV reader (columns by name, a missing
 * column, quoted fields, a line longer than any fixed buffer, the project's own writer's
 * output), the atomic writes (both forms: commit renames, abort leaves nothing), the hash against
 * published XXH3 values, the Gauss-Legendre generator against the closed-form rules, the sort, and
 * the monotonic clock. */
#include "testutil.h"

#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/clock.h"
#include "base/csv_read.h"
#include "base/hash.h"
#include "base/quadrature.h"
#include "base/file_read.h"
#include "kernels/ppb_sort.h"

static const char *write_text(const char *dir, const char *name, const char *text)
{
    static char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

static int file_exists(const char *path)
{
    FILE *f = fopen(path, "r");
    if (f)
        fclose(f);
    return f != NULL;
}

/* Columns are found by name whatever their position; a short row reads "" past its end. */
static void test_csv_columns_by_name(void **state)
{
    (void)state;
    const char *dir = tu_scratch("csv_names");
    const char *path = write_text(dir, "a.csv", "method,cell,rms_rel\npp,R_x0,0.25\r\nss,T_x0\n\n");
    ppb_csv c;
    ppb_err err = {{0}};
    assert_int_equal(ppb_csv_open(&c, path, &err), 0);
    assert_int_equal(c.ncol, 3);
    assert_int_equal(ppb_csv_col(&c, "rms_rel"), 2);
    assert_int_equal(ppb_csv_col(&c, "method"), 0);
    assert_int_equal(ppb_csv_col(&c, "noise_rel"), -1);
    int rms = ppb_csv_need(&c, "rms_rel", &err);
    assert_int_equal(ppb_csv_next(&c, &err), 1);
    assert_string_equal(ppb_csv_get(&c, 0), "pp");
    double v = 0;
    assert_true(ppb_csv_double(&c, rms, &v));
    assert_close(v, 0.25, 0);                    /* "0.25" is exact in binary */
    assert_int_equal(ppb_csv_next(&c, &err), 1); /* "\r\n" ended the previous line */
    assert_string_equal(ppb_csv_get(&c, 1), "T_x0");
    assert_string_equal(ppb_csv_get(&c, rms), ""); /* the row is short */
    assert_false(ppb_csv_double(&c, rms, &v));
    assert_int_equal(c.line, 3);
    assert_int_equal(ppb_csv_next(&c, &err), 0); /* the blank line is skipped, then the end */
    ppb_csv_close(&c);
}

static void test_csv_missing_column_is_an_error(void **state)
{
    (void)state;
    const char *dir = tu_scratch("csv_missing");
    const char *path = write_text(dir, "a.csv", "method,cell\npp,R_x0\n");
    ppb_csv c;
    ppb_err err = {{0}};
    assert_int_equal(ppb_csv_open(&c, path, &err), 0);
    assert_int_equal(ppb_csv_need(&c, "rms_excess", &err), -1);
    assert_non_null(strstr(err.msg, "no column 'rms_excess'"));
    assert_non_null(strstr(err.msg, "a.csv"));
    ppb_csv_close(&c);
    /* An empty file has no header; a missing file cannot be opened. */
    path = write_text(dir, "empty.csv", "");
    assert_int_equal(ppb_csv_open(&c, path, &err), -1);
    assert_non_null(strstr(err.msg, "empty"));
    char none[1200];
    snprintf(none, sizeof none, "%s/none.csv", dir);
    assert_int_equal(ppb_csv_open(&c, none, &err), -1);
    assert_non_null(strstr(err.msg, "cannot open"));
}

/* RFC 4180 quoting, as Python's csv module writes it (perf_mc.c reads pmcxcl's answer that way):
 * commas, doubled quotes and a newline inside quotes. */
static void test_csv_quoted_fields(void **state)
{
    (void)state;
    const char *dir = tu_scratch("csv_quoted");
    const char *path = write_text(dir, "q.csv",
                                  "nphoton,\"runtime_ms\",device\n"
                                  "1000,12.5,\"pthread-Intel(R) Xeon(R), 16 \"\"cores\"\"\"\n"
                                  "2,3,\"two\nlines\"\n"
                                  "4,5,\"open\n");
    ppb_csv c;
    ppb_err err = {{0}};
    assert_int_equal(ppb_csv_open(&c, path, &err), 0);
    int dev = ppb_csv_need(&c, "device", &err);
    assert_int_equal(ppb_csv_need(&c, "runtime_ms", &err), 1);
    assert_int_equal(ppb_csv_next(&c, &err), 1);
    assert_string_equal(ppb_csv_get(&c, dev), "pthread-Intel(R) Xeon(R), 16 \"cores\"");
    assert_int_equal(c.nfield, 3);
    assert_int_equal(ppb_csv_next(&c, &err), 1);
    assert_string_equal(ppb_csv_get(&c, dev), "two\nlines");
    assert_int_equal(c.line, 3);
    assert_int_equal(ppb_csv_next(&c, &err), -1); /* the last quote is never closed */
    assert_non_null(strstr(err.msg, "q.csv:5: a quoted field is not closed"));
    ppb_csv_close(&c);
}

/* A header and a row far longer than the 8192-byte line buffers the readers had. */
static void test_csv_long_line(void **state)
{
    (void)state;
    const char *dir = tu_scratch("csv_long");
    char path[1200];
    snprintf(path, sizeof path, "%s/long.csv", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    const int ncol = 5000; /* "c4999" and the row's numbers: ~40 kB per line */
    for (int i = 0; i < ncol; i++)
        fprintf(f, "%sc%d", i ? "," : "", i);
    fputc('\n', f);
    for (int i = 0; i < ncol; i++)
        fprintf(f, "%s%d.5", i ? "," : "", i);
    fputc('\n', f);
    fclose(f);
    ppb_csv c;
    ppb_err err = {{0}};
    assert_int_equal(ppb_csv_open(&c, path, &err), 0);
    assert_int_equal(c.ncol, ncol);
    int last = ppb_csv_need(&c, "c4999", &err);
    assert_int_equal(last, ncol - 1);
    assert_int_equal(ppb_csv_next(&c, &err), 1);
    double v;
    assert_true(ppb_csv_double(&c, last, &v));
    assert_close(v, 4999.5, 0);
    ppb_csv_close(&c);
}

/* A quote opened on line 2 and never closed, then 400,000 short lines: the reader must report the
 * open quote at line 2 having read the input once (file_read.h, csv_read.h: linear in the input).
 * The expected error is csv_read.h's own. A reader that rescans the record at every line takes
 * hours here; the alarm turns that into a failure (it is a watchdog, not a timing assertion: the
 * linear reader needs well under a second). */
static void test_csv_unclosed_quote_is_linear(void **state)
{
    (void)state;
    const char *dir = tu_scratch("csv_unclosed");
    char path[1200];
    snprintf(path, sizeof path, "%s/open.csv", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("a,b\n\"x,1\n", f);
    for (int i = 0; i < 400000; i++)
        fputs("y,2\n", f);
    fclose(f);
    alarm(120);
    ppb_csv c;
    ppb_err err = {{0}};
    assert_int_equal(ppb_csv_open(&c, path, &err), 0);
    assert_int_equal(ppb_csv_next(&c, &err), -1);
    assert_non_null(strstr(err.msg, "open.csv:2: a quoted field is not closed"));
    ppb_csv_close(&c);
    alarm(0);
}

/* A NUL byte in a CSV record is refused at its line: the text after it was lost (the fields
 * are C strings), so "x\0junk" read as "x". The expected message is csv_read.c's. */
static void test_csv_nul_byte(void **state)
{
    (void)state;
    const char *dir = tu_scratch("csv_nul");
    char path[1200];
    snprintf(path, sizeof path, "%s/nul.csv", dir);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fwrite("a,b\nx\0junk,1\n", 1, 15, f);
    fclose(f);
    ppb_csv c;
    ppb_err err = {{0}};
    assert_int_equal(ppb_csv_open(&c, path, &err), 0);
    assert_int_equal(ppb_csv_next(&c, &err), -1);
    assert_non_null(strstr(err.msg, "nul.csv:2: a NUL byte"));
    ppb_csv_close(&c);
}

/* Files that are not regular are refused at once, naming the file: a FIFO (open() would wait
 * for a writer for ever) and /dev/zero (never ends) (file_read.h). The alarm turns a reader
 * that blocks into a failure. */
static void test_read_only_regular_files(void **state)
{
    (void)state;
    const char *dir = tu_scratch("read_fifo");
    char fifo[1200];
    snprintf(fifo, sizeof fifo, "%s/fifo.csv", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    alarm(60);
    ppb_csv c;
    ppb_err err = {{0}};
    assert_int_equal(ppb_csv_open(&c, fifo, &err), -1);
    assert_non_null(strstr(err.msg, "fifo.csv: not a regular file (a FIFO)"));
    assert_null(ppb_read_file(fifo, NULL));
    assert_int_equal(ppb_csv_open(&c, "/dev/zero", &err), -1);
    assert_non_null(strstr(err.msg, "/dev/zero: not a regular file (a character device)"));
    assert_null(ppb_read_file("/dev/zero", NULL));
    assert_int_equal(ppb_open_regular(dir, PPB_READ_MAX, &err), -1);
    assert_non_null(strstr(err.msg, "not a regular file (a directory)"));
    /* The size bound: a 10-byte file against a 4-byte bound. */
    const char *small = write_text(dir, "ten.txt", "0123456789");
    assert_int_equal(ppb_open_regular(small, 4, &err), -1);
    assert_non_null(strstr(err.msg, "ten.txt: 10 bytes, more than the 4 bytes"));
    alarm(0);
}

/* ppb_afile: the file appears complete on commit, and nothing (not even the temporary) after an
 * abort. */
static void test_afile_commit_and_abort(void **state)
{
    (void)state;
    const char *dir = tu_scratch("afile");
    char path[1200];
    snprintf(path, sizeof path, "%s/out.txt", dir);
    ppb_afile af;
    ppb_err err = {{0}};
    assert_int_equal(ppb_afile_open(&af, path, &err), 0);
    fputs("hello\n", af.f);
    assert_false(file_exists(path)); /* not there before the commit */
    assert_true(file_exists(af.name.tmp));
    assert_int_equal(ppb_afile_commit(&af, &err), 0);
    assert_true(file_exists(path));
    assert_false(file_exists(af.name.tmp));
    assert_int_equal(ppb_afile_open(&af, path, &err), 0);
    fputs("half", af.f);
    ppb_afile_abort(&af);
    assert_false(file_exists(af.name.tmp));
    FILE *f = fopen(path, "r");
    char line[16] = "";
    assert_non_null(fgets(line, sizeof line, f));
    fclose(f);
    assert_string_equal(line, "hello\n"); /* the committed version is untouched */
}

/* ppb_apath, for libraries that open by name: commit renames what they wrote, abort removes it,
 * a commit with nothing written fails and leaves nothing; too long a path is refused. */
static void test_apath_commit_and_abort(void **state)
{
    (void)state;
    const char *dir = tu_scratch("apath");
    char path[1200];
    snprintf(path, sizeof path, "%s/img.exr", dir);
    ppb_apath ap;
    ppb_err err = {{0}};
    assert_int_equal(ppb_apath_begin(&ap, path, &err), 0);
    assert_non_null(strstr(ap.tmp, "img.exr.tmp."));
    write_text(dir, strrchr(ap.tmp, '/') + 1, "pixels");
    assert_int_equal(ppb_apath_commit(&ap, &err), 0);
    assert_true(file_exists(path));
    assert_false(file_exists(ap.tmp));

    snprintf(path, sizeof path, "%s/other.png", dir);
    assert_int_equal(ppb_apath_begin(&ap, path, &err), 0);
    write_text(dir, strrchr(ap.tmp, '/') + 1, "half");
    ppb_apath_abort(&ap);
    assert_false(file_exists(ap.tmp));
    assert_false(file_exists(path));
    assert_int_equal(ppb_apath_commit(&ap, &err), -1); /* nothing to rename */
    assert_non_null(strstr(err.msg, "cannot rename into place"));
    assert_false(file_exists(path));

    static char huge[PPB_PATH_MAX + 10];
    memset(huge, 'a', sizeof huge - 1);
    assert_int_equal(ppb_apath_begin(&ap, huge, &err), -1);
    assert_non_null(strstr(err.msg, "path too long"));
}

/* XXH3_64bits with seed 0: the empty input's value is the one xxHash publishes in its sanity
 * tests (0x2D06800538D394C2); the others are what `xxhsum -H3` (Debian xxhash 0.8.1) prints for
 * the same bytes. */
static void test_hash_xxh3_values(void **state)
{
    (void)state;
    assert_true(ppb_hash64("", 0) == 0x2d06800538d394c2ull);
    assert_true(ppb_hash64("ppbench", 7) == 0x4724288ff52dd59bull);
    assert_true(ppb_hash64("a,b\n", 4) == 0xf765cba0be541510ull);
    assert_true(ppb_hash64("ppbench", 6) != ppb_hash64("ppbench", 7));
}

/* Against the closed forms (Abramowitz & Stegun 25.4.29): q = 3: +-sqrt(3/5), 5/9, 8/9; q = 4:
 * sqrt(3/7 -+ 2/7 sqrt(6/5)), (18 +- sqrt(30)) / 36; q = 5: 0, (1/3) sqrt(5 -+ 2 sqrt(10/7)),
 * 128/225, (322 +- 13 sqrt(70)) / 900. The generator's nodes agree to 1 ulp, its weights to a few
 * (4e-16 measured, 1e-15 allowed). And a q-point rule is exact to degree 2q - 1 and misses
 * degree 2q by its error term. */
static void test_gauss_legendre_closed_forms(void **state)
{
    (void)state;
    double x[5], w[5];
    ppb_gauss_legendre(3, x, w);
    double x3[3] = {sqrt(0.6), 0, -sqrt(0.6)}, w3[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
    for (int i = 0; i < 3; i++) {
        assert_close(x[i], x3[i], 3e-16);
        assert_close(w[i], w3[i], 1e-15);
    }
    ppb_gauss_legendre(4, x, w);
    double a4 = sqrt(3.0 / 7 - 2.0 / 7 * sqrt(1.2)), b4 = sqrt(3.0 / 7 + 2.0 / 7 * sqrt(1.2));
    double x4[4] = {b4, a4, -a4, -b4};
    double w4[4] = {(18 - sqrt(30.0)) / 36, (18 + sqrt(30.0)) / 36, (18 + sqrt(30.0)) / 36,
                    (18 - sqrt(30.0)) / 36};
    for (int i = 0; i < 4; i++) {
        assert_close(x[i], x4[i], 3e-16);
        assert_close(w[i], w4[i], 1e-15);
    }
    ppb_gauss_legendre(5, x, w);
    double a5 = sqrt(5 - 2 * sqrt(10.0 / 7)) / 3, b5 = sqrt(5 + 2 * sqrt(10.0 / 7)) / 3;
    double x5[5] = {b5, a5, 0, -a5, -b5};
    double w5[5] = {(322 - 13 * sqrt(70.0)) / 900, (322 + 13 * sqrt(70.0)) / 900, 128.0 / 225,
                    (322 + 13 * sqrt(70.0)) / 900, (322 - 13 * sqrt(70.0)) / 900};
    for (int i = 0; i < 5; i++) {
        assert_close(x[i], x5[i], 3e-16);
        assert_close(w[i], w5[i], 1e-15);
    }
    for (int q = 1; q <= 16; q++) {
        double xq[16], wq[16];
        ppb_gauss_legendre(q, xq, wq);
        double exact = 0, high = 0; /* int x^(2q-2) dx = 2/(2q-1); x^(2q): 2/(2q+1) */
        for (int i = 0; i < q; i++) {
            exact += wq[i] * pow(xq[i], 2 * q - 2);
            high += wq[i] * pow(xq[i], 2 * q);
        }
        assert_close(exact, 2.0 / (2 * q - 1), 1e-14 * 2.0 / (2 * q - 1));
        if (q > 8)
            continue; /* beyond, the degree-2q error is too small to see in double */
        /* The rule's error term (A&S 25.4.29) for f = x^(2q), f^(2q) = (2q)!:
         * 2^(2q+1) (q!)^4 / ((2q + 1) ((2q)!)^2). */
        double fq = tgamma(q + 1.0), f2q = tgamma(2.0 * q + 1);
        double err_term = pow(2, 2 * q + 1) * pow(fq, 4) / ((2 * q + 1) * f2q * f2q);
        assert_close(2.0 / (2 * q + 1) - high, err_term, 1e-8 * err_term);
    }
}

/* Ascending order, stable for equal keys (checked by the sign of zero), against a sorted copy
 * built by selection (an independent algorithm). */
static void test_sort_doubles(void **state)
{
    (void)state;
    double v[7] = {3.5, -1, 0.0, 2, -0.0, 10, -7};
    ppb_sort_doubles(v, 7);
    const double want[7] = {-7, -1, 0.0, -0.0, 2, 3.5, 10};
    for (int i = 0; i < 7; i++)
        assert_close(v[i], want[i], 0);
    assert_false(signbit(v[2])); /* 0.0 came first in the input and stays first */
    assert_true(signbit(v[3]));
    unsigned s = 12345;
    for (int trial = 0; trial < 50; trial++) {
        double a[9], b[9];
        for (int i = 0; i < 9; i++)
            a[i] = b[i] = (double)((s = s * 1103515245u + 12345u) >> 16 & 1023) - 512;
        ppb_sort_doubles(a, 9);
        for (int i = 0; i < 9; i++) {
            int m = i;
            for (int k = i + 1; k < 9; k++)
                m = b[k] < b[m] ? k : m;
            double t = b[i];
            b[i] = b[m], b[m] = t;
            assert_close(a[i], b[i], 0);
        }
    }
    ppb_sort_doubles(v, 0); /* nothing to do, nothing touched */
    assert_close(v[0], -7, 0);
}

/* Monotonic and in seconds: a 20 ms sleep reads as at least 20 ms and not absurdly more. */
static void test_clock_seconds(void **state)
{
    (void)state;
    double t0 = ppb_now();
    struct timespec ts = {0, 20000000};
    nanosleep(&ts, NULL);
    double dt = ppb_now() - t0;
    assert_close(dt, 2.51, 2.49); /* in [0.02, 5] */
}

/* A file of more than one read block (200000 bytes, NULs and all) comes back whole and
 * NUL-terminated; a missing file is NULL. Expected bytes: the ones written. */
static void test_read_file(void **state)
{
    (void)state;
    char path[1200];
    snprintf(path, sizeof path, "%s/blob", tu_scratch("read-file"));
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    for (int i = 0; i < 200000; i++)
        fputc(i % 251, f);
    fclose(f);
    size_t n = 0;
    char *b = ppb_read_file(path, &n);
    assert_non_null(b);
    assert_int_equal(n, 200000);
    for (int i = 0; i < 200000; i++)
        if ((unsigned char)b[i] != i % 251)
            fail_msg("byte %d is %d, wrote %d", i, (unsigned char)b[i], i % 251);
    assert_int_equal(b[n], '\0');
    free(b);
    strcat(path, ".missing");
    assert_null(ppb_read_file(path, NULL));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_csv_columns_by_name),
        cmocka_unit_test(test_csv_missing_column_is_an_error),
        cmocka_unit_test(test_csv_quoted_fields),
        cmocka_unit_test(test_csv_long_line),
        cmocka_unit_test(test_csv_unclosed_quote_is_linear),
        cmocka_unit_test(test_read_only_regular_files),
        cmocka_unit_test(test_csv_nul_byte),
        cmocka_unit_test(test_afile_commit_and_abort),
        cmocka_unit_test(test_apath_commit_and_abort),
        cmocka_unit_test(test_hash_xxh3_values),
        cmocka_unit_test(test_gauss_legendre_closed_forms),
        cmocka_unit_test(test_sort_doubles),
        cmocka_unit_test(test_read_file),
        cmocka_unit_test(test_clock_seconds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
