/* memory.h: the memory limit of a run: what a method may allocate, and the check a
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

/* The linear-algebra library's threads (docs/reference.md: Keys, run.memory_limit). OpenBLAS
 * starts its threads and reads OPENBLAS_NUM_THREADS when it is loaded, before main, and a
 * thread whose 128 MiB work buffer cannot be had retries for ever (an exit then waits on it,
 * deaf to SIGTERM). ppbench's count: the CPUs it may run on (OpenBLAS's own default, so results
 * do not change), fewer under an address-space limit (ulimit -v) so that every thread's buffer
 * fits in a quarter of it, at least 1; a count the user set (OPENBLAS_NUM_THREADS,
 * GOTO_NUM_THREADS, OMP_NUM_THREADS) is theirs. ppb_memory_blas_threads returns the count
 * wanted given `have`, the library's; when they differ the caller executes ppbench again with
 * OPENBLAS_NUM_THREADS set (ppb_memory_blas_reexec, which returns only if it cannot), and the
 * second run unsets it (and returns `have`), so that the commands ppbench starts see the
 * environment it was given. */
int ppb_memory_blas_threads(int have);
void ppb_memory_blas_reexec(int want, char **argv);

/* Whether `bytes` can be allocated now (malloc, touched nowhere, freed). */
int ppb_memory_can_have(double bytes);

/* The bytes OpenBLAS allocates for its work buffer at its first call (BUFFER_SIZE of its x86-64
 * builds, 128 MiB, and its guard page): it retries the allocation for ever, so ppbench checks it
 * first. */
#define PPB_BLAS_BUFFER_BYTES 134221824.0

/* Address space the OpenCL runtime (the ICD loader, PoCL and LLVM) maps when it is loaded:
 * about 200 MB with PoCL 3; below that, "no platform found" means out of memory. */
#define PPB_OCL_LOAD_BYTES 256e6

/* Fails with "out of memory: WHAT needs about X MB, which cannot be had (address-space limit
 * ...)" unless `bytes` can be had now. */
int ppb_memory_need(double bytes, const char *what, ppb_err *err);

/* The address-space limit (ulimit -v) in bytes, 0 when there is none. */
double ppb_memory_as_limit(void);

#endif
