#include "drivers/slurm.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/file_read.h"
#include "base/atomic_file.h"
#include "base/hash.h"
#include "drivers/sweep.h"
#include "methods/registry.h"

/* Copies src into dst[cap], cut to fit (callers check lengths where a cut would matter). */
static void copy_str(char *dst, size_t cap, const char *src)
{
    size_t n = strlen(src);
    if (n >= cap)
        n = cap - 1;
    memcpy(dst, src, n);
    dst[n] = '\0';
}

/* ---- checks of the #SBATCH values ---- */

static int all_of(const char *s, const char *allowed)
{
    return *s && strspn(s, allowed) == strlen(s);
}

/* Slurm's time forms (sbatch(1), --time): "M", "M:S", "H:M:S", "D-H", "D-H:M", "D-H:M:S". */
static int slurm_time_ok(const char *s)
{
    if (!strcmp(s, "UNLIMITED") || !strcmp(s, "INFINITE"))
        return 1;
    const char *dash = strchr(s, '-');
    if (dash && (dash == s || strspn(s, "0123456789") != (size_t)(dash - s)))
        return 0;
    const char *t = dash ? dash + 1 : s;
    int fields = 0;
    for (const char *p = t;; p++) {
        size_t n = strspn(p, "0123456789");
        if (n == 0)
            return 0;
        fields++;
        p += n;
        if (*p == '\0')
            break;
        if (*p != ':')
            return 0;
    }
    return fields <= 3;
}

int ppb_slurm_check_opts(const ppb_slurm_opts *o, ppb_err *err)
{
    if (o->shards < 1 || o->shards > PPB_SLURM_MAX_SHARDS)
        return ppb_fail(err, "--shards %d: expected 1 to %d", o->shards, PPB_SLURM_MAX_SHARDS);
    if (o->time && !slurm_time_ok(o->time))
        return ppb_fail(err,
                        "--time %s: expected minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS "
                        "or UNLIMITED (sbatch --time)",
                        o->time);
    if (o->mem) {
        size_t n = strspn(o->mem, "0123456789");
        if (n == 0 || (o->mem[n] && (strchr("KMGT", o->mem[n]) == NULL || o->mem[n + 1])))
            return ppb_fail(err, "--mem %s: expected a whole number of MB, or with K, M, G or T",
                            o->mem);
    }
    static const char name_chars[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                     "0123456789_-.,";
    const struct {
        const char *opt, *v;
    } names[] = {{"--partition", o->partition}, {"--account", o->account}, {"--qos", o->qos}};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
        if (names[k].v && !all_of(names[k].v, name_chars))
            return ppb_fail(err, "%s %s: expected letters, digits, '_', '-', '.' and ','",
                            names[k].opt, names[k].v);
    if (o->gres && !all_of(o->gres, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                    "0123456789_-.,:"))
        return ppb_fail(err,
                        "--gres %s: expected letters, digits, '_', '-', '.', ',' and ':' "
                        "(e.g. gpu:1)",
                        o->gres);
    /* Free #SBATCH lines: one sbatch option each, printable, so that nothing can end the line
     * and start a command in the script; not an option the scripts set themselves. */
    static const char *const own[] = {"--array",      "--job-name", "--output", "--error",
                                      "--dependency", "--parsable", "-J",       "-o",
                                      "-e",           "-a",         "-d"};
    for (int i = 0; i < o->nsbatch; i++) {
        const char *l = o->sbatch[i];
        int printable = *l != '\0';
        for (const char *p = l; *p; p++)
            printable &= (unsigned char)*p >= 0x20 && (unsigned char)*p < 0x7f;
        if (!printable)
            return ppb_fail(err,
                            "--sbatch: %s: an #SBATCH line holds printable characters only "
                            "(no newline, tab or control character)",
                            *l ? "the line" : "an empty line");
        if (strncmp(l, "--", 2) != 0 || !isalpha((unsigned char)l[2]))
            return ppb_fail(err, "--sbatch %s: expected one sbatch option, e.g. --constraint=x", l);
        for (size_t k = 0; k < sizeof own / sizeof own[0]; k++) {
            size_t n = strlen(own[k]);
            if (own[k][1] == '-' && !strncmp(l, own[k], n) &&
                (l[n] == '\0' || l[n] == '=' || l[n] == ' '))
                return ppb_fail(err, "--sbatch %s: %s is set by ppbench slurm itself", l, own[k]);
        }
    }
    return 0;
}

/* ---- pure text ---- */

size_t ppb_slurm_shell_quote(const char *s, char *buf, size_t cap)
{
    size_t n = 0;
#define PUT(c)                                                                                     \
    do {                                                                                           \
        if (n + 1 < cap)                                                                           \
            buf[n] = (c);                                                                          \
        n++;                                                                                       \
    } while (0)
    PUT('\'');
    for (; *s; s++) {
        if (*s == '\'') {
            PUT('\'');
            PUT('\\');
            PUT('\'');
            PUT('\'');
        } else {
            PUT(*s);
        }
    }
    PUT('\'');
#undef PUT
    if (cap)
        buf[n < cap ? n : cap - 1] = '\0';
    return n;
}

/* A memstream; the text is NULL if anything failed. */
typedef struct text {
    FILE *f;
    char *buf;
    size_t len;
} text;

static int text_open(text *t)
{
    t->buf = NULL;
    t->len = 0;
    t->f = open_memstream(&t->buf, &t->len);
    return t->f ? 0 : -1;
}

static char *text_close(text *t)
{
    if (!t->f)
        return NULL;
    int bad = ferror(t->f);
    if (fclose(t->f) != 0 || bad) {
        free(t->buf);
        return NULL;
    }
    return t->buf;
}

static void put_quoted(FILE *f, const char *s)
{
    char small[1];
    size_t n = ppb_slurm_shell_quote(s, small, 0);
    char *q = malloc(n + 1);
    if (!q) {
        fputs("''", f); /* out of memory: the caller's memstream fails too */
        return;
    }
    ppb_slurm_shell_quote(s, q, n + 1);
    fputs(q, f);
    free(q);
}

/* Whether the resolved line "section.key = value" is the key of a grid axis. */
static int axis_of_line(const ppb_grid *grid, const char *line, size_t keylen)
{
    for (int a = 0; grid && a < grid->naxes; a++) {
        char name[128];
        ppb_config_key_name(grid->axes[a].key, name, sizeof name);
        if (strlen(name) == keylen && !memcmp(name, line, keylen))
            return 1;
    }
    return 0;
}

char *ppb_slurm_config_text(const ppb_config *cfg, const ppb_grid *grid, const char *out_dir)
{
    /* The resolved lines, "section.key = value" in the key table's order (model/config.h). */
    text r, t;
    if (text_open(&r))
        return NULL;
    ppb_config c = *cfg;
    snprintf(c.out_dir, sizeof c.out_dir, "%s", out_dir);
    ppb_config_write_resolved(&c, r.f);
    char *resolved = text_close(&r);
    if (!resolved || text_open(&t)) {
        free(resolved);
        return NULL;
    }
    /* No path in it: the same settings give the same text, and the same job stamp. */
    fprintf(t.f, "; Written by `ppbench slurm` (job.txt names the config given): every key at\n"
                 "; its resolved value (--set applied), the swept keys last in the sweep's axis\n"
                 "; order.\n");
    char section[64] = "";
    for (char *line = resolved, *next; *line; line = next) {
        char *nl = strchr(line, '\n');
        next = nl ? nl + 1 : line + strlen(line);
        if (nl)
            *nl = '\0';
        /* The key is after the last dot before " = ": an external method's lines are
         * "method.NAME.key", its section [method.NAME]. */
        char *eq = strstr(line, " = "), *dot = NULL;
        for (char *p = line; eq && p < eq; p++)
            if (*p == '.')
                dot = p;
        if (!dot || !eq)
            continue;
        if (axis_of_line(grid, line, (size_t)(eq - line)))
            continue;
        if (strlen(section) != (size_t)(dot - line) || memcmp(section, line, strlen(section))) {
            snprintf(section, sizeof section, "%.*s", (int)(dot - line), line);
            fprintf(t.f, "[%s]\n", section);
        }
        fprintf(t.f, "%.*s = %s\n", (int)(eq - dot - 1), dot + 1, eq + 3);
    }
    free(resolved);
    /* A section may open again (each key is given once): the axes keep their order. */
    for (int a = 0; grid && a < grid->naxes; a++) {
        char name[128];
        ppb_config_key_name(grid->axes[a].key, name, sizeof name);
        char *dot = strchr(name, '.');
        if (!dot)
            continue;
        *dot = '\0';
        fprintf(t.f, "[%s]\n%s = ", name, dot + 1);
        for (int v = 0; v < grid->axes[a].n; v++)
            fprintf(t.f, "%s%.17g", v ? ", " : "", grid->axes[a].values[v]);
        fputc('\n', t.f);
    }
    return text_close(&t);
}

/* The #SBATCH lines of the options; task: the array's tasks (and check.sh, which runs as one),
 * which take --cpus-per-task and --gres; the merge takes neither. */
static void sbatch_lines(FILE *f, const ppb_slurm_opts *o, int task)
{
    if (o->partition)
        fprintf(f, "#SBATCH --partition=%s\n", o->partition);
    if (o->account)
        fprintf(f, "#SBATCH --account=%s\n", o->account);
    if (o->qos)
        fprintf(f, "#SBATCH --qos=%s\n", o->qos);
    if (o->time)
        fprintf(f, "#SBATCH --time=%s\n", o->time);
    if (o->mem)
        fprintf(f, "#SBATCH --mem=%s\n", o->mem);
    if (task && o->cpus > 0)
        fprintf(f, "#SBATCH --cpus-per-task=%d\n", o->cpus);
    if (task && o->gres)
        fprintf(f, "#SBATCH --gres=%s\n", o->gres);
    for (int i = 0; i < o->nsbatch; i++)
        fprintf(f, "#SBATCH %s\n", o->sbatch[i]);
}

static const char *what(const ppb_slurm_job *job)
{
    return job->kind == PPB_SLURM_SWEEP ? "the sweep's grid points" : "the Monte Carlo's photons";
}

char *ppb_slurm_array_script(const ppb_slurm_job *job, const ppb_slurm_opts *o)
{
    text t;
    if (text_open(&t))
        return NULL;
    FILE *f = t.f;
    fprintf(f,
            "#!/bin/bash\n"
            "# Written by `ppbench slurm`: task I of this job array computes shard I of %d of\n"
            "# %s (%lld) into shards/I with the config and the ppbench binary\n"
            "# beside this script, and marks the shard done (done/I) only when ppbench exits 0.\n"
            "# Re-run the `ppbench slurm` command to submit the shards neither done nor queued.\n",
            job->shards, what(job), job->units);
    fprintf(f, "#SBATCH --job-name=%s\n#SBATCH --array=1-%d\n", job->name, job->shards);
    fprintf(f, "#SBATCH --output=%s/logs/task_%%a_job_%%A.out\n", job->dir);
    sbatch_lines(f, o, 1);
    fprintf(f, "set -euo pipefail\ndir=");
    put_quoted(f, job->dir);
    fprintf(f, "\nstamp=");
    put_quoted(f, job->stamp);
    fprintf(f, "\ni=${SLURM_ARRAY_TASK_ID:?this script runs as a task of a Slurm job array}\n"
               "rm -f \"$dir/done/$i\"\n");
    fprintf(f, "\"$dir/ppbench\" %s --quiet", job->kind == PPB_SLURM_SWEEP ? "sweep" : "mc-shard");
    if (o->device) {
        fprintf(f, " --device ");
        put_quoted(f, o->device);
    }
    fprintf(f, " --shard \"$i/%d\" --out \"$dir/shards/$i\" \"$dir/config.ini\"\n", job->shards);
    fprintf(f, "# Written whole and renamed: a task killed before this leaves no marker.\n"
               "printf '%%s\\n' \"$stamp\" > \"$dir/done/$i.tmp.$$\"\n"
               "mv -f \"$dir/done/$i.tmp.$$\" \"$dir/done/$i\"\n");
    return text_close(&t);
}

char *ppb_slurm_merge_script(const ppb_slurm_job *job, const ppb_slurm_opts *o)
{
    text t;
    if (text_open(&t))
        return NULL;
    FILE *f = t.f;
    fprintf(f,
            "#!/bin/bash\n"
            "# Written by `ppbench slurm`: merges the %d shards into result/ once each is marked\n"
            "# done by a task of this job (done/I holds this job's stamp: its kind, shard count,\n"
            "# config and build); ppbench %s checks the shards themselves.\n",
            job->shards, job->kind == PPB_SLURM_SWEEP ? "merge" : "mc-merge");
    fprintf(f, "#SBATCH --job-name=%s-merge\n", job->name);
    fprintf(f, "#SBATCH --output=%s/logs/merge_job_%%j.out\n", job->dir);
    sbatch_lines(f, o, 0);
    fprintf(f, "set -euo pipefail\ndir=");
    put_quoted(f, job->dir);
    fprintf(f, "\nstamp=");
    put_quoted(f, job->stamp);
    fprintf(f,
            "\nshards=()\n"
            "for i in $(seq 1 %d); do\n"
            "  m=$(cat \"$dir/done/$i\" 2>/dev/null || true)\n"
            "  if [ \"$m\" != \"$stamp\" ]; then\n"
            "    echo \"ppbench slurm merge: shard $i of %d is not done by this job (done/$i: "
            "${m:-none}): run the ppbench slurm command again\" >&2\n"
            "    exit 1\n"
            "  fi\n"
            "  shards+=(\"$dir/shards/$i\")\n"
            "done\n"
            "rm -f \"$dir/done/merge\"\n",
            job->shards, job->shards);
    if (job->kind == PPB_SLURM_SWEEP)
        fprintf(f, "\"$dir/ppbench\" merge --out \"$dir/result\" \"${shards[@]}\"\n");
    else
        fprintf(f, "\"$dir/ppbench\" mc-merge --out \"$dir/result\" \"$dir/config.ini\" "
                   "\"${shards[@]}\"\n");
    fprintf(f, "printf '%%s\\n' \"$stamp\" > \"$dir/done/merge.tmp.$$\"\n"
               "mv -f \"$dir/done/merge.tmp.$$\" \"$dir/done/merge\"\n");
    return text_close(&t);
}

int ppb_slurm_array_spec(const unsigned char *pick, int n, char *buf, size_t cap)
{
    size_t len = 0;
    int count = 0;
    if (cap)
        buf[0] = '\0';
    for (int i = 1; i <= n; i++) {
        if (!pick[i])
            continue;
        int j = i;
        while (j + 1 <= n && pick[j + 1])
            j++;
        count += j - i + 1;
        char part[32];
        if (j == i)
            snprintf(part, sizeof part, "%s%d", len ? "," : "", i);
        else
            snprintf(part, sizeof part, "%s%d-%d", len ? "," : "", i, j);
        if (len + strlen(part) < cap) {
            memcpy(buf + len, part, strlen(part) + 1);
        }
        len += strlen(part);
        i = j;
    }
    return count;
}

int ppb_slurm_parse_squeue(const char *text, const char *name, int shards, unsigned char *active,
                           char (*task_ids)[32], char *merge_id, size_t merge_cap)
{
    char merge_name[200];
    snprintf(merge_name, sizeof merge_name, "%s-merge", name);
    if (merge_cap)
        merge_id[0] = '\0';
    int count = 0;
    for (const char *line = text; *line;) {
        const char *nl = strchr(line, '\n');
        size_t len = nl ? (size_t)(nl - line) : strlen(line);
        char buf[512];
        snprintf(buf, sizeof buf, "%.*s", (int)(len < sizeof buf ? len : sizeof buf - 1), line);
        line += len + (nl ? 1 : 0);
        char *bar1 = strchr(buf, '|'), *bar2 = bar1 ? strchr(bar1 + 1, '|') : NULL;
        if (!bar1 || !bar2)
            continue;
        *bar1 = *bar2 = '\0';
        const char *id = buf, *job = bar1 + 1;
        if (!strcmp(job, merge_name)) {
            if (merge_cap)
                copy_str(merge_id, merge_cap, id);
            continue;
        }
        if (strcmp(job, name))
            continue;
        const char *us = strchr(id, '_');
        char *end;
        long task = us ? strtol(us + 1, &end, 10) : 0;
        if (!us || *end != '\0' || task < 1 || task > shards)
            continue;
        if (!active[task])
            count++;
        active[task] = 1;
        if (task_ids)
            copy_str(task_ids[task], 32, id);
    }
    return count;
}

/* ---- the job directory ---- */

char *ppb_slurm_check_script(const ppb_slurm_job *job, const ppb_slurm_opts *o,
                             const char *kernel_dir)
{
    text t;
    if (text_open(&t))
        return NULL;
    FILE *f = t.f;
    fprintf(f,
            "#!/bin/bash\n"
            "# Written by `ppbench slurm`: checks, as one job with the tasks' #SBATCH lines, that\n"
            "# a compute node can run them: the binary's shared libraries, the kernel\n"
            "# sources and an OpenCL device. Submit it first: sbatch --wait check.sh\n");
    fprintf(f, "#SBATCH --job-name=%s-check\n", job->name);
    fprintf(f, "#SBATCH --output=%s/logs/check_job_%%j.out\n", job->dir);
    sbatch_lines(f, o, 1);
    fprintf(f, "set -uo pipefail\ndir=");
    put_quoted(f, job->dir);
    fprintf(f, "\nsource=${PPBENCH_SOURCE:-");
    put_quoted(f, kernel_dir);
    fprintf(f, "}\n");
    fprintf(f,
            "node=$(hostname)\nbad=0\n"
            "missing=$(ldd \"$dir/ppbench\" 2>&1 | grep 'not found')\n"
            "if [ -n \"$missing\" ]; then\n"
            "  echo \"ppbench slurm check: $node lacks shared libraries of $dir/ppbench:\"\n"
            "  echo \"$missing\"\n  bad=1\nfi\n"
            "if [ ! -r \"$source/kernels\" ] || [ ! -r \"$source/src/methods\" ]; then\n"
            "  echo \"ppbench slurm check: $node cannot read the kernel sources in $source \"\\\n"
            "       \"(a file system the nodes share, or PPBENCH_SOURCE)\"\n  bad=1\nfi\n"
            "if [ $bad = 0 ]; then\n"
            "  devices=$(\"$dir/ppbench\" devices 2>&1)\n"
            "  if [ $? != 0 ] || ! grep -q '^[0-9]' <<<\"$devices\"; then\n"
            "    echo \"ppbench slurm check: $node has no OpenCL device (an ICD in \"\\\n"
            "         \"/etc/OpenCL/vendors and its driver):\"\n"
            "    echo \"$devices\"\n    bad=1\n  else\n"
            "    echo \"$devices\"\n  fi\nfi\n"
            "[ $bad = 0 ] && echo \"ppbench slurm check: ok on $node\"\n"
            "exit $bad\n");
    return text_close(&t);
}

static int write_file(const char *path, const char *data, size_t len, int exec, ppb_err *err)
{
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    if (fwrite(data, 1, len, af.f) != len || (exec && fchmod(fileno(af.f), 0755) != 0)) {
        ppb_afile_abort(&af);
        return ppb_fail(err, "%s: cannot write: %s", path, strerror(errno));
    }
    return ppb_afile_commit(&af, err);
}

/* The first line of path (without its newline) into buf; 0 when there is none. */
static int first_line(const char *path, char *buf, size_t cap)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    int ok = fgets(buf, (int)cap, f) != NULL;
    fclose(f);
    if (ok)
        buf[strcspn(buf, "\n")] = '\0';
    return ok;
}

/* The job directory's path goes into #SBATCH lines, which sbatch does not read as a shell
 * would: only characters that need no quoting there. */
static int dir_chars_ok(const char *dir)
{
    return all_of(dir, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_./+,:@=-");
}

static int same_settings(const ppb_config *a, const ppb_grid *ga, const ppb_config *b,
                         const ppb_grid *gb)
{
    char *ta = NULL, *tb = NULL;
    size_t na = 0, nb = 0;
    FILE *fa = open_memstream(&ta, &na), *fb = open_memstream(&tb, &nb);
    if (fa)
        ppb_config_write_resolved(a, fa), fclose(fa);
    if (fb)
        ppb_config_write_resolved(b, fb), fclose(fb);
    int same = fa && fb && ta && tb && na == nb && !memcmp(ta, tb, na);
    free(ta);
    free(tb);
    int naxes = ga ? ga->naxes : 0;
    if (!same || naxes != (gb ? gb->naxes : 0))
        return 0;
    for (int x = 0; x < naxes; x++) {
        const ppb_axis *p = &ga->axes[x], *q = &gb->axes[x];
        if (p->key != q->key || p->n != q->n ||
            memcmp(p->values, q->values, sizeof *p->values * (size_t)p->n))
            return 0;
    }
    return 1;
}

/* Runs argv (found on PATH), its stdout into out (cut at cap). Returns its exit status, or -1
 * with err set when it could not run or was killed. */
static int run_tool(char *const argv[], char *out, size_t cap, ppb_err *err)
{
    int fd[2];
    fflush(NULL);
    if (pipe(fd) < 0)
        return ppb_fail(err, "%s: cannot start: %s", argv[0], strerror(errno));
    pid_t pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        return ppb_fail(err, "%s: cannot start: %s", argv[0], strerror(errno));
    }
    if (pid == 0) {
        close(fd[0]);
        dup2(fd[1], 1);
        close(fd[1]);
        execvp(argv[0], argv);
        fprintf(stderr, "ppbench slurm: %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    close(fd[1]);
    size_t n = 0;
    char sink[4096];
    for (;;) {
        ssize_t r =
            n + 1 < cap ? read(fd[0], out + n, cap - 1 - n) : read(fd[0], sink, sizeof sink);
        if (r == 0)
            break;
        if (r < 0) {
            if (errno == EINTR)
                continue;
            break;
        }
        if (n + 1 < cap)
            n += (size_t)r;
    }
    out[n] = '\0';
    close(fd[0]);
    int st;
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR)
            return ppb_fail(err, "%s: %s", argv[0], strerror(errno));
    if (!WIFEXITED(st))
        return ppb_fail(err, "%s: killed by signal %d", argv[0], WTERMSIG(st));
    if (WEXITSTATUS(st) == 127)
        return ppb_fail(err, "%s: not found on PATH (is this a Slurm submit host?)", argv[0]);
    return WEXITSTATUS(st);
}

/* sbatch --parsable prints "<id>" or "<id>;<cluster>"; script names what is submitted. */
static int sbatch(char *const argv[], const char *script, char *id, size_t cap, ppb_err *err)
{
    char out[256];
    int rc = run_tool(argv, out, sizeof out, err);
    if (rc < 0)
        return -1;
    out[strcspn(out, ";\n")] = '\0';
    if (rc != 0 || !*out || strspn(out, "0123456789") != strlen(out))
        return ppb_fail(err, "sbatch %s failed (exit %d%s%s; its message is above)", script, rc,
                        *out ? ", printed " : "", out);
    if (strlen(out) >= cap)
        return ppb_fail(err, "sbatch %s: job id %s too long", script, out);
    copy_str(id, cap, out);
    return 0;
}

/* Which part of two stamps differs: "config", "build", "shards", "kind" (or "stamp"). */
static const char *stamp_diff(const char *a, const char *b)
{
    static const char *const parts[] = {"config=", "build=", "shards="};
    for (int k = 0; k < 3; k++) {
        const char *p = strstr(a, parts[k]), *q = strstr(b, parts[k]);
        if (!p || !q)
            continue;
        size_t np = strcspn(p, " "), nq = strcspn(q, " ");
        if (np != nq || memcmp(p, q, np))
            return k == 0   ? "another config"
                   : k == 1 ? "another build of ppbench"
                            : "another --shards";
    }
    return strcspn(a, " ") != strcspn(b, " ") || memcmp(a, b, strcspn(a, " "))
               ? "another kind (a sweep and a Monte Carlo)"
               : "another job";
}

static int dir_is_empty(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return 1;
    int empty = 1;
    for (struct dirent *e; empty && (e = readdir(d)) != NULL;)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            empty = 0;
    closedir(d);
    return empty;
}

static void print_commands(const ppb_slurm_job *job, const char *spec, int nmissing)
{
    if (nmissing)
        printf("to submit the %d missing shard%s and the merge after them:\n"
               "  jid=$(sbatch --parsable --array=%s %s/job.sh)\n"
               "  sbatch --dependency=afterok:$jid %s/merge.sh\n",
               nmissing, nmissing > 1 ? "s" : "", spec, job->dir, job->dir);
    else
        printf("to submit the merge:\n  sbatch %s/merge.sh\n", job->dir);
    printf("(or run this command again with --submit: it also leaves out the tasks still "
           "queued)\n");
    printf("to check first that a compute node can run them (libraries, kernels, an OpenCL "
           "device):\n  sbatch --wait %s/check.sh\n",
           job->dir);
}

/* Asks Slurm which of the job's tasks are still queued or running, cancels a merge job left
 * waiting on tasks that failed or were cancelled, and submits the missing shards (done[i] 0,
 * not queued) with a merge job after them and after the tasks still queued. */
static int submit(const ppb_slurm_job *job, const unsigned char *done, int merged, ppb_err *err)
{
    int n = job->shards, rc = -1;
    unsigned char *active = calloc((size_t)n + 1, 1), *missing = calloc((size_t)n + 1, 1);
    char(*ids)[32] = calloc((size_t)n + 1, sizeof *ids);
    size_t qcap = 64 + (size_t)n * 96, dcap = 64 + (size_t)n * 34;
    char *queue = malloc(qcap), *dep = malloc(dcap), *spec = malloc((size_t)n * 12 + 16);
    if (!active || !missing || !ids || !queue || !dep || !spec) {
        ppb_fail(err, "slurm: out of memory for %d shards", n);
        goto out;
    }
    char names[400], merge_id[64], array_id[64] = "", new_merge[64];
    snprintf(names, sizeof names, "--name=%s,%s-merge", job->name, job->name);
    char *squeue[] = {"squeue", "-h", "-r", names, "-o", "%i|%j|%T", NULL};
    int st = run_tool(squeue, queue, qcap, err);
    if (st != 0) {
        if (st > 0)
            ppb_fail(err,
                     "squeue failed (exit %d; its message is above): which tasks are still "
                     "queued is unknown, nothing submitted",
                     st);
        goto out;
    }
    int nactive =
        ppb_slurm_parse_squeue(queue, job->name, n, active, ids, merge_id, sizeof merge_id);
    int nmissing = 0;
    for (int i = 1; i <= n; i++)
        nmissing += missing[i] = !done[i] && !active[i];
    if (nmissing == 0 && (*merge_id || merged)) {
        if (*merge_id)
            printf("nothing to submit: %d task%s still queued or running, merge job %s after "
                   "them\n",
                   nactive, nactive == 1 ? "" : "s", merge_id);
        else
            printf("nothing to submit: every shard is done and merged into %s/result\n", job->dir);
        rc = 0;
        goto out;
    }
    /* A merge job still waiting depends on the tasks now missing: it would never run. */
    if (*merge_id) {
        char *scancel[] = {"scancel", merge_id, NULL};
        char sink[256];
        st = run_tool(scancel, sink, sizeof sink, err);
        if (st != 0) {
            if (st > 0)
                ppb_fail(err, "scancel %s failed (exit %d): nothing submitted", merge_id, st);
            goto out;
        }
        printf("cancelled: merge job %s (it waited on tasks that failed or were cancelled)\n",
               merge_id);
    }
    size_t dlen = 0;
    dep[0] = '\0';
    if (nmissing) {
        ppb_slurm_array_spec(missing, n, spec, (size_t)n * 12 + 16);
        char array_opt[64 + 12 * PPB_SLURM_MAX_SHARDS], script[1200];
        snprintf(array_opt, sizeof array_opt, "--array=%s", spec);
        snprintf(script, sizeof script, "%s/job.sh", job->dir);
        char *argv[] = {"sbatch", "--parsable", array_opt, script, NULL};
        if (sbatch(argv, script, array_id, sizeof array_id, err))
            goto out;
        printf("submitted: array job %s, task%s %s\n", array_id, nmissing > 1 ? "s" : "", spec);
        dlen += (size_t)snprintf(dep, dcap, "afterok:%s", array_id);
    }
    for (int i = 1; i <= n; i++)
        if (active[i])
            dlen +=
                (size_t)snprintf(dep + dlen, dcap - dlen, "%s%s", dlen ? ":" : "afterok:", ids[i]);
    char dep_opt[64 + 34 * PPB_SLURM_MAX_SHARDS], script[1200];
    snprintf(dep_opt, sizeof dep_opt, "--dependency=%s", dep);
    snprintf(script, sizeof script, "%s/merge.sh", job->dir);
    char *margv[] = {"sbatch", "--parsable", dep_opt, script, NULL};
    if (!dlen) /* every shard done: the merge can run now */
        margv[2] = script, margv[3] = NULL;
    if (sbatch(margv, script, new_merge, sizeof new_merge, err))
        goto out;
    printf("submitted: merge job %s%s%s\n", new_merge, dlen ? ", after " : "", dep);
    rc = 0;
out:
    free(active);
    free(missing);
    free(ids);
    free(queue);
    free(dep);
    free(spec);
    return rc;
}

/* The running binary's bytes (every task runs a copy of them) and their hash. */
static char *self_binary(size_t *len, ppb_err *err)
{
    char *bin = ppb_read_file("/proc/self/exe", len);
    if (!bin)
        ppb_fail(err, "slurm: cannot read the ppbench binary (/proc/self/exe): %s",
                 strerror(errno));
    return bin;
}

/* The config's name as a Slurm job name may hold it. */
static void job_name(const ppb_config *cfg, const char *dir, char *buf, size_t cap)
{
    char name[41];
    size_t k = 0;
    for (const char *s = cfg->name; *s && k < sizeof name - 1; s++)
        name[k++] = strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-", *s)
                        ? *s
                        : '_';
    name[k] = '\0';
    snprintf(buf, cap, "ppb-%s-%08llx", name,
             (unsigned long long)(ppb_hash64(dir, strlen(dir)) & 0xffffffffu));
}

/* Checks what can be checked before anything is written: the options, the kind of job, the
 * shard count against its units, the directory's name. */
static int check_job(const ppb_config *cfg, const ppb_grid *grid, const ppb_slurm_opts *o,
                     ppb_slurm_job *job, ppb_err *err)
{
    if (ppb_slurm_check_opts(o, err))
        return -1;
    job->kind = grid && grid->naxes > 0 ? PPB_SLURM_SWEEP : PPB_SLURM_MC;
    job->shards = o->shards;
    if (job->kind == PPB_SLURM_SWEEP) {
        job->units = ppb_grid_npoints(grid);
        if (job->units > PPB_SWEEP_MAX_POINTS)
            return ppb_fail(err,
                            "%s: the grid has %lld points, over the sweep's limit of %d (which "
                            "only `ppbench sweep --yes` lifts)",
                            cfg->path, job->units, PPB_SWEEP_MAX_POINTS);
        ppb_config pt;
        for (long long i = 0; i < job->units; i++)
            if (ppb_config_point(cfg, grid, i, &pt, err))
                return -1;
    } else {
        const char *ref = ppb_method_reference()->id;
        if (!ppb_config_has_method(cfg, ref))
            return ppb_fail(err,
                            "%s: no key holds a list and [experiment] methods has no %s: nothing "
                            "to shard (a sweep or a Monte Carlo)",
                            cfg->path, ref);
        job->units = cfg->mc.photons;
    }
    if (o->shards > job->units)
        return ppb_fail(err, "--shards %d: more shards than %s (%lld)", o->shards,
                        job->kind == PPB_SLURM_SWEEP ? "grid points" : "photons", job->units);
    if (!dir_chars_ok(o->out))
        return ppb_fail(err,
                        "--out %s: a job directory's path goes into #SBATCH lines: letters, "
                        "digits and _ . / + , : @ = - only",
                        o->out);
    struct stat st;
    if (stat(o->out, &st) == 0 && !S_ISDIR(st.st_mode))
        return ppb_fail(err, "--out %s: not a directory", o->out);
    return 0;
}

int ppb_slurm_run(const ppb_config *cfg, const ppb_grid *grid, const ppb_slurm_opts *o,
                  ppb_err *err)
{
    ppb_slurm_job job = {0};
    if (check_job(cfg, grid, o, &job, err))
        return PPB_SLURM_BAD_CONFIG;
    if (ppb_mkdirs(o->out, err))
        return -1;
    char *abs = realpath(o->out, NULL);
    if (!abs)
        return ppb_fail(err, "--out %s: %s", o->out, strerror(errno));
    /* Room for "/result" in a config's out_dir and for the longest file name below. */
    int too_long = strlen(abs) + 32 >= sizeof cfg->out_dir;
    snprintf(job.dir, sizeof job.dir, "%s", abs);
    free(abs);
    if (too_long || !dir_chars_ok(job.dir))
        return ppb_fail(err,
                        "--out %s: its absolute path %s is too long or holds characters "
                        "#SBATCH lines cannot",
                        o->out, job.dir),
               PPB_SLURM_BAD_CONFIG;

    char path[1300], result[1200];
    snprintf(result, sizeof result, "%s/result", job.dir);
    char *conf = ppb_slurm_config_text(cfg, grid, result);
    size_t bin_len = 0;
    char *bin = conf ? self_binary(&bin_len, err) : NULL;
    char *array = NULL, *merge = NULL, *check = NULL;
    unsigned char *done = NULL;
    ppb_grid *back_grid = NULL;
    int rc = -1;
    if (!conf) {
        ppb_fail(err, "slurm: out of memory for the config text");
        goto out;
    }
    if (!bin)
        goto out;
    job_name(cfg, job.dir, job.name, sizeof job.name);
    snprintf(job.stamp, sizeof job.stamp, "%s shards=%d config=%016llx build=%016llx",
             job.kind == PPB_SLURM_SWEEP ? "sweep" : ppb_method_reference()->id, job.shards,
             (unsigned long long)ppb_hash64(conf, strlen(conf)),
             (unsigned long long)ppb_hash64(bin, bin_len));

    /* The directory is this job's, or new: job.txt's first line is its stamp. */
    char had[256];
    snprintf(path, sizeof path, "%s/job.txt", job.dir);
    if (first_line(path, had, sizeof had)) {
        const char *prefix = "ppbench slurm job: ";
        const char *old = strncmp(had, prefix, strlen(prefix)) ? had : had + strlen(prefix);
        if (strcmp(old, job.stamp)) {
            rc = PPB_SLURM_BAD_CONFIG;
            ppb_fail(err,
                     "--out %s holds the job of %s (job.txt: %s; this command: %s): its shards "
                     "would not merge with these; give another --out, or remove it",
                     job.dir, stamp_diff(old, job.stamp), old, job.stamp);
            goto out;
        }
    } else if (!dir_is_empty(job.dir)) {
        rc = PPB_SLURM_BAD_CONFIG;
        ppb_fail(err, "--out %s: not empty and not a ppbench slurm job directory (no job.txt)",
                 job.dir);
        goto out;
    }

    array = ppb_slurm_array_script(&job, o);
    merge = ppb_slurm_merge_script(&job, o);
    check = ppb_slurm_check_script(&job, o, PPB_SOURCE_DIR);
    done = calloc((size_t)job.shards + 1, 1);
    back_grid = ppb_grid_new();
    if (!array || !merge || !check || !done || !back_grid) {
        ppb_fail(err, "slurm: out of memory");
        goto out;
    }
    static const char *const subdirs[] = {"logs", "shards", "done"};
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/%s", job.dir, subdirs[k]);
        if (ppb_mkdirs(path, err))
            goto out;
    }
    snprintf(path, sizeof path, "%s/config.ini", job.dir);
    if (write_file(path, conf, strlen(conf), 0, err))
        goto out;
    /* The copy must give every task the settings of this command. */
    ppb_config back, want = *cfg;
    copy_str(want.out_dir, sizeof want.out_dir, result);
    ppb_err e;
    if (ppb_config_load_grid(&back, back_grid, path, &e) ||
        !same_settings(&want, grid, &back, back_grid)) {
        rc = PPB_SLURM_BAD_CONFIG;
        ppb_fail(err,
                 "%s: the config copy does not load back to the same settings (%s): a name or "
                 "path with ';' or surrounding spaces?",
                 path, ppb_config_load_grid(&back, back_grid, path, &e) ? e.msg : "other values");
        goto out;
    }
    struct {
        const char *name;
        const char *data;
        size_t len;
        int exec;
    } files[] = {
        {"ppbench", bin, bin_len, 1},
        {"job.sh", array, strlen(array), 1},
        {"merge.sh", merge, strlen(merge), 1},
        {"check.sh", check, strlen(check), 1},
    };
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        snprintf(path, sizeof path, "%s/%s", job.dir, files[k].name);
        if (write_file(path, files[k].data, files[k].len, files[k].exec, err))
            goto out;
    }
    char info[4096];
    int ninfo =
        snprintf(info, sizeof info,
                 "ppbench slurm job: %s\n"
                 "config %s, %s, %d shards, Slurm job name %s\n",
                 job.stamp, cfg->path, job.kind == PPB_SLURM_SWEEP ? "sweep" : "Monte Carlo",
                 job.shards, job.name);
    snprintf(path, sizeof path, "%s/job.txt", job.dir);
    if (write_file(path, info, (size_t)ninfo < sizeof info ? (size_t)ninfo : sizeof info - 1, 0,
                   err))
        goto out;

    /* The shards done by this job, and its merge. */
    int ndone = 0;
    char mark[256];
    for (int i = 1; i <= job.shards; i++) {
        snprintf(path, sizeof path, "%s/done/%d", job.dir, i);
        ndone += done[i] = first_line(path, mark, sizeof mark) && !strcmp(mark, job.stamp);
    }
    snprintf(path, sizeof path, "%s/done/merge", job.dir);
    int merged =
        ndone == job.shards && first_line(path, mark, sizeof mark) && !strcmp(mark, job.stamp);
    {
        printf("%s: %s of %lld %s in %d shards; job directory %s (Slurm job name %s)\n", cfg->name,
               job.kind == PPB_SLURM_SWEEP ? "a sweep" : "the Monte Carlo", job.units,
               job.kind == PPB_SLURM_SWEEP ? "grid points" : "photons", job.shards, job.dir,
               job.name);
        printf("shards done: %d of %d%s\n", ndone, job.shards,
               merged ? ", merged into result/" : "");
    }
    if (o->submit) {
        rc = submit(&job, done, merged, err);
        goto out;
    }
    if (!merged) {
        unsigned char *missing = done; /* reused: done[i] becomes "missing" */
        for (int i = 1; i <= job.shards; i++)
            missing[i] = !missing[i];
        char spec[64 + 12 * PPB_SLURM_MAX_SHARDS];
        int nmissing = ppb_slurm_array_spec(missing, job.shards, spec, sizeof spec);
        print_commands(&job, spec, nmissing);
    }
    rc = 0;
out:
    free(conf);
    free(bin);
    free(array);
    free(merge);
    free(check);
    free(done);
    ppb_grid_free(back_grid);
    return rc;
}
