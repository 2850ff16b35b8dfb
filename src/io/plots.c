/* plots.c: runs scripts/plots.sh on an output set (see plots.h; reference: Outputs). */
#include "io/plots.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <stdlib.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/child.h"

#ifndef PPB_SCRIPT_DIR
#define PPB_SCRIPT_DIR "scripts"
#endif

const char *ppb_plots_script_dir(void)
{
    const char *d = getenv("PPBENCH_SCRIPTS");
    return (d && *d) ? d : PPB_SCRIPT_DIR;
}

void ppb_figures_fail(ppb_figures *f, const char *figure, const char *why)
{
    char key[600], said[2048];
    snprintf(key, sizeof key, "figure.%s = ", figure);
    if (strstr(f->text, key))
        return;
    const char *at = f->staged && f->final ? strstr(why, f->staged) : NULL;
    if (at)
        snprintf(said, sizeof said, "%.*s%s%s", (int)(at - why), why, f->final,
                 at + strlen(f->staged));
    else
        snprintf(said, sizeof said, "%s", why);
    why = said;
    size_t len = strlen(f->text);
    snprintf(f->text + len, sizeof f->text - len, "%snot drawn: %.300s\n", key, why);
    f->nfailed++;
    fprintf(stderr, "%s: figure %s not drawn (the other outputs are written): %s\n",
            f->who ? f->who : "ppbench", figure, why);
}

/* gnuplot's reason from its stderr: the last line that is not blank or only the caret under
 * the failing column, without the "/dev/stdin" it names the script by. */
static void last_reason(FILE *f, char *why, size_t cap)
{
    char line[512];
    rewind(f);
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\n")] = '\0';
        const char *p = line + strspn(line, " \t^");
        if (!*p)
            continue;
        if (!strncmp(p, "\"/dev/stdin\" ", 13))
            p += 13;
        snprintf(why, cap, "%s", p);
    }
}

/* Writes all of buf to fd; a gnuplot that stopped reading (it failed early) is no error of
 * the writer's: SIGPIPE is ignored meanwhile and the exit status tells. */
static void write_all(int fd, const char *buf, size_t len)
{
    struct sigaction ign = {.sa_handler = SIG_IGN}, old;
    sigemptyset(&ign.sa_mask);
    sigaction(SIGPIPE, &ign, &old);
    while (len > 0) {
        ssize_t w = write(fd, buf, len);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            break;
        buf += w;
        len -= (size_t)w;
    }
    sigaction(SIGPIPE, &old, NULL);
}

int ppb_gnuplot_run(const char *script, size_t len, const char *const *args, int nargs, char *why,
                    size_t cap)
{
    enum { MAX_ARGS = 9 }; /* gnuplot's ARG1..ARG9 */
    const char *argv[MAX_ARGS + 4] = {"gnuplot", "-c", "/dev/stdin"};
    for (int i = 0; i < nargs && i < MAX_ARGS; i++)
        argv[3 + i] = args[i];
    snprintf(why, cap, "gnuplot failed without a message");
    FILE *errs = tmpfile();
    int in[2] = {-1, -1};
    if (!errs || pipe(in) < 0) {
        snprintf(why, cap, "cannot start gnuplot: %s", strerror(errno));
        if (errs)
            fclose(errs);
        return -1;
    }
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        dup2(in[0], STDIN_FILENO);
        dup2(fileno(errs), STDOUT_FILENO);
        dup2(fileno(errs), STDERR_FILENO);
        close(in[0]);
        close(in[1]);
        execvp("gnuplot", (char *const *)argv);
        fprintf(stderr, "cannot run gnuplot: %s (is it installed?)\n", strerror(errno));
        _exit(127);
    }
    close(in[0]);
    if (pid > 0)
        write_all(in[1], script, len);
    close(in[1]);
    int status = 0, rc = -1;
    while (pid > 0 && waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) /* an interrupt while drawing still waits for gnuplot */
            break;
    if (pid < 0)
        snprintf(why, cap, "cannot start gnuplot: %s", strerror(errno));
    else if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
        rc = 0;
    else if (WIFSIGNALED(status)) {
        char last[400] = "";
        last_reason(errs, last, sizeof last);
        snprintf(why, cap, "gnuplot was killed by signal %d%s%s", WTERMSIG(status),
                 last[0] ? ": " : "", last);
    } else
        last_reason(errs, why, cap);
    fclose(errs);
    return rc;
}

/* PPB_PLOTS_KEEP=DIR keeps each figure's script as DIR/<file name>.gp, as plots.sh keeps its
 * bodies (the tests read them). */
static void keep_script(const char *path, const char *script, size_t len)
{
    const char *keep = getenv("PPB_PLOTS_KEEP"), *base = strrchr(path, '/');
    if (!keep || !*keep)
        return;
    char kept[4200];
    snprintf(kept, sizeof kept, "%s/%s.gp", keep, base ? base + 1 : path);
    FILE *f = fopen(kept, "w");
    if (f) {
        fwrite(script, 1, len, f);
        fclose(f);
    }
}

int ppb_gnuplot_figure(const char *path, const char *script, size_t len, const char *name,
                       char *why, size_t cap)
{
    ppb_apath ap; /* gnuplot opens the file by name: it writes the temporary */
    ppb_err err;
    char style[4200];
    snprintf(style, sizeof style, "%s/plot_style.gp", ppb_plots_script_dir());
    const char *args[3] = {ap.tmp, style, name ? name : ""};
    keep_script(path, script, len);
    if (ppb_apath_begin(&ap, path, &err)) {
        snprintf(why, cap, "%s", err.msg);
        return -1;
    }
    if (ppb_gnuplot_run(script, len, args, 3, why, cap)) {
        ppb_apath_abort(&ap);
        return -1;
    }
    /* gnuplot's cairo exits 0 on a full disk, leaving a 0-byte or cut file */
    if (ppb_file_complete(ap.tmp, &err) || ppb_apath_commit(&ap, &err)) {
        const char *what = strstr(err.msg, ": incomplete: "); /* named by the final path */
        if (what)
            snprintf(why, cap, "%s%s", path, what);
        else
            snprintf(why, cap, "%s", err.msg);
        ppb_apath_abort(&ap);
        return -1;
    }
    return 0;
}

/* The lines plots.sh writes on its stdout, "<figure>\t<why>" for each figure it left out. */
static void read_failures(FILE *f, ppb_figures *fig)
{
    char line[1024];
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\n")] = '\0';
        char *tab = strchr(line, '\t');
        if (!tab)
            continue;
        *tab = '\0';
        ppb_figures_fail(fig, line, tab + 1);
    }
}

void ppb_plots_write(const char *dir, const char *ref, ppb_figures *fig)
{
    char script[4096];
    snprintf(script, sizeof script, "%s/plots.sh", ppb_plots_script_dir());
    int out[2];
    if (access(script, R_OK) != 0 || pipe(out) < 0) {
        char why[4200];
        snprintf(why, sizeof why,
                 "cannot read %s (the plot script; PPBENCH_SCRIPTS names its folder)", script);
        ppb_figures_fail(fig, "plots", why);
        return;
    }
    /* stdout: the figures left out, for read_failures; the script's other messages go to
     * stderr. Under a guard: the script and what it starts die with ppbench (base/child.h).
     * The reference's id reaches it as data, in its environment, never as script text. */
    fflush(NULL); /* the child must not repeat buffered output */
    int saved = dup(STDOUT_FILENO);
    if (ref)
        setenv("PPB_REFERENCE", ref, 1);
    char *argv[] = {"bash", script, (char *)dir, NULL};
    pid_t pid =
        saved < 0 || dup2(out[1], STDOUT_FILENO) < 0 ? -1 : ppb_child_spawn("bash", argv, 0, 0);
    if (saved >= 0) {
        dup2(saved, STDOUT_FILENO);
        close(saved);
    }
    unsetenv("PPB_REFERENCE");
    close(out[1]);
    FILE *f = pid > 0 ? fdopen(out[0], "r") : NULL;
    if (f) {
        read_failures(f, fig);
        fclose(f);
    } else {
        close(out[0]);
    }
    int status = 0;
    while (pid > 0 && waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) /* an interrupt during plotting still waits for the script */
            break;
    if (pid < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        char why[4200];
        snprintf(why, sizeof why, "%s stopped (exit %d); the figures it had not drawn are missing",
                 script, pid > 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        ppb_figures_fail(fig, "plots", why);
    }
}
