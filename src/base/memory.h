/* memory.h: the memory limit of a run (issue 15): what a method may allocate, and the check a
 * method makes with its own estimate before it allocates anything, so that a point too large
 * for the machine is refused with the estimate in the message instead of growing until the
 * allocator or the OpenCL runtime fails (or the machine swaps). */
#ifndef PPB_MEMORY_H
#define PPB_MEMORY_H

#include "base/err.h"

/* Physical memory of this machine in bytes (0 when the system does not say). */
double ppb_memory_physical(void);

/* The limit in bytes for a setting in GB ([run] memory_limit): the setting when positive, else
 * half the physical memory (or 8 GB when the system does not say). */
double ppb_memory_limit(double setting_gb);

/* Fails unless `bytes` (an estimate of what `what` will allocate) fits within the limit of
 * setting_gb: "WHAT needs about X GB (DETAIL), above the memory limit of Y GB ([run]
 * memory_limit)". */
int ppb_memory_check(double bytes, double setting_gb, const char *what, const char *detail,
                     ppb_err *err);

#endif
