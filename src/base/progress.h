/* progress.h: progress lines on stderr (percent, rate, ETA) and clean interruption.
 *
 * Long loops call ppb_progress_update() between units of work and stop when
 * ppb_interrupted() turns true (SIGINT or SIGTERM caught by ppb_progress_install_signals()),
 * then write what they have, marked partial. A second SIGINT or SIGTERM exits at once with
 * status 130 from the handler (_exit: nothing is flushed or written). Lines are suppressed when
 * quiet is set. On a terminal one line is rewritten in place (\r), a few times a second; when
 * stderr is not a terminal (a log, Slurm's output file) each update is a plain line of its own,
 * at most one every PPB_PROGRESS_LOG_SECONDS, so a log holds no \r and a bounded number of
 * lines. */
#ifndef PPB_PROGRESS_H
#define PPB_PROGRESS_H

#include "base/clock.h" /* ppb_now: its users time what they report progress on */

typedef struct ppb_progress {
    const char *label;
    const char *unit;
    double total;
    double t0, last;
    int quiet;
    int tty; /* stderr is a terminal (isatty at ppb_progress_begin) */
} ppb_progress;

#define PPB_PROGRESS_LOG_SECONDS 5.0 /* least gap between two lines when not a terminal */

void ppb_progress_install_signals(void);
int ppb_interrupted(void);
void ppb_interrupt_reset(void);

void ppb_progress_begin(ppb_progress *p, const char *label, const char *unit, double total,
                        int quiet);
void ppb_progress_update(ppb_progress *p, double done);
void ppb_progress_end(ppb_progress *p, double done);

#endif
