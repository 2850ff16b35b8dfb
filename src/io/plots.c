/* plots.c: runs scripts/plots.sh on an output set (see plots.h; reference: Outputs). */
#include "io/plots.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef PPB_SCRIPT_DIR
#define PPB_SCRIPT_DIR "scripts"
#endif

const char *ppb_plots_script_dir(void)
{
    const char *d = getenv("PPBENCH_SCRIPTS");
    return (d && *d) ? d : PPB_SCRIPT_DIR;
}

int ppb_plots_write(const char *dir, ppb_err *err)
{
    char script[4096];
    snprintf(script, sizeof script, "%s/plots.sh", ppb_plots_script_dir());
    if (access(script, R_OK) != 0)
        return ppb_fail(err, "cannot read %s (the plot script; PPBENCH_SCRIPTS names its folder)",
                        script);
    fflush(NULL); /* the child must not repeat buffered output */
    pid_t pid = fork();
    if (pid < 0)
        return ppb_fail(err, "cannot start %s", script);
    if (pid == 0) {
        /* The script's own messages go to stderr; stdout stays the caller's. */
        dup2(STDERR_FILENO, STDOUT_FILENO);
        execlp("bash", "bash", script, dir, (char *)NULL);
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) /* an interrupt during plotting still waits for the script */
            return ppb_fail(err, "lost the plot script %s", script);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return ppb_fail(err, "%s %s failed (exit %d; is gnuplot installed?)", script, dir,
                        WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    return 0;
}
