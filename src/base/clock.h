/* clock.h: the one wall clock of ppbench (timings, progress rates, benchmarks).
 *
 * Monotonic (CLOCK_MONOTONIC): never steps back when the system time is set, so differences
 * are durations. Its origin is arbitrary: only differences mean anything. */
#ifndef PPB_CLOCK_H
#define PPB_CLOCK_H

/* Monotonic seconds. */
double ppb_now(void);

#endif
