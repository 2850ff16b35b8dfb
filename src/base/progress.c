#include "base/progress.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static volatile sig_atomic_t interrupted;

/* Only async-signal-safe calls here (write, _exit). The first signal asks the running loop to
 * stop at its next check and write what it has; the second exits at once, for the stretches no
 * check reaches (a LAPACK call, one long kernel launch), writing nothing more. */
static void on_signal(int sig)
{
    (void)sig;
    static const char first[] = "\nppbench: interrupted: stopping at the next check, writing "
                                "what is done (interrupt again to exit at once)\n";
    static const char second[] = "\nppbench: interrupted again: exiting now, nothing more is "
                                 "written\n";
    if (interrupted) {
        ssize_t w = write(STDERR_FILENO, second, sizeof second - 1);
        (void)w;
        _exit(130);
    }
    interrupted = 1;
    ssize_t w = write(STDERR_FILENO, first, sizeof first - 1);
    (void)w;
}

void ppb_progress_install_signals(void)
{
    struct sigaction sa = {0};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT); /* one handler at a time: the count stays exact */
    sigaddset(&sa.sa_mask, SIGTERM);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

int ppb_interrupted(void)
{
    return interrupted != 0;
}
void ppb_interrupt_reset(void)
{
    interrupted = 0;
}

void ppb_progress_begin(ppb_progress *p, const char *label, const char *unit, double total,
                        int quiet)
{
    p->label = label;
    p->unit = unit;
    p->total = total;
    p->t0 = p->last = ppb_now();
    p->quiet = quiet;
    p->tty = isatty(STDERR_FILENO);
}

/* The unit as the count needs it: "1 point", "2 points" (units are given in the plural). */
static int singular(const char *unit, double n)
{
    size_t len = strlen(unit);
    return n == 1 && len > 1 && unit[len - 1] == 's';
}

static void print_line(const ppb_progress *p, double done, double now)
{
    double dt = now - p->t0;
    double rate = dt > 0 ? done / dt : 0;
    double pct = p->total > 0 ? 100.0 * done / p->total : 100.0;
    double eta = rate > 0 ? (p->total - done) / rate : 0;
    if (p->tty)
        fprintf(stderr, "\r%s: %5.1f%%  %.3g %s/s  ETA %.0f s   ", p->label, pct, rate, p->unit,
                eta);
    else
        fprintf(stderr, "%s: %.1f%%  %.3g %s/s  ETA %.0f s\n", p->label, pct, rate, p->unit, eta);
    fflush(stderr);
}

void ppb_progress_update(ppb_progress *p, double done)
{
    double now = ppb_now();
    if (p->quiet || now - p->last < (p->tty ? 0.5 : PPB_PROGRESS_LOG_SECONDS))
        return;
    p->last = now;
    print_line(p, done, now);
}

void ppb_progress_end(ppb_progress *p, double done)
{
    if (p->quiet)
        return;
    double now = ppb_now();
    int one = singular(p->unit, done);
    fprintf(stderr, "%s%s: %.3g %.*s in %.2f s%s\n", p->tty ? "\r" : "", p->label, done,
            (int)strlen(p->unit) - one, p->unit, now - p->t0,
            ppb_interrupted() ? " (interrupted)"
            : p->tty          ? "                "
                              : "");
}
