/* child.h: commands ppbench runs (an external method's command, scripts/plots.sh) die with it.
 *
 * A command is not started directly: ppbench forks a guard, which forks the command. The guard
 * is a child subreaper (prctl PR_SET_CHILD_SUBREAPER), so every descendant the command leaves
 * behind -- a background job, a daemon that called setsid to leave the process group --
 * re-parents to it instead of to init; when the command ends, or when the guard is told to stop
 * (SIGTERM, SIGINT, SIGHUP) or ppbench dies (PR_SET_PDEATHSIG: SIGTERM), the guard kills all
 * of them (SIGKILL, until it has no child left) and exits with the command's status. Every
 * descendant also carries PPBENCH_OWNER=<pid>:<start time> of the ppbench that started it in
 * its environment, so that a run after a ppbench (or guard) killed with SIGKILL kills what that
 * one left: ppb_child_clean_dead (docs/reference.md: Exit codes). */
#ifndef PPB_CHILD_H
#define PPB_CHILD_H

#include <sys/types.h>

/* Forks a guard running `path argv...` (execvp), its stdout the caller's stderr when
 * stdout_to_stderr, in a process group of its own when new_group (the guard's pid is the
 * group's id); the guard's pid, or -1 with errno set. Its wait status is the command's: the
 * same exit code, or the same terminating signal. */
pid_t ppb_child_spawn(const char *path, char *const argv[], int stdout_to_stderr, int new_group);

/* Kills (SIGKILL) the processes of this user that a ppbench no longer running left behind:
 * those whose PPBENCH_OWNER names a process that is gone or was started at another time.
 * Returns how many. */
int ppb_child_clean_dead(void);

#endif
