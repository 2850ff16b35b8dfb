#include "drivers/report.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"
#include "base/csv_read.h"

/* Shinya et al. 2009, Table 2: RMS error against MC in percent, per case and cell, for the
 * proposed method (pp), MP (mp), MP+S (mp+ss) and S (ss). */
typedef struct paper_row {
    const char *case_name, *cell;
    double pp, mp, mpss, ss;
} paper_row;

static const paper_row paper[] = {
    {"uniform_g0_normal", "R_x0", 13, 13, 23, 65},
    {"uniform_g0_normal", "T_x0", 4, 72, 24, 56},
    {"uniform_g0_oblique", "R_x0", 10, 43, 101, 57},
    {"uniform_g0_oblique", "T_x0", 8, 210, 302, 89},
    {"uniform_gm05_normal", "R_x0", 20, 23, 51, 48},
    {"uniform_gm05_normal", "T_x0", 5, 84, 189, 47},
    {"uniform_gp05_normal", "R_x0", 24, 19, 6, 81},
    {"uniform_gp05_normal", "T_x0", 7, 58, 26, 66},
};

static double paper_value(const char *case_name, const char *cell, const char *method)
{
    for (size_t i = 0; i < sizeof paper / sizeof paper[0]; i++) {
        const paper_row *r = &paper[i];
        if (strcmp(r->case_name, case_name) || strcmp(r->cell, cell))
            continue;
        if (!strcmp(method, "pp"))
            return r->pp;
        if (!strcmp(method, "mp"))
            return r->mp;
        if (!strcmp(method, "mp+ss"))
            return r->mpss;
        if (!strcmp(method, "ss"))
            return r->ss;
    }
    return NAN;
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

/* The first line of each file report writes, by which it knows its own (issue 14). table2.csv
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

/* Commits af, saying so. */
static int commit_said(ppb_afile *af, ppb_err *err)
{
    if (ppb_afile_commit(af, err))
        return -1;
    fprintf(stderr, "ppbench report: wrote %s\n", af->name.path);
    return 0;
}

static void md_cell(FILE *f, double v)
{
    fprintf(f, isnan(v) ? " - |" : " %.1f |", v);
}

static int write_tables(const char *dir, const char *const *cases, int ncases, ppb_err *err)
{
    char path[1200];
    ppb_afile csv, md;
    snprintf(path, sizeof path, "%s/table2.csv", dir);
    if (ppb_afile_open(&csv, path, err))
        return -1;
    snprintf(path, sizeof path, "%s/table2.md", dir);
    if (ppb_afile_open(&md, path, err)) {
        ppb_afile_abort(&csv);
        return -1;
    }
    fprintf(csv.f, "%s\n", csv_header);
    fprintf(md.f, "%s\n", md_header);
    fprintf(md.f, "|---|---|---|---|---|---|---|\n");
    summary_row rows[512]; /* 36 KB */
    for (int c = 0; c < ncases; c++) {
        int n = read_summary(dir, cases[c], rows, 512, err);
        if (n < 0) {
            ppb_afile_abort(&csv);
            ppb_afile_abort(&md);
            return -1;
        }
        for (int i = 0; i < n; i++) {
            const summary_row *r = &rows[i];
            if (strcmp(r->cell, "R_x0") && strcmp(r->cell, "T_x0"))
                continue;
            double pv = paper_value(cases[c], r->cell, r->method);
            fprintf(csv.f, "%s,%s,%s,%.6g,%.6g,%.6g,%.6g\n", cases[c], r->cell, r->method, r->rms,
                    r->noise, r->excess, pv / 100);
            fprintf(md.f, "| %s | %c | %s |", cases[c], r->cell[0], r->method);
            md_cell(md.f, 100 * r->rms);
            md_cell(md.f, 100 * r->noise);
            md_cell(md.f, 100 * r->excess);
            md_cell(md.f, pv);
            fputc('\n', md.f);
        }
    }
    if (commit_said(&csv, err)) {
        ppb_afile_abort(&md);
        return -1;
    }
    return commit_said(&md, err);
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

static int write_readme(const char *dir, const char *const *cases, int ncases, ppb_err *err)
{
    char path[1200];
    ppb_afile af;
    snprintf(path, sizeof path, "%s/README.md", dir);
    if (ppb_afile_open(&af, path, err))
        return -1;
    FILE *f = af.f;
    fprintf(f, "%s\n%s\n\n", readme_mark, readme_mark_v1);
    fprintf(f, "RMS error against the Monte Carlo (docs/reference.md) at the two segments next "
               "to x = 0 on S1 (R) and S2 (T), beside the paper's Table 2 and the Monte "
               "Carlo's own noise floor. `excess` removes the noise: sqrt(rms^2 - noise^2).\n\n");
    snprintf(path, sizeof path, "%s/table2.md", dir);
    copy_file(f, path);
    snprintf(path, sizeof path, "%s/notes.md", dir);
    copy_file(f, path);
    fprintf(f, "\n## Plots\n\n");
    fprintf(f, "RMS versus x (paper Fig. 8) and in-plane angular distributions at x = 0 (Fig. "
               "5):\n\n");
    for (int c = 0; c < ncases; c++)
        fprintf(f,
                "- %s: ![rms](%s/plots/rms_vs_x.png) ![angular](%s/plots/angular_x0.png) "
                "![angular, polar](%s/plots/angular_x0_polar.png)\n",
                cases[c], cases[c], cases[c], cases[c]);
    fprintf(f, "\n## Images (paper Fig. 6-7)\n\n");
    for (int c = 0; c < ncases; c++) {
        fprintf(f, "- %s: ![all methods](%s/images/all.png)\n", cases[c], cases[c]);
        link_error_images(f, dir, cases[c]);
    }
    fprintf(f, "\nEach case's directory holds radiance.csv, rms.csv, summary.csv, totals.csv, "
               "summary_mc1.csv, timings.csv and provenance.txt (config, seed, photons, "
               "device, version, timings).\n");
    return commit_said(&af, err);
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
    if (write_tables(dir, cases, ncases, err))
        return -1;
    return write_readme(dir, cases, ncases, err);
}
