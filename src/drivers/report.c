#include "drivers/report.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "base/atomic_file.h"
#include "base/csv_read.h"
#include "methods/registry.h"
#include "model/paper.h"

/* The paper's Table 2 value for a method of ppbench: its registry entry names its column. */
static double paper_value(const char *case_name, const char *cell, const char *method)
{
    const ppb_method *m = ppb_method_find(NULL, method);
    return m ? ppb_paper_table2(case_name, cell, m->paper_column) : NAN;
}

/* A method's place in the paper's column order, -1 when the paper has no column for it. */
static int paper_rank(const char *method)
{
    const ppb_method *m = ppb_method_find(NULL, method);
    return m ? ppb_paper_column_rank(m->paper_column) : -1;
}

typedef struct summary_row {
    char method[32], cell[16];
    double rms, noise, excess;
} summary_row;

/* Reads <dir>/<case>/summary.csv (columns by name); returns the row count or -1. Rows whose
 * method or cell is empty or whose numbers do not parse are skipped. */
static int read_summary(const char *dir, const char *name, summary_row *rows, int cap, ppb_err *err)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s/summary.csv", dir, name);
    ppb_csv c;
    ppb_err open_err;
    if (ppb_csv_open(&c, path, &open_err))
        return ppb_fail(err, "%s (did the case run with mc?)", open_err.msg);
    static const char *const names[5] = {"method", "cell", "rms_rel", "noise_rel", "rms_excess"};
    int col[5];
    for (int k = 0; k < 5; k++)
        if ((col[k] = ppb_csv_need(&c, names[k], err)) < 0) {
            ppb_csv_close(&c);
            return -1;
        }
    int n = 0, rc = 0;
    while (n < cap && (rc = ppb_csv_next(&c, err)) == 1) {
        summary_row *r = &rows[n];
        snprintf(r->method, sizeof r->method, "%s", ppb_csv_get(&c, col[0]));
        snprintf(r->cell, sizeof r->cell, "%s", ppb_csv_get(&c, col[1]));
        if (r->method[0] && r->cell[0] && ppb_csv_double(&c, col[2], &r->rms) &&
            ppb_csv_double(&c, col[3], &r->noise) && ppb_csv_double(&c, col[4], &r->excess))
            n++;
    }
    ppb_csv_close(&c);
    return rc < 0 ? -1 : n;
}

/* What the report reads of one case: its summary rows, the Monte Carlo's own noise per
 * segment (rms.csv) and its photon budget (provenance.txt). */
enum { MAX_ROWS = 512, MAX_SEGS = 1024 };

typedef struct case_data {
    summary_row *rows;
    int n;
    double seg_lo[4], seg_hi[4]; /* noise_rel per segment of S1..S4, min and max; NAN: none */
    long long photons;           /* mc.photons; -1 when provenance.txt does not say */
} case_data;

/* The noise floor per segment: rms.csv's noise_rel combines the reference's standard errors
 * with the method's (reference: Metrics), which are 0 for deterministic methods, so the
 * smallest over the methods of a segment is the Monte Carlo's own. A case without rms.csv
 * (no reference) leaves NAN. */
static void read_segment_noise(const char *dir, const char *name, case_data *cd)
{
    for (int s = 0; s < 4; s++)
        cd->seg_lo[s] = cd->seg_hi[s] = NAN;
    char path[1200];
    snprintf(path, sizeof path, "%s/%s/rms.csv", dir, name);
    ppb_csv c;
    ppb_err e;
    if (ppb_csv_open(&c, path, &e))
        return;
    int cs = ppb_csv_need(&c, "surface", &e), cg = ppb_csv_need(&c, "segment", &e),
        cn = ppb_csv_need(&c, "noise_rel", &e);
    double(*floor)[MAX_SEGS] = malloc(4 * sizeof *floor);
    if (cs < 0 || cg < 0 || cn < 0 || !floor) {
        free(floor);
        ppb_csv_close(&c);
        return;
    }
    for (int s = 0; s < 4; s++)
        for (int k = 0; k < MAX_SEGS; k++)
            floor[s][k] = INFINITY;
    while (ppb_csv_next(&c, &e) == 1) {
        const char *surf = ppb_csv_get(&c, cs);
        double seg, noise;
        if (surf[0] != 'S' || surf[1] < '1' || surf[1] > '4' || surf[2] ||
            !ppb_csv_double(&c, cg, &seg) || !ppb_csv_double(&c, cn, &noise) || !(seg >= 0) ||
            seg >= MAX_SEGS || !isfinite(noise))
            continue;
        double *f = &floor[surf[1] - '1'][(int)seg];
        if (noise < *f)
            *f = noise;
    }
    ppb_csv_close(&c);
    for (int s = 0; s < 4; s++)
        for (int k = 0; k < MAX_SEGS; k++) {
            double v = floor[s][k];
            if (!isfinite(v))
                continue;
            if (isnan(cd->seg_lo[s]) || v < cd->seg_lo[s])
                cd->seg_lo[s] = v;
            if (isnan(cd->seg_hi[s]) || v > cd->seg_hi[s])
                cd->seg_hi[s] = v;
        }
    free(floor);
}

/* mc.photons from the case's provenance.txt (reference: Outputs), -1 when absent. */
static long long read_photons(const char *dir, const char *name)
{
    char path[1200], line[512];
    snprintf(path, sizeof path, "%s/%s/provenance.txt", dir, name);
    FILE *f = fopen(path, "r");
    long long n = -1;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "mc.photons = %lld", &n) == 1)
            break;
    if (f)
        fclose(f);
    return n;
}

static void free_cases(case_data *cd, int ncases)
{
    for (int c = 0; cd && c < ncases; c++)
        free(cd[c].rows);
    free(cd);
}

static case_data *load_cases(const char *dir, const char *const *cases, int ncases, ppb_err *err)
{
    case_data *cd = calloc((size_t)ncases, sizeof *cd);
    if (!cd) {
        ppb_fail(err, "report: out of memory");
        return NULL;
    }
    for (int c = 0; c < ncases; c++) {
        cd[c].rows = malloc(MAX_ROWS * sizeof *cd[c].rows);
        if (!cd[c].rows) {
            ppb_fail(err, "report: out of memory");
            free_cases(cd, ncases);
            return NULL;
        }
        if ((cd[c].n = read_summary(dir, cases[c], cd[c].rows, MAX_ROWS, err)) < 0) {
            free_cases(cd, ncases);
            return NULL;
        }
        read_segment_noise(dir, cases[c], &cd[c]);
        cd[c].photons = read_photons(dir, cases[c]);
    }
    return cd;
}

static int is_table2_cell(const char *cell)
{
    return !strcmp(cell, "R_x0") || !strcmp(cell, "T_x0");
}

/* The first line of each file report writes, by which it knows its own. table2.csv
 * and table2.md start with their header rows, which no other file has; README.md with an HTML
 * comment (invisible on the rendered page). A README.md an earlier ppbench report wrote starts
 * with its title line instead, also accepted. */
static const char readme_mark[] = "<!-- written by ppbench report: it replaces only a file that "
                                  "starts with this line -->";
static const char readme_mark_v1[] = "# The accuracy study (written by `make bench`)";
static const char csv_header[] = "case,cell,method,rms_rel,noise_rel,rms_excess,paper_rms_rel";
static const char md_header[] = "| case | cell | method | RMS % | noise floor % | excess % | "
                                "paper % |";

/* Whether report may write path: it does not exist, or it is a file whose first line is one of
 * marks (NULL-terminated). */
static int check_own(const char *path, const char *const *marks, ppb_err *err)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0; /* a missing file is written; another failure shows when it is written */
    char line[512] = "";
    if (!fgets(line, sizeof line, f))
        line[0] = '\0';
    int is_file = !ferror(f);
    fclose(f);
    line[strcspn(line, "\r\n")] = '\0';
    for (int i = 0; is_file && marks[i]; i++)
        if (!strcmp(line, marks[i]))
            return 0;
    return ppb_fail(err,
                    "%s: not written by ppbench report (its first line is not \"%s\"): it is "
                    "not replaced; move it away or report into another directory",
                    path, marks[0]);
}

/* The files of one report, each written and closed under its temporary name, then put in
 * place together (ppb_apaths_commit): an interrupt or a failure never leaves new tables beside
 * an old README. */
enum { REPORT_FILES = 3 };
typedef struct report_files {
    ppb_afile f[REPORT_FILES]; /* table2.csv, table2.md, README.md; zeroed: none begun */
} report_files;

static void md_cell(FILE *f, double v)
{
    fprintf(f, isnan(v) ? " - |" : " %.1f |", v);
}

/* table2.csv and table2.md into rf->f[0], rf->f[1], closed (not yet in place). */
static int write_tables(const char *dir, const char *const *cases, const case_data *cd, int ncases,
                        report_files *rf, ppb_err *err)
{
    char path[1200];
    ppb_afile *csvf = &rf->f[0], *mdf = &rf->f[1];
    snprintf(path, sizeof path, "%s/table2.csv", dir);
    if (ppb_afile_open(csvf, path, err))
        return -1;
    snprintf(path, sizeof path, "%s/table2.md", dir);
    if (ppb_afile_open(mdf, path, err))
        return -1;
    fprintf(csvf->f, "%s\n", csv_header);
    fprintf(mdf->f, "%s\n", md_header);
    fprintf(mdf->f, "|---|---|---|---|---|---|---|\n");
    for (int c = 0; c < ncases; c++)
        for (int i = 0; i < cd[c].n; i++) {
            const summary_row *r = &cd[c].rows[i];
            if (!is_table2_cell(r->cell))
                continue;
            double pv = paper_value(cases[c], r->cell, r->method);
            fprintf(csvf->f, "%s,%s,%s,%.6g,%.6g,%.6g,%.6g\n", cases[c], r->cell, r->method, r->rms,
                    r->noise, r->excess, pv / 100);
            fprintf(mdf->f, "| %s | %c | %s |", cases[c], r->cell[0], r->method);
            md_cell(mdf->f, 100 * r->rms);
            md_cell(mdf->f, 100 * r->noise);
            md_cell(mdf->f, 100 * r->excess);
            md_cell(mdf->f, pv);
            fputc('\n', mdf->f);
        }
    return ppb_afile_close(csvf, err) || ppb_afile_close(mdf, err) ? -1 : 0;
}

static void copy_file(FILE *dst, const char *path)
{
    FILE *f = fopen(path, "r");
    char buf[4096];
    size_t n;
    if (!f)
        return;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        fwrite(buf, 1, n, dst);
    fclose(f);
}

/* The case's error figures (scripts/plots.sh's images/error_<method>.png), linked in name
 * order under its line of the images section. */
static int cmp_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void link_error_images(FILE *f, const char *dir, const char *name)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s/images", dir, name);
    DIR *d = opendir(path);
    if (!d)
        return;
    char *found[64];
    int n = 0;
    for (struct dirent *e = readdir(d); e && n < 64; e = readdir(d)) {
        size_t len = strlen(e->d_name);
        if (!strncmp(e->d_name, "error_", 6) && len > 10 && !strcmp(e->d_name + len - 4, ".png"))
            if ((found[n] = strdup(e->d_name)))
                n++;
    }
    closedir(d);
    qsort(found, (size_t)n, sizeof *found, cmp_name);
    if (n > 0)
        fprintf(f, "  - errors against mc:");
    for (int k = 0; k < n; k++) {
        int len = (int)strlen(found[k]);
        fprintf(f, " [%.*s](%s/images/%s)", len - 10, found[k] + 6, name, found[k]);
        free(found[k]);
    }
    if (n > 0)
        fprintf(f, "\n");
}

/* The wide table's columns: the paper's methods in its order (proposed, MP, MP+S, S), then
 * every other method in the order the cases list them. */
enum { MAX_COLS = 32 };

static int table_methods(const case_data *cd, int ncases, char cols[][32])
{
    int n = 0;
    for (int pass = 0; pass < 2; pass++)
        for (int c = 0; c < ncases; c++)
            for (int i = 0; i < cd[c].n && n < MAX_COLS; i++) {
                const char *m = cd[c].rows[i].method;
                int in_paper = paper_rank(m) >= 0, seen = 0;
                for (int k = 0; k < n; k++)
                    seen |= !strcmp(m, cols[k]);
                if (seen || !is_table2_cell(cd[c].rows[i].cell) || in_paper != (pass == 0))
                    continue;
                snprintf(cols[n++], 32, "%s", m);
            }
    /* The paper's methods found in the first pass came in case order: put them in its order. */
    int np = 0;
    char sorted[MAX_COLS][32];
    for (int k = 0; ppb_paper_columns[k]; k++)
        for (int j = 0; j < n; j++)
            if (paper_rank(cols[j]) == k)
                memcpy(sorted[np++], cols[j], sizeof sorted[0]);
    for (int j = 0; j < n; j++)
        if (paper_rank(cols[j]) < 0)
            memcpy(sorted[np++], cols[j], sizeof sorted[0]);
    memcpy(cols, sorted, (size_t)n * sizeof sorted[0]);
    return n;
}

static const summary_row *find_row(const case_data *cd, const char *method, const char *cell)
{
    for (int i = 0; i < cd->n; i++)
        if (!strcmp(cd->rows[i].method, method) && !strcmp(cd->rows[i].cell, cell))
            return &cd->rows[i];
    return NULL;
}

/* Table 2 as the paper gives it: a row per case and cell, a column per method, RMS % with the
 * paper's value in parentheses, and the Monte Carlo's noise floor at that cell. */
static void write_wide_table(FILE *f, const char *const *cases, const case_data *cd, int ncases)
{
    char cols[MAX_COLS][32];
    int ncols = table_methods(cd, ncases, cols);
    fprintf(f, "| case | cell |");
    for (int j = 0; j < ncols; j++)
        fprintf(f, " %s |", cols[j]);
    fprintf(f, " MC noise |\n|---|---|");
    for (int j = 0; j <= ncols; j++)
        fprintf(f, "---|");
    fputc('\n', f);
    static const char *const cells[2] = {"R_x0", "T_x0"};
    for (int c = 0; c < ncases; c++)
        for (int k = 0; k < 2; k++) {
            fprintf(f, "| %s | %s |", cases[c], cells[k]);
            double noise = NAN;
            for (int j = 0; j < ncols; j++) {
                const summary_row *r = find_row(&cd[c], cols[j], cells[k]);
                double pv = paper_value(cases[c], cells[k], cols[j]);
                if (!r)
                    fprintf(f, " - |");
                else if (isnan(pv))
                    fprintf(f, " %.1f |", 100 * r->rms);
                else
                    fprintf(f, " %.1f (%g) |", 100 * r->rms, pv);
                if (r && !(r->noise >= noise)) /* the smallest: the Monte Carlo's own */
                    noise = r->noise;
            }
            md_cell(f, 100 * noise);
            fputc('\n', f);
        }
}

static void range_pct(FILE *f, double lo, double hi)
{
    if (isnan(lo))
        fprintf(f, " - |");
    else
        fprintf(f, " %.1f-%.1f |", 100 * lo, 100 * hi);
}

/* The Monte Carlo's noise floor: at the Table 2 cells (summary.csv) and per segment of each
 * surface (rms.csv), with one sentence giving the ranges over all cases. */
static void write_noise(FILE *f, const char *const *cases, const case_data *cd, int ncases)
{
    double x0_lo = INFINITY, x0_hi = -INFINITY;
    for (int c = 0; c < ncases; c++)
        for (int i = 0; i < cd[c].n; i++)
            if (is_table2_cell(cd[c].rows[i].cell) && isfinite(cd[c].rows[i].noise)) {
                double v = cd[c].rows[i].noise;
                x0_lo = v < x0_lo ? v : x0_lo;
                x0_hi = v > x0_hi ? v : x0_hi;
            }
    /* Per segment: the range over the cases whose segments stay within twice the x = 0
     * floor, and each case beyond it named with its own range. */
    double lo = INFINITY, hi = -INFINITY, limit = 2 * x0_hi;
    int nseg = 0, nout = 0;
    for (int c = 0; c < ncases; c++) {
        double clo = INFINITY, chi = -INFINITY;
        for (int s = 0; s < 4; s++)
            if (!isnan(cd[c].seg_lo[s])) {
                clo = cd[c].seg_lo[s] < clo ? cd[c].seg_lo[s] : clo;
                chi = cd[c].seg_hi[s] > chi ? cd[c].seg_hi[s] : chi;
            }
        if (!isfinite(clo))
            continue;
        nseg++;
        if (isfinite(limit) && chi > limit) {
            nout++;
            continue;
        }
        lo = clo < lo ? clo : lo;
        hi = chi > hi ? chi : hi;
    }
    fprintf(f, "\n## Noise floor\n\n");
    fprintf(f, "The Monte Carlo's own relative standard error (noise_rel, from its batches; "
               "docs/reference.md, Metrics)");
    if (isfinite(x0_lo))
        fprintf(f, ": %.1f-%.1f%% at the Table 2 cells (x = 0)", 100 * x0_lo, 100 * x0_hi);
    if (nseg > 0) {
        fprintf(f, "; per segment of S1-S4 (rms.csv)");
        if (isfinite(lo))
            fprintf(f, " %.1f-%.1f%%%s", 100 * lo, 100 * hi,
                    nout ? " in every case but" : (nseg > 1 ? " in every case" : ""));
        for (int c = 0, k = 0; c < ncases && nout; c++) {
            double clo = INFINITY, chi = -INFINITY;
            for (int s = 0; s < 4; s++)
                if (!isnan(cd[c].seg_lo[s])) {
                    clo = cd[c].seg_lo[s] < clo ? cd[c].seg_lo[s] : clo;
                    chi = cd[c].seg_hi[s] > chi ? cd[c].seg_hi[s] : chi;
                }
            if (!isfinite(clo) || !(chi > limit))
                continue;
            fprintf(f, "%s %s (%.1f-%.1f%%)", k++ ? "," : "", cases[c], 100 * clo, 100 * chi);
        }
    }
    fprintf(f, ". An RMS error well above it is the method's; `excess` in table2.csv removes "
               "it. In percent:\n\n");
    fprintf(f, "| case | R_x0 | T_x0 | S1 per segment | S2 per segment | S3 per segment | S4 per "
               "segment |\n|---|---|---|---|---|---|---|\n");
    for (int c = 0; c < ncases; c++) {
        fprintf(f, "| %s |", cases[c]);
        static const char *const cells[2] = {"R_x0", "T_x0"};
        for (int k = 0; k < 2; k++) {
            double v = NAN;
            for (int i = 0; i < cd[c].n; i++)
                if (!strcmp(cd[c].rows[i].cell, cells[k]) && !(cd[c].rows[i].noise >= v))
                    v = cd[c].rows[i].noise;
            md_cell(f, 100 * v);
        }
        for (int s = 0; s < 4; s++)
            range_pct(f, cd[c].seg_lo[s], cd[c].seg_hi[s]);
        fputc('\n', f);
    }
}

/* A photon count as the configs write it when it is a round number (4e8), else in full. */
static void photons_text(char *buf, size_t cap, long long n)
{
    long long m = n;
    int e = 0;
    while (m >= 10 && m % 10 == 0) {
        m /= 10;
        e++;
    }
    if (e >= 3 && m < 1000)
        snprintf(buf, cap, "%llde%d", m, e);
    else
        snprintf(buf, cap, "%lld", n);
}

/* One sentence: the budget most cases share, "per case", and the cases that differ. */
static void write_budget(FILE *f, const char *const *cases, const case_data *cd, int ncases)
{
    int best = -1, best_count = 0;
    for (int c = 0; c < ncases; c++) {
        int count = 0;
        for (int d = 0; d < ncases; d++)
            count += cd[d].photons == cd[c].photons;
        if (cd[c].photons > 0 && count > best_count) {
            best = c;
            best_count = count;
        }
    }
    if (best < 0)
        return;
    char t[64];
    photons_text(t, sizeof t, cd[best].photons);
    fprintf(f, "Monte Carlo budget (mc.photons in each case's provenance.txt): %s photons per case",
            t);
    for (int c = 0; c < ncases; c++)
        if (cd[c].photons != cd[best].photons) {
            if (cd[c].photons > 0)
                photons_text(t, sizeof t, cd[c].photons);
            else
                snprintf(t, sizeof t, "unknown");
            fprintf(f, ", %s for %s", t, cases[c]);
        }
    fprintf(f, ".\n\n");
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp((const char *)a, (const char *)b);
}

/* The footer: the top-level files of the case directories (their union, sorted) but
 * radiance.csv, which .gitignore keeps out of results/ (reference: Outputs). */
static void write_footer(FILE *f, const char *dir, const char *const *cases, int ncases)
{
    enum { MAX_FILES = 64 };
    char names[MAX_FILES][128];
    int n = 0, radiance = 0;
    for (int c = 0; c < ncases; c++) {
        char path[1200];
        snprintf(path, sizeof path, "%s/%s", dir, cases[c]);
        DIR *d = opendir(path);
        for (struct dirent *e = d ? readdir(d) : NULL; e; e = readdir(d)) {
            char file[1500];
            snprintf(file, sizeof file, "%s/%s", path, e->d_name);
            struct stat st;
            if (e->d_name[0] == '.' || stat(file, &st) || !S_ISREG(st.st_mode) ||
                strlen(e->d_name) >= sizeof names[0])
                continue;
            if (!strcmp(e->d_name, "radiance.csv")) {
                radiance = 1;
                continue;
            }
            int seen = 0;
            for (int k = 0; k < n; k++)
                seen |= !strcmp(names[k], e->d_name);
            if (!seen && n < MAX_FILES)
                memcpy(names[n++], e->d_name, strlen(e->d_name) + 1); /* length checked above */
        }
        if (d)
            closedir(d);
    }
    qsort(names, (size_t)n, sizeof names[0], cmp_str);
    fprintf(f, "\nEach case's directory holds plots/ and images/ (above; `images/<method>.exr` is "
               "the linear radiance, its header naming the method, case, seed, photons and "
               "version)");
    for (int k = 0; k < n; k++)
        fprintf(f, "%s%s", k == 0 ? " and " : (k == n - 1 ? " and " : ", "), names[k]);
    fprintf(f, " (docs/reference.md, Outputs, says what each holds).");
    if (radiance)
        fprintf(f, " radiance.csv, every bin's radiance (megabytes per case), is written by "
                   "`ppbench run` but not kept in the repository (.gitignore).");
    fprintf(f, "\n");
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The README's opening: the summary figure (summary.png, drawn from the cases' summary.csv by
 * scripts/summary_plot.sh, which scripts/bench.sh runs before the report) when the study has
 * one, and the findings in one paragraph, computed from the same rows: per method of the wide
 * table, ordered by its median, the range and median of rms_excess over the Table 2 cells of
 * every case and at how many of them it is within the Monte Carlo's noise floor (rms_excess at
 * most noise_rel); then the floor's range. */
static void write_opening(FILE *f, const char *dir, const case_data *cd, int ncases)
{
    static const char *const cells[2] = {"R_x0", "T_x0"};
    char path[1200];
    struct stat st;
    snprintf(path, sizeof path, "%s/summary.png", dir);
    if (stat(path, &st) == 0 && S_ISREG(st.st_mode))
        fprintf(f, "![The excess RMS at the Table 2 cells, per case and method, beside the Monte "
                   "Carlo's noise floor](summary.png)\n\n"
                   "The excess RMS (rms_excess: the RMS error against the Monte Carlo with its "
                   "noise removed; docs/reference.md, Metrics) of every method at the paper's "
                   "Table 2 cells, the two segments next to x = 0 on S1 (R_x0) and S2 (T_x0), "
                   "per case, on a log scale (an excess under 0.1 %% is drawn at 0.1 %%); the "
                   "black bars are the Monte Carlo's own noise floor there (noise_rel). From "
                   "each case's summary.csv (scripts/summary_plot.sh).\n\n");
    char cols[MAX_COLS][32];
    int ncols = table_methods(cd, ncases, cols);
    double *v = malloc(sizeof *v * (size_t)(2 * ncases + 1));
    struct {
        double lo, hi, median;
        int n, within;
    } stat_of[MAX_COLS];
    int order[MAX_COLS];
    double nlo = INFINITY, nhi = -INFINITY;
    for (int j = 0; v && j < ncols; j++) {
        int n = 0, within = 0;
        for (int c = 0; c < ncases; c++)
            for (int k = 0; k < 2; k++) {
                const summary_row *r = find_row(&cd[c], cols[j], cells[k]);
                if (!r || isnan(r->excess))
                    continue;
                v[n++] = 100 * r->excess;
                within += r->excess <= r->noise;
                if (r->noise < nlo)
                    nlo = r->noise;
                if (r->noise > nhi)
                    nhi = r->noise;
            }
        qsort(v, (size_t)n, sizeof *v, cmp_double);
        stat_of[j].n = n;
        stat_of[j].within = within;
        stat_of[j].lo = n ? v[0] : NAN;
        stat_of[j].hi = n ? v[n - 1] : NAN;
        stat_of[j].median = n ? (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2])) : NAN;
        order[j] = j;
    }
    free(v);
    if (ncols == 0 || !isfinite(nlo))
        return;
    for (int a = 1; a < ncols; a++) /* by median, stable: the table's order among equals */
        for (int b = a; b > 0 && stat_of[order[b]].median < stat_of[order[b - 1]].median; b--) {
            int t = order[b];
            order[b] = order[b - 1];
            order[b - 1] = t;
        }
    fprintf(f,
            "**Findings.** At the Table 2 cells of the %d case%s, ordered by their median "
            "excess RMS against the Monte Carlo:",
            ncases, ncases == 1 ? "" : "s");
    for (int a = 0; a < ncols; a++) {
        int j = order[a];
        if (stat_of[j].n == 0)
            continue;
        fprintf(f,
                "%s `%s` %.1f-%.1f %% (median %.1f %%; within the noise floor at %d of %d "
                "cells)",
                a == 0 ? "" : ",", cols[j], stat_of[j].lo, stat_of[j].hi, stat_of[j].median,
                stat_of[j].within, stat_of[j].n);
    }
    fprintf(f,
            ". The Monte Carlo's noise floor there is %.1f-%.1f %%. Where each method errs, "
            "and why, is in \"What the study shows\" below.\n\n",
            100 * nlo, 100 * nhi);
}

/* The ranking: per method (the wide table's columns) and per surface cell, the median over the
 * cases of rms_excess in percent, its rank among the methods at that cell (1: lowest), and at
 * how many cases the method is the best at that cell. Cases a method did not run in are left
 * out of its median; the reference methods (mc) have no summary rows and never appear. */
static const char *const rank_cells[] = {"R_x0", "T_x0", "S1_all", "S2_all", "S3_all", "S4_all"};
enum { NRANK_CELLS = sizeof rank_cells / sizeof rank_cells[0] };

static double method_median(const char *const *cases, const case_data *cd, int ncases,
                            const char *method, const char *cell)
{
    double v[256];
    int n = 0;
    (void)cases;
    for (int c = 0; c < ncases && n < 256; c++) {
        const summary_row *r = find_row(&cd[c], method, cell);
        if (r && isfinite(r->excess))
            v[n++] = r->excess;
    }
    if (n == 0)
        return NAN;
    qsort(v, (size_t)n, sizeof v[0], cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* A method checked as an exact answer (rte2d: ppb_method.reference): it is ranked, but the
 * cases a model wins are counted among the models alone. */
static int is_reference(const char *method)
{
    const ppb_method *m = ppb_method_find(NULL, method);
    return m && m->reference;
}

/* How many cases name `method` the lowest rms_excess at `cell` among the non-reference
 * columns. */
static int method_wins(const case_data *cd, int ncases, char cols[][32], int ncols,
                       const char *method, const char *cell)
{
    int wins = 0;
    for (int c = 0; c < ncases; c++) {
        const char *best = NULL;
        double lo = INFINITY;
        for (int j = 0; j < ncols; j++) {
            if (is_reference(cols[j]))
                continue;
            const summary_row *r = find_row(&cd[c], cols[j], cell);
            if (r && r->excess < lo) {
                lo = r->excess;
                best = cols[j];
            }
        }
        wins += best && !strcmp(best, method);
    }
    return wins;
}

static void write_ranking(FILE *f, const char *const *cases, const case_data *cd, int ncases)
{
    char cols[MAX_COLS][32];
    int ncols = table_methods(cd, ncases, cols);
    double med[MAX_COLS][NRANK_CELLS];
    for (int j = 0; j < ncols; j++)
        for (int k = 0; k < NRANK_CELLS; k++)
            med[j][k] = method_median(cases, cd, ncases, cols[j], rank_cells[k]);
    fprintf(f, "## Ranking\n\n");
    fprintf(f,
            "Every method per surface: the median over the %d cases of the excess RMS "
            "(rms_excess, percent) at the Table 2 cells and over each whole surface, its "
            "rank among the methods at that cell (1 = closest to the Monte Carlo), and in "
            "brackets at how many cases it is the best there among the models (the exact "
            "solvers set aside).\n\n| method |",
            ncases);
    for (int k = 0; k < NRANK_CELLS; k++)
        fprintf(f, " %s |", rank_cells[k]);
    fprintf(f, "\n|---|");
    for (int k = 0; k < NRANK_CELLS; k++)
        fprintf(f, "---|");
    fputc('\n', f);
    for (int j = 0; j < ncols; j++) {
        fprintf(f, "| %s |", cols[j]);
        for (int k = 0; k < NRANK_CELLS; k++) {
            if (isnan(med[j][k])) {
                fprintf(f, " - |");
                continue;
            }
            int rank = 1;
            for (int i = 0; i < ncols; i++)
                rank += !isnan(med[i][k]) && med[i][k] < med[j][k];
            if (is_reference(cols[j]))
                fprintf(f, " %.1f (#%d) |", 100 * med[j][k], rank);
            else
                fprintf(f, " %.1f (#%d) [%d] |", 100 * med[j][k], rank,
                        method_wins(cd, ncases, cols, ncols, cols[j], rank_cells[k]));
        }
        fputc('\n', f);
    }
    fputc('\n', f);
}

/* README.md into rf->f[2], closed (not yet in place). */
static int write_readme(const char *dir, const char *const *cases, const case_data *cd, int ncases,
                        report_files *rf, ppb_err *err)
{
    char path[1200];
    ppb_afile *af = &rf->f[2];
    snprintf(path, sizeof path, "%s/README.md", dir);
    if (ppb_afile_open(af, path, err))
        return -1;
    FILE *f = af->f;
    fprintf(f, "%s\n%s\n\n", readme_mark, readme_mark_v1);
    write_opening(f, dir, cd, ncases);
    write_budget(f, cases, cd, ncases);
    fprintf(f, "## Table 2\n\n");
    fprintf(f, "RMS error against the Monte Carlo (docs/reference.md) in percent at the two "
               "segments next to x = 0 on S1 (R_x0) and S2 (T_x0), the paper's Table 2 value "
               "in parentheses, and the Monte Carlo's own noise floor there. table2.csv (and "
               "table2.md) give the same rows one per method, with `excess` = "
               "sqrt(rms^2 - noise^2), the RMS with the noise removed.\n\n");
    write_wide_table(f, cases, cd, ncases);
    write_ranking(f, cases, cd, ncases);
    write_noise(f, cases, cd, ncases);
    snprintf(path, sizeof path, "%s/notes.md", dir);
    copy_file(f, path);
    /* The figures the findings above use stand beside their sentences (notes.md); every
     * case's figures are linked here, not shown. */
    fprintf(f, "\n## Every case's figures\n\n");
    fprintf(f, "RMS versus x (paper Fig. 8), in-plane angular distributions at x = 0 (Fig. 5), "
               "the tube as each method renders it (Fig. 6-7) and its error against the Monte "
               "Carlo:\n\n");
    for (int c = 0; c < ncases; c++) {
        fprintf(f,
                "- %s: [rms vs x](%s/plots/rms_vs_x.png), [angular](%s/plots/angular_x0.png), "
                "[angular, polar](%s/plots/angular_x0_polar.png), [all methods](%s/images/"
                "all.png)\n",
                cases[c], cases[c], cases[c], cases[c], cases[c]);
        link_error_images(f, dir, cases[c]);
    }
    write_footer(f, dir, cases, ncases);
    return ppb_afile_close(af, err);
}

int ppb_report_write(const char *dir, const char *const *cases, int ncases, ppb_err *err)
{
    /* Every file checked before any is written: a refusal leaves the directory as it was. */
    static const char *const csv_marks[] = {csv_header, NULL};
    static const char *const md_marks[] = {md_header, NULL};
    static const char *const readme_marks[] = {readme_mark, readme_mark_v1, NULL};
    static const struct {
        const char *file;
        const char *const *marks;
    } outs[] = {{"table2.csv", csv_marks}, {"table2.md", md_marks}, {"README.md", readme_marks}};
    for (size_t i = 0; i < sizeof outs / sizeof outs[0]; i++) {
        char path[1200];
        snprintf(path, sizeof path, "%s/%s", dir, outs[i].file);
        if (check_own(path, outs[i].marks, err))
            return PPB_REPORT_REFUSED;
    }
    case_data *cd = load_cases(dir, cases, ncases, err);
    if (!cd) /* a case missing or unreadable: bad input, nothing written */
        return PPB_REPORT_BAD_INPUT;
    report_files rf = {0};
    int rc = write_tables(dir, cases, cd, ncases, &rf, err);
    if (rc == 0)
        rc = write_readme(dir, cases, cd, ncases, &rf, err);
    free_cases(cd, ncases);
    ppb_apath *names[REPORT_FILES] = {&rf.f[0].name, &rf.f[1].name, &rf.f[2].name};
    if (rc) {
        for (int i = 0; i < REPORT_FILES; i++) /* open or closed, its temporary goes */
            ppb_afile_abort(&rf.f[i]);
        return -1;
    }
    if (ppb_apaths_commit(names, REPORT_FILES, err))
        return -1;
    for (int i = 0; i < REPORT_FILES; i++)
        fprintf(stderr, "ppbench report: wrote %s\n", names[i]->path);
    /* the last line says where the results went, as `run` does (docs/reference.md: Outputs) */
    fprintf(stderr, "ppbench report: wrote %s (%d files)\n", dir, REPORT_FILES);
    return 0;
}
