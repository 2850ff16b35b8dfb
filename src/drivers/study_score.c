#include "drivers/study_score.h"

#include <errno.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/clock.h"
#include "base/err.h"
#include "base/file_read.h"
#include "base/progress.h"
#include "drivers/report.h"
#include "drivers/study_guard.h"
#include "methods/registry.h"

enum { EXIT_OK = 0, EXIT_RUN = 1, EXIT_USAGE = 2, EXIT_INTERRUPTED = 130 };
enum { MAX_CASES = 64, MAX_ARGS = 512 };

/* A growing list of strings the child's argv is made of (each malloc'd). */
typedef struct strlist {
    char **v;
    int n, cap;
} strlist;

static int push(strlist *l, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int push(strlist *l, const char *fmt, ...)
{
    if (l->n + 2 > l->cap) {
        int cap = l->cap ? 2 * l->cap : 32;
        char **v = realloc(l->v, (size_t)cap * sizeof *v);
        if (!v)
            return -1;
        l->v = v;
        l->cap = cap;
    }
    va_list ap;
    va_start(ap, fmt);
    int len = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    char *str = len < 0 ? NULL : malloc((size_t)len + 1);
    if (!str)
        return -1;
    va_start(ap, fmt);
    vsnprintf(str, (size_t)len + 1, fmt, ap);
    va_end(ap);
    l->v[l->n] = str;
    l->v[++l->n] = NULL;
    return 0;
}

static void strlist_free(strlist *l)
{
    for (int i = 0; i < l->n; i++)
        free(l->v[i]);
    free(l->v);
    memset(l, 0, sizeof *l);
}

/* The cases of <source>/configs/study.list, one a line. */
static int read_cases(char cases[][128], int *n, ppb_err *err)
{
    char path[PPB_PATH_MAX + 32];
    snprintf(path, sizeof path, "%.4000s/configs/study.list", ppb_source_dir());
    FILE *f = fopen(path, "r");
    if (!f)
        return ppb_fail(err, "%s: %s", path, strerror(errno));
    char line[256];
    *n = 0;
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        if (!line[0] || line[0] == '#')
            continue;
        if (*n == MAX_CASES) {
            fclose(f);
            return ppb_fail(err, "%s: more than %d cases", path, MAX_CASES);
        }
        snprintf(cases[(*n)++], 128, "%.127s", line);
    }
    fclose(f);
    return *n ? 0 : ppb_fail(err, "%s: no case", path);
}

/* The [method.NAME] sections of path as --set method.NAME.KEY=VALUE (an indented line
 * continues the value, joined with one space; a ';' after a blank starts a comment, as the
 * config reader has them: docs/external.md, The config), and the NAMEs, comma-separated, into
 * names. Other sections are not read: the cases' own configs set the scene. */
static int config_methods(const char *path, strlist *sets, char *names, size_t cap, ppb_err *err)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return ppb_fail(err, "%s: %s", path, strerror(errno));
    char *line = NULL, section[256] = "";
    size_t lcap = 0;
    int last = -1, lineno = 0; /* the set an indented line continues */
    names[0] = '\0';
    while (getline(&line, &lcap, f) > 0) {
        lineno++;
        line[strcspn(line, "\r\n")] = '\0';
        for (char *c = line; (c = strchr(c, ';')); c++)
            if (c == line || c[-1] == ' ' || c[-1] == '\t') {
                *c = '\0';
                break;
            }
        size_t len = strlen(line);
        while (len && (line[len - 1] == ' ' || line[len - 1] == '\t'))
            line[--len] = '\0';
        char *s = line + strspn(line, " \t");
        if (!*s)
            continue;
        if (*s == '[') {
            char *end = strchr(s, ']');
            snprintf(section, sizeof section, "%.*s", end ? (int)(end - s - 1) : 0, s + 1);
            last = -1;
            if (strncmp(section, "method.", 7) == 0 && section[7]) {
                size_t used = strlen(names);
                snprintf(names + used, cap - used, "%s%s", used ? "," : "", section + 7);
            }
            continue;
        }
        if (strncmp(section, "method.", 7) != 0)
            continue;
        if (s != line && last >= 0) { /* a continuation line */
            size_t glen = strlen(sets->v[last]) + strlen(s) + 2;
            char *grown = malloc(glen);
            if (!grown)
                goto oom;
            snprintf(grown, glen, "%s %s", sets->v[last], s);
            free(sets->v[last]);
            sets->v[last] = grown;
            continue;
        }
        char *eq = strchr(s, '=');
        if (!eq) {
            fclose(f);
            free(line);
            return ppb_fail(err, "%s:%d: [%s]: expected KEY = VALUE", path, lineno, section);
        }
        char *k_end = eq;
        while (k_end > s && (k_end[-1] == ' ' || k_end[-1] == '\t'))
            k_end--;
        char *v = eq + 1 + strspn(eq + 1, " \t");
        if (push(sets, "--set") || push(sets, "%s.%.*s=%s", section, (int)(k_end - s), s, v))
            goto oom;
        last = sets->n - 1;
    }
    free(line);
    fclose(f);
    return names[0] ? 0 : ppb_fail(err, "%s: no [method.NAME] section", path);
oom:
    free(line);
    fclose(f);
    return ppb_fail(err, "out of memory");
}

/* The shell-quoted form of s ('...', a ' inside as '\''). */
static char *shell_quote(const char *s)
{
    size_t n = 3;
    for (const char *c = s; *c; c++)
        n += *c == '\'' ? 4 : 1;
    char *q = malloc(n), *o = q;
    if (!q)
        return NULL;
    *o++ = '\'';
    for (const char *c = s; *c; c++)
        if (*c == '\'') {
            memcpy(o, "'\\''", 4);
            o += 4;
        } else
            *o++ = *c;
    *o++ = '\'';
    *o = '\0';
    return q;
}

/* --radiance-dir: the case's file, DIR/<case>.csv or else DIR/<case>/radiance.csv. */
static int radiance_file(const char *dir, const char *name, char *buf, size_t cap)
{
    snprintf(buf, cap, "%.4000s/%.127s.csv", dir, name);
    if (access(buf, R_OK) == 0)
        return 0;
    snprintf(buf, cap, "%.4000s/%.127s/radiance.csv", dir, name);
    return access(buf, R_OK) == 0 ? 0 : -1;
}

/* The methods of a radiance file (its method column, first appearance order), comma-separated;
 * the reference's rows (mc, mc1) are the study's, not the file's: left out. */
static int file_methods(const char *path, char *names, size_t cap, ppb_err *err)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return ppb_fail(err, "%s: %s", path, strerror(errno));
    char *line = NULL;
    size_t lcap = 0;
    names[0] = '\0';
    int lineno = 0;
    while (getline(&line, &lcap, f) > 0) {
        if (lineno++ == 0)
            continue;
        char id[64];
        snprintf(id, sizeof id, "%.*s", (int)strcspn(line, ",\n"), line);
        const ppb_method *ref = ppb_method_reference();
        if (!id[0] || !strcmp(id, ref->id) || (ref->also && !strcmp(id, ref->also)))
            continue;
        char probe[80];
        snprintf(probe, sizeof probe, ",%s,", id);
        char have[4200];
        snprintf(have, sizeof have, ",%s,", names);
        if (strstr(have, probe))
            continue;
        size_t used = strlen(names);
        snprintf(names + used, cap - used, "%s%s", used ? "," : "", id);
    }
    free(line);
    fclose(f);
    return names[0] ? 0 : ppb_fail(err, "%s: no rows of a method", path);
}

/* The surfaces (S1..S4) id has rows of in the radiance file, as a surfaces value ("S1,S2"). */
static void file_surfaces(const char *path, const char *id, char *buf, size_t cap)
{
    unsigned mask = 0;
    FILE *f = fopen(path, "r");
    char *line = NULL;
    size_t lcap = 0, idlen = strlen(id);
    while (f && getline(&line, &lcap, f) > 0)
        if (strncmp(line, id, idlen) == 0 && line[idlen] == ',' && line[idlen + 1] == 'S' &&
            line[idlen + 2] >= '1' && line[idlen + 2] <= '4' && line[idlen + 3] == ',')
            mask |= 1u << (line[idlen + 2] - '1');
    free(line);
    if (f)
        fclose(f);
    buf[0] = '\0';
    for (int k = 0; k < 4; k++)
        if (mask & (1u << k)) {
            size_t n = strlen(buf);
            snprintf(buf + n, cap - n, "%sS%d", n ? "," : "", k + 1);
        }
}

/* Each method of a --radiance-dir file becomes an external method whose command copies its
 * rows (and its totals.csv rows, when one is beside the file) into {out}; the surfaces it has
 * rows of are its surfaces (as `ppbench score` infers them: docs/external.md, "Partial
 * coverage"). */
static int radiance_methods(const char *file, const char *names, strlist *sets, ppb_err *err)
{
    char dir[PPB_PATH_MAX], totals[PPB_PATH_MAX + 16];
    snprintf(dir, sizeof dir, "%.4000s", file);
    char *slash = strrchr(dir, '/');
    if (slash)
        *slash = '\0';
    else
        snprintf(dir, sizeof dir, ".");
    snprintf(totals, sizeof totals, "%s/totals.csv", dir);
    char *qf = shell_quote(file), *qt = shell_quote(totals);
    char list[4200];
    snprintf(list, sizeof list, "%s", names);
    int rc = qf && qt ? 0 : ppb_fail(err, "out of memory");
    for (char *save = NULL, *id = strtok_r(list, ",", &save); id && rc == 0;
         id = strtok_r(NULL, ",", &save)) {
        const char *sel = "awk -F, -v m=%s 'NR == 1 || $1 == m' %s > {out}/radiance.csv";
        char cmd[16384];
        int n = snprintf(cmd, sizeof cmd, sel, id, qf);
        if (access(totals, R_OK) == 0)
            snprintf(cmd + n, sizeof cmd - (size_t)n,
                     " && awk -F, -v m=%s 'NR == 1 || $1 == m' %s > {out}/totals.csv", id, qt);
        char surf[32];
        file_surfaces(file, id, surf, sizeof surf);
        if (push(sets, "--set") || push(sets, "method.%s.command=%s", id, cmd) ||
            (surf[0] && (push(sets, "--set") || push(sets, "method.%s.surfaces=%s", id, surf))))
            rc = ppb_fail(err, "out of memory");
    }
    free(qf);
    free(qt);
    return rc;
}

/* Runs argv (this binary) and waits: its exit code, 130 for a signal. */
static int run_child(char *const *argv, int quiet)
{
    pid_t pid = fork();
    if (pid < 0)
        return EXIT_RUN;
    if (pid == 0) {
        if (quiet) {
            FILE *n = freopen("/dev/null", "w", stdout);
            (void)n;
        }
        execv("/proc/self/exe", argv);
        perror("ppbench study-score: exec");
        _exit(127);
    }
    int st;
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR)
            return EXIT_RUN;
    return WIFEXITED(st) ? WEXITSTATUS(st) : EXIT_INTERRUPTED;
}

/* The value of "key = " in a provenance.txt, "" when absent. */
static void prov_value(const char *path, const char *key, char *buf, size_t cap)
{
    buf[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    char line[8192];
    size_t kl = strlen(key);
    while (fgets(line, sizeof line, f))
        if (strncmp(line, key, kl) == 0 && strncmp(line + kl, " = ", 3) == 0) {
            line[strcspn(line, "\n")] = '\0';
            snprintf(buf, cap, "%s", line + kl + 3);
            break;
        }
    fclose(f);
}

/* The reference's key of a provenance.txt (mc.shipped_key: every config key, the kernel
 * source; not the device), "" if none. */
static void reference_key(const char *prov, char *buf, size_t cap)
{
    prov_value(prov, "mc.shipped_key", buf, cap);
}

/* Appends to case_dir/file the rows of study_dir/file whose method is not in case_dir/file. */
static int add_rows(const char *case_dir, const char *study_dir, const char *file, ppb_err *err)
{
    char a[PPB_PATH_MAX + 64], b[PPB_PATH_MAX + 64];
    snprintf(a, sizeof a, "%s/%s", case_dir, file);
    snprintf(b, sizeof b, "%s/%s", study_dir, file);
    char *mine = ppb_read_file(a, NULL), *theirs = ppb_read_file(b, NULL);
    int rc = 0;
    if (!mine || !theirs) {
        rc = mine ? 0 : ppb_fail(err, "%s: cannot be read", a);
        goto done;
    }
    FILE *f = fopen(a, "a");
    if (!f) {
        rc = ppb_fail(err, "%s: %s", a, strerror(errno));
        goto done;
    }
    char *line = strchr(theirs, '\n'); /* past the header */
    while (line && *++line) {
        char *end = strchr(line, '\n');
        size_t idlen = strcspn(line, ",\n");
        char probe[80];
        snprintf(probe, sizeof probe, "\n%.*s,", (int)idlen, line);
        if (!strstr(mine, probe))
            fprintf(f, "%.*s\n", end ? (int)(end - line) : (int)strlen(line), line);
        line = end;
    }
    if (fclose(f))
        rc = ppb_fail(err, "%s: %s", a, strerror(errno));
done:
    free(mine);
    free(theirs);
    return rc;
}

int ppb_study_score_main(const ppb_study_score_opts *o)
{
    ppb_err err = {{0}};
    static char cases[MAX_CASES][128];
    int ncases = 0, code = EXIT_USAGE;
    strlist base = {0}, msets = {0};
    char names[4200] = "", out[PPB_PATH_MAX];
    snprintf(out, sizeof out, "%s", o->out ? o->out : "study-score");
    if (read_cases(cases, &ncases, &err))
        goto done;
    if (!o->methods && !o->config && !o->radiance_dir) {
        ppb_fail(&err, "nothing to score: give --methods a,b, a CONFIG with [method.NAME] "
                       "sections, or --radiance-dir DIR (see ppbench study-score --help)");
        goto done;
    }
    if (o->radiance_dir && (o->methods || o->config)) {
        ppb_fail(&err, "--radiance-dir scores the files it holds: give neither --methods nor a "
                       "CONFIG with it");
        goto done;
    }
    if (o->config && config_methods(o->config, &msets, names, sizeof names, &err))
        goto done;
    if (o->methods)
        snprintf(names, sizeof names, "%s", o->methods);
    if (ppb_study_guard(out, &err)) /* the committed study is make bench's */
        goto done;
    if (mkdir(out, 0777) && errno != EEXIST) {
        ppb_fail(&err, "--out %s: %s", out, strerror(errno));
        goto done;
    }
    /* The arguments every case's run shares. */
    if (push(&base, "ppbench") || push(&base, "run"))
        goto oom;
    if (o->quiet && push(&base, "--quiet"))
        goto oom;
    if (o->device && (push(&base, "--device") || push(&base, "%s", o->device)))
        goto oom;
    if (o->ref_cache && (push(&base, "--ref-cache") || push(&base, "%s", o->ref_cache)))
        goto oom;
    if (o->no_ref_cache && push(&base, "--no-ref-cache"))
        goto oom;
    for (int i = 0; i < o->nsets; i++)
        if (push(&base, "--set") || push(&base, "%s", o->sets[i]))
            goto oom;
    for (int i = 0; i < msets.n; i++)
        if (push(&base, "%s", msets.v[i]))
            goto oom;
    if (!getenv("PPBENCH_MC_NO_TRACE"))
        setenv("PPBENCH_MC_NO_TRACE", "1", 1);
    double t0 = ppb_now();
    long long traced = 0;
    int failed = 0;
    code = EXIT_OK;
    for (int c = 0; c < ncases && !ppb_interrupted(); c++) {
        strlist argv = {0};
        char case_names[4200];
        snprintf(case_names, sizeof case_names, "%s", names);
        for (int i = 0; i < base.n; i++)
            if (push(&argv, "%s", base.v[i]))
                goto oom;
        if (o->radiance_dir) {
            char file[PPB_PATH_MAX + 256];
            if (radiance_file(o->radiance_dir, cases[c], file, sizeof file)) {
                fprintf(stderr,
                        "ppbench study-score: %s: no %s/%s.csv nor %s/%s/radiance.csv: not "
                        "scored\n",
                        cases[c], o->radiance_dir, cases[c], o->radiance_dir, cases[c]);
                failed++;
                strlist_free(&argv);
                continue;
            }
            if (file_methods(file, case_names, sizeof case_names, &err) ||
                radiance_methods(file, case_names, &argv, &err)) {
                strlist_free(&argv);
                code = EXIT_USAGE;
                goto done;
            }
        }
        double tc = ppb_now();
        if (push(&argv, "--set") ||
            push(&argv, "experiment.methods=%s,%s", ppb_method_reference()->id, case_names) ||
            push(&argv, "--out") || push(&argv, "%s/%s", out, cases[c]) ||
            push(&argv, "%.4000s/configs/%s.ini", ppb_source_dir(), cases[c]))
            goto oom;
        fprintf(stderr, "[%d/%d] %s: %s\n", c + 1, ncases, cases[c], case_names);
        int rc = run_child(argv.v, o->quiet);
        strlist_free(&argv);
        if (rc == EXIT_INTERRUPTED || ppb_interrupted()) {
            code = EXIT_INTERRUPTED;
            goto done;
        }
        char prov[PPB_PATH_MAX + 256], v[64], mine[256], theirs[256], study[PPB_PATH_MAX + 256];
        snprintf(prov, sizeof prov, "%.4000s/%.127s/provenance.txt", out, cases[c]);
        if (rc != 0) {
            fprintf(stderr, "ppbench study-score: %s: its run failed (exit %d)\n", cases[c], rc);
            failed++;
            if (rc == EXIT_USAGE)
                code = EXIT_USAGE;
            continue;
        }
        prov_value(prov, "mc.photons_traced", v, sizeof v);
        traced += atoll(v);
        /* The committed study's other methods, when it was scored against the same file. */
        snprintf(study, sizeof study, "%.4000s/results/%.127s", ppb_source_dir(), cases[c]);
        char sprov[PPB_PATH_MAX + 300], cdir[PPB_PATH_MAX + 256];
        snprintf(sprov, sizeof sprov, "%s/provenance.txt", study);
        snprintf(cdir, sizeof cdir, "%.4000s/%.127s", out, cases[c]);
        reference_key(prov, mine, sizeof mine);
        reference_key(sprov, theirs, sizeof theirs);
        int same = mine[0] && strcmp(mine, theirs) == 0;
        if (same &&
            (add_rows(cdir, study, "summary.csv", &err) || add_rows(cdir, study, "rms.csv", &err)))
            fprintf(stderr, "ppbench study-score: %s: the committed rows not added: %s\n", cases[c],
                    err.msg);
        fprintf(stderr, "%s: scored in %.1f s (mc: %s photons traced)%s\n", cases[c],
                ppb_now() - tc, v[0] ? v : "0",
                same ? "; the committed study's methods added beside"
                     : "; the committed study's methods not added (another reference)");
    }
    if (code == EXIT_OK && failed)
        code = EXIT_RUN;
    fprintf(stderr, "study-score: %d of %d cases scored in %.1f s, %lld photons traced\n",
            ncases - failed, ncases, ppb_now() - t0, traced);
    if (failed == 0) {
        const char *list[MAX_CASES];
        for (int c = 0; c < ncases; c++)
            list[c] = cases[c];
        int rc = ppb_report_write(out, list, ncases, &err);
        if (rc) {
            code = rc == PPB_REPORT_REFUSED || rc == PPB_REPORT_BAD_INPUT ? EXIT_USAGE : EXIT_RUN;
            goto done;
        }
        fprintf(stderr, "study-score: wrote %s (README.md, table2.md)\n", out);
    }
    goto done;
oom:
    ppb_fail(&err, "out of memory");
    code = EXIT_RUN;
done:
    if (code && err.msg[0])
        fprintf(stderr, "ppbench study-score: %s\n", err.msg);
    strlist_free(&base);
    strlist_free(&msets);
    return code;
}
