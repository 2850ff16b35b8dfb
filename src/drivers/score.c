#include "drivers/score.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/progress.h"
#include "base/csv_read.h"
#include "base/file_read.h"
#include "base/hash.h"
#include "drivers/experiment.h"
#include "drivers/summary_table.h"
#include "io/csv.h"
#include "methods/external/method_external.h"
#include "methods/registry.h"
#include "model/config.h"

enum { EXIT_OK = 0, EXIT_RUN = 1, EXIT_USAGE = 2, EXIT_INTERRUPTED = 130 };

/* The start of the first line of provenance.txt in score's output set: what marks a directory
 * as one (ppb_out_claim). */
static const char score_mark[] = "# ppbench score provenance";

/* DIR/radiance.csv against the hash its set's provenance.txt records (docs/reference.md:
 * Outputs, provenance.txt's radiance.xxh64): a radiance.csv left by another run beside this
 * provenance is refused, never scored against. */
static int check_radiance(const char *dir, const char *want, ppb_err *err)
{
    char path[PPB_PATH_MAX + 32], got[32];
    snprintf(path, sizeof path, "%s/radiance.csv", dir);
    size_t len;
    char *data = ppb_read_file(path, &len);
    if (!data)
        return 0; /* no radiance.csv: said where it is read */
    snprintf(got, sizeof got, "%016llx", (unsigned long long)ppb_hash64(data, len));
    free(data);
    if (strcmp(got, want) != 0)
        return ppb_fail(err,
                        "--ref %s: radiance.csv is not the one its provenance.txt records "
                        "(radiance.xxh64 %s, the file hashes to %s): another run wrote it; run "
                        "the experiment again, or score against a set whose files agree",
                        dir, want, got);
    return 0;
}

/* The experiment's config from DIR/provenance.txt: its "section.key = value" lines from
 * experiment.name on (the resolved config, model/config.h) applied as --set options would be
 * to the defaults; [method.NAME] lines are not settings of the scene and are passed over. */
static int load_provenance(const char *dir, ppb_config *cfg, ppb_err *err)
{
    char path[PPB_PATH_MAX + 32], empty[PPB_PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/provenance.txt", dir);
    FILE *f = fopen(path, "r");
    if (!f)
        return ppb_fail(err, "--ref %s: no %s (%s): not a finished experiment", dir, path,
                        strerror(errno));
    char *line = NULL, **sets = NULL;
    size_t cap = 0;
    int nsets = 0, on = 0, rc = -1, lineno = 0;
    ssize_t got;
    while ((got = getline(&line, &cap, f)) > 0) {
        lineno++;
        if (memchr(line, '\0', (size_t)got)) { /* the text after it would be lost */
            ppb_fail(err, "%s:%d: a NUL byte: not a text file", path, lineno);
            goto done;
        }
        if (lineno == 1 && strncmp(line, "# ppbench provenance", 20) != 0) {
            ppb_fail(err, "%s:1: not a ppbench provenance record", path);
            goto done;
        }
        line[strcspn(line, "\n")] = '\0';
        if (!on && strncmp(line, "radiance.xxh64 = ", 17) == 0 &&
            check_radiance(dir, line + 17, err))
            goto done;
        on |= strncmp(line, "experiment.name = ", 18) == 0;
        char *eq = strstr(line, " = ");
        if (!on || !eq || strncmp(line, "method.", 7) == 0)
            continue;
        char **grown = realloc(sets, (size_t)(nsets + 1) * sizeof *sets);
        size_t klen = (size_t)(eq - line);
        char *set = malloc(klen + strlen(eq + 3) + 2);
        if (!grown || !set) {
            sets = grown ? grown : sets;
            free(set);
            ppb_fail(err, "out of memory");
            goto done;
        }
        sets = grown;
        sprintf(set, "%.*s=%s", (int)klen, line, eq + 3);
        sets[nsets++] = set;
    }
    if (!on) {
        ppb_fail(err, "%s: holds no resolved config (no experiment.name line)", path);
        goto done;
    }
    /* ppb_config_load_sets reads a file first: an empty one, so every key comes from the sets. */
    const char *tmp = getenv("TMPDIR");
    snprintf(empty, sizeof empty, "%s/ppbench-score-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    int fd = mkstemp(empty);
    if (fd < 0) {
        ppb_fail(err, "cannot make a temporary file %s: %s", empty, strerror(errno));
        goto done;
    }
    close(fd);
    rc = ppb_config_load_sets(cfg, NULL, empty, (const char *const *)sets, nsets, err);
    unlink(empty);
    if (rc)
        rc = ppb_fail(err, "%s: %.1900s", path, err->msg);
    else
        snprintf(cfg->path, sizeof cfg->path, "%.1000s", path);
done:
    for (int i = 0; i < nsets; i++)
        free(sets[i]);
    free(sets);
    free(line);
    fclose(f);
    return rc;
}

/* The method ids of a radiance file, in the order of first appearance. */
static int method_ids(const char *path, char ids[][32], int max, int *n, ppb_err *err)
{
    ppb_csv c;
    if (ppb_csv_open(&c, path, err))
        return -1;
    int col = ppb_csv_need(&c, "method", err), got = 0;
    *n = 0;
    while (col >= 0 && (got = ppb_csv_next(&c, err)) == 1) {
        const char *id = ppb_csv_get(&c, col);
        int seen = 0;
        for (int i = 0; i < *n && !seen; i++)
            seen = strcmp(ids[i], id) == 0;
        if (seen)
            continue;
        if (*n == max || strlen(id) >= 32) {
            ppb_csv_close(&c);
            return ppb_fail(err, "%s:%ld: more than %d methods, or an id over 31 characters", path,
                            c.line, max);
        }
        snprintf(ids[(*n)++], 32, "%s", id);
    }
    ppb_csv_close(&c);
    return (col < 0 || got < 0) ? -1 : 0;
}

/* DIR without trailing slashes + "-score", or the first of "-score-2", ... that is free. */
static int default_out(const char *ref_dir, char *buf, size_t cap)
{
    size_t n = strlen(ref_dir);
    while (n > 1 && ref_dir[n - 1] == '/')
        n--;
    for (int k = 1; k < 1000; k++) {
        if (k == 1)
            snprintf(buf, cap, "%.*s-score", (int)n, ref_dir);
        else
            snprintf(buf, cap, "%.*s-score-%d", (int)n, ref_dir, k);
        struct stat st;
        if (stat(buf, &st) != 0)
            return 0;
    }
    return -1;
}

static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

/* Score's files, under dir: provenance.txt (what was scored against what) and the CSVs. */
static int write_set(const char *dir, const char *ref_dir, const char *radiance,
                     const ppb_config *cfg, const ppb_result *res, int n, const ppb_method *refm,
                     ppb_err *err)
{
    char path[PPB_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/provenance.txt", dir);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    fprintf(af.f, "%s: what produced the files beside this one\n", score_mark);
    fprintf(af.f, "score.ref = %s\nscore.radiance = %s\n", ref_dir, radiance);
    if (ppb_afile_commit(&af, err))
        return -1;
    static const char *const files[] = {"summary.csv", "rms.csv", "regions.csv", "totals.csv"};
    for (int f = 0; f < 4; f++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[f]);
        int rc = f == 0   ? ppb_write_summary_csv(path, res, n, &res[0], refm->also, err)
                 : f == 1 ? ppb_write_rms_csv(path, &cfg->scene, res, n, &res[0], refm->also, err)
                 : f == 2
                     ? ppb_write_regions_csv(path, &cfg->scene, res, n, &res[0], refm->also, err)
                     : ppb_write_totals_csv(path, res + 1, n - 1, err);
        if (rc)
            return -1;
    }
    return 0;
}

/* Any incomplete file fails the set (score draws no figures). */
static int any_bad(const char *rel, const char *why, void *ctx, ppb_err *err)
{
    (void)rel;
    (void)ctx;
    return ppb_fail(err, "%s", why);
}

/* An interrupt before the swap: nothing is put in place (the exit code is 130). */
static int interrupted(ppb_err *err)
{
    return ppb_interrupted() ? ppb_fail(err, "interrupted: nothing written") : 0;
}

int ppb_score_main(const char *radiance, int nargs, const char *ref_dir, const char *out_dir,
                   int quiet)
{
    if (nargs != 1 || !ref_dir) {
        fprintf(stderr, "ppbench score: usage: ppbench score --ref DIR [--out DIR2] RADIANCE.csv "
                        "(see ppbench score --help)\n");
        return EXIT_USAGE;
    }
    ppb_err err = {{0}};
    static ppb_config cfg;
    if (load_provenance(ref_dir, &cfg, &err)) {
        fprintf(stderr, "ppbench score: %s\n", err.msg);
        return EXIT_USAGE;
    }
    const ppb_method *refm = NULL;
    for (int i = 0; i < ppb_method_count() && !refm; i++)
        if (ppb_method_at(i)->reference == 1)
            refm = ppb_method_at(i);
    char out[PPB_PATH_MAX];
    if (out_dir)
        snprintf(out, sizeof out, "%s", out_dir);
    else if (default_out(ref_dir, out, sizeof out)) {
        fprintf(stderr, "ppbench score: no free name %s-score-N\n", ref_dir);
        return EXIT_USAGE;
    }
    if (same_file(out, ref_dir)) {
        fprintf(stderr,
                "ppbench score: --out %s is the experiment's own directory: never written\n", out);
        return EXIT_USAGE;
    }
    /* Score's output set is its own, replaced whole as run's is (ppb_out_claim): never a
     * finished run or a user's directory. */
    ppb_adir ad;
    if (ppb_out_claim(out, score_mark, &ad, &err)) {
        fprintf(stderr, "ppbench score: --out %s\n", err.msg);
        return EXIT_USAGE;
    }
    static ppb_result res[PPB_MAX_RESULTS];
    char ids[PPB_MAX_RESULTS][32];
    int nids = 0, n = 0, code = EXIT_USAGE; /* a file read below that will not do is bad input */
    ppb_layout lo = ppb_scene_layout(&cfg.scene);
    char path[PPB_PATH_MAX + 64], beside[PPB_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/radiance.csv", ref_dir);
    if (method_ids(radiance, ids, PPB_MAX_RESULTS - 1, &nids, &err) ||
        ppb_result_init(&res[n++], refm->id, &lo, &err) ||
        ppb_external_read_radiance(path, refm->id, 1, &cfg.scene, &res[0], &err))
        goto done;
    /* totals.csv beside RADIANCE.csv (a run's own, or a method's output directory) */
    const char *slash = strrchr(radiance, '/');
    snprintf(beside, sizeof beside, "%.*s%stotals.csv", slash ? (int)(slash - radiance) : 0,
             radiance, slash ? "/" : "");
    for (int i = 0; i < nids; i++) {
        if (strcmp(ids[i], refm->id) == 0 || (refm->also && strcmp(ids[i], refm->also) == 0))
            continue;
        ppb_result *r = &res[n];
        if (ppb_result_init(r, ids[i], &lo, &err))
            goto done;
        n++;
        if (ppb_external_read_radiance_on(radiance, ids[i], 1, &cfg.scene, PPB_SURFACES_FROM_ROWS,
                                          r, &err) ||
            ppb_external_totals(beside, &cfg.scene, r, &err))
            goto done;
    }
    if (n == 1) {
        ppb_fail(&err, "%s: no rows of a method to score (only the reference's)", radiance);
        goto done;
    }
    code = EXIT_RUN;
    if (ppb_adir_begin(&ad, &err))
        goto done;
    if (write_set(ad.tmp, ref_dir, radiance, &cfg, res, n, refm, &err) ||
        ppb_dir_verify(ad.tmp, any_bad, NULL, &err) || interrupted(&err)) {
        ppb_adir_abort(&ad);
        goto done;
    }
    if (ppb_adir_commit(&ad, &err))
        goto done;
    if (!quiet) { /* the summary table (reference: Outputs), before the line saying where */
        ppb_summary_table_print(stdout, cfg.name, res, n, &res[0], refm->also);
        fprintf(stderr, "score: wrote %s\n", out);
    }
    code = EXIT_OK;
done:
    if (code)
        fprintf(stderr, "ppbench score: %s\n", err.msg);
    if (code && ppb_interrupted())
        code = EXIT_INTERRUPTED;
    for (int i = 0; i < n; i++)
        ppb_result_free(&res[i]);
    return code;
}
