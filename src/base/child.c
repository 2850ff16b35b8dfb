/* child.c: see child.h. */
#include "base/child.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* Field 3 (state), field 4 (ppid) and field 22 (start time, clock ticks since boot) of
 * /proc/PID/stat; -1 when the process is gone. The fields are counted after the command name's
 * closing parenthesis (a name may hold spaces and parentheses). */
static int proc_stat(long pid, char *state, long *ppid, unsigned long long *start)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%ld/stat", pid);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return -1;
    ssize_t n = read(fd, buf, sizeof buf - 1);
    close(fd);
    if (n <= 0)
        return -1;
    buf[n] = '\0';
    char *p = strrchr(buf, ')');
    if (!p)
        return -1;
    unsigned long long st = 0;
    long pp = 0;
    char c = '?';
    /* after ") ": state ppid pgrp session tty_nr tpgid flags minflt cminflt majflt cmajflt utime
     * stime cutime cstime priority nice num_threads itrealvalue starttime */
    if (sscanf(p + 1,
               " %c %ld %*d %*d %*d %*d %*u %*u %*u %*u %*u %*u %*u %*d %*d %*d %*d %*d "
               "%*d %llu",
               &c, &pp, &st) != 3)
        return -1;
    if (state)
        *state = c;
    if (ppid)
        *ppid = pp;
    if (start)
        *start = st;
    return 0;
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* Calls fn(pid, arg) for every numeric entry of /proc. */
static void each_process(void (*fn)(long, void *), void *arg)
{
    DIR *d = opendir("/proc");
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d))) {
        char *end;
        long pid = strtol(e->d_name, &end, 10);
        if (*end == '\0' && pid > 0)
            fn(pid, arg);
    }
    closedir(d);
}

static void kill_if_child(long pid, void *arg)
{
    long ppid;
    if (proc_stat(pid, NULL, &ppid, NULL) == 0 && ppid == (long)getpid()) {
        kill((pid_t)pid, SIGKILL);
        *(int *)arg += 1;
    }
}

/* The guard's end: SIGKILL to every child (a subreaper's children include every orphaned
 * descendant), reaped, until none is left; a killed process's own children re-parent here and
 * are found by the next round. Bounded: a fork bomb outrunning it is left after 10 s. */
static void kill_descendants(void)
{
    for (int round = 0; round < 1000; round++) {
        int found = 0;
        each_process(kill_if_child, &found);
        while (waitpid(-1, NULL, WNOHANG) > 0)
            ;
        if (!found && waitpid(-1, NULL, WNOHANG) < 0 && errno == ECHILD)
            return;
        sleep_ms(10);
    }
}

static volatile sig_atomic_t guard_stop;

static void on_stop(int sig)
{
    guard_stop = sig;
}

static void owner_token(pid_t owner, char *buf, size_t cap)
{
    unsigned long long start = 0;
    proc_stat((long)owner, NULL, NULL, &start);
    snprintf(buf, cap, "%ld:%llu", (long)owner, start);
}

static void run_guard(const char *path, char *const argv[], pid_t owner)
{
    /* ppbench may have died before the prctl: then the parent is already another process. */
    if (prctl(PR_SET_PDEATHSIG, SIGTERM) != 0 || getppid() != owner)
        _exit(127);
    prctl(PR_SET_CHILD_SUBREAPER, 1);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;
    sigemptyset(&sa.sa_mask);
    int sigs[] = {SIGTERM, SIGINT, SIGHUP};
    for (int i = 0; i < 3; i++)
        sigaction(sigs[i], &sa, NULL);
    char token[64];
    owner_token(owner, token, sizeof token);
    pid_t cmd = fork();
    if (cmd == 0) {
        for (int i = 0; i < 3; i++)
            signal(sigs[i], SIG_DFL);
        setenv("PPBENCH_OWNER", token, 1);
        execvp(path, argv);
        _exit(127);
    }
    int st = 0, stop = 0;
    /* Polled, not a blocking wait: a signal between a check and the wait is never lost. */
    while (cmd > 0) {
        pid_t r = waitpid(cmd, &st, WNOHANG);
        if (r == cmd || (r < 0 && errno != EINTR))
            break;
        if ((stop = guard_stop)) {
            /* SIGTERM first, SIGKILL after 1.5 s: within the 2 s the caller gives the whole
             * group before its own SIGKILL (method_external.c), so the guard is still there to
             * kill the descendants that left the group. */
            kill(cmd, SIGTERM);
            pid_t r = 0;
            for (int i = 0; i < 75 && (r = waitpid(cmd, &st, WNOHANG)) == 0; i++)
                sleep_ms(20);
            if (r != cmd) {
                kill(cmd, SIGKILL);
                while (waitpid(cmd, &st, 0) < 0 && errno == EINTR)
                    ;
            }
            break;
        }
        sleep_ms(20);
    }
    kill_descendants();
    int sig = stop ? stop : cmd > 0 && WIFSIGNALED(st) ? WTERMSIG(st) : 0;
    if (sig) { /* the caller sees the same end as the command's own */
        signal(sig, SIG_DFL);
        raise(sig);
    }
    _exit(cmd > 0 && WIFEXITED(st) ? WEXITSTATUS(st) : 127);
}

pid_t ppb_child_spawn(const char *path, char *const argv[], int stdout_to_stderr, int new_group)
{
    pid_t owner = getpid();
    fflush(NULL); /* the child must not repeat buffered output */
    pid_t pid = fork();
    if (pid != 0) {
        if (pid > 0 && new_group)
            setpgid(pid, pid); /* also here: no race with the child's own call */
        return pid;
    }
    if (new_group)
        setpgid(0, 0);
    if (stdout_to_stderr)
        dup2(STDERR_FILENO, STDOUT_FILENO);
    run_guard(path, argv, owner);
    _exit(127);
}

/* Whether /proc/PID/environ holds PPBENCH_OWNER=P:T with P not running or started at another
 * time than T. */
static int left_by_dead(long pid)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/%ld/environ", pid);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return 0; /* another user's, or gone */
    static char env[1 << 16];
    ssize_t n = read(fd, env, sizeof env - 1);
    close(fd);
    if (n <= 0)
        return 0;
    env[n] = '\0';
    for (char *e = env; e < env + n; e += strlen(e) + 1) {
        long owner;
        unsigned long long start, now;
        if (sscanf(e, "PPBENCH_OWNER=%ld:%llu", &owner, &start) != 2)
            continue;
        /* A zombie is dead: a ppbench killed with SIGKILL stays one until its parent reaps
         * it. */
        char state;
        return owner != pid && (proc_stat(owner, &state, NULL, &now) != 0 || now != start ||
                                state == 'Z' || state == 'X');
    }
    return 0;
}

static void kill_if_left(long pid, void *arg)
{
    if (pid != (long)getpid() && left_by_dead(pid) && kill((pid_t)pid, SIGKILL) == 0)
        *(int *)arg += 1;
}

int ppb_child_clean_dead(void)
{
    int n = 0;
    each_process(kill_if_left, &n);
    return n;
}
