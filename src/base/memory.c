/* memory.c: the memory limit of a run (memory.h). */
#include "base/memory.h"

#include <math.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdint.h>
#include <sys/resource.h>
#include <unistd.h>

double ppb_memory_physical(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    return pages > 0 && page > 0 ? (double)pages * (double)page : 0.0;
}

double ppb_memory_limit(double setting_gb)
{
    if (setting_gb > 0.0)
        return setting_gb * 1e9;
    double phys = ppb_memory_physical();
    return phys > 0.0 ? 0.5 * phys : 8e9;
}

int ppb_memory_check(double bytes, double setting_gb, const char *what, const char *detail,
                     ppb_err *err)
{
    double limit = ppb_memory_limit(setting_gb);
    if (bytes <= limit)
        return 0;
    return ppb_fail(err,
                    "%s needs about %.3g GB (%s), above the memory limit of %.3g GB ([run] "
                    "memory_limit%s)",
                    what, bytes / 1e9, detail, limit / 1e9,
                    setting_gb > 0.0 ? "" : " = 0: half the machine's memory");
}

int ppb_memory_blas_threads(int have)
{
    const char *mark = getenv("PPB_BLAS_THREADS_SET");
    if (mark) { /* the second run: the library has read it; children see what we were given */
        unsetenv("OPENBLAS_NUM_THREADS");
        unsetenv("PPB_BLAS_THREADS_SET");
        return have;
    }
    const char *user[] = {"OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"};
    for (int i = 0; i < 3; i++)
        if (getenv(user[i]))
            return have; /* the user's count */
    /* The library's own count (the CPUs ppbench may run on: results unchanged), fewer under an
     * address-space limit; executing ppbench again only then. */
    int want = have;
    double as = ppb_memory_as_limit();
    if (as > 0.0) /* every thread's buffer within a quarter of the address space */
        want = (int)fmax(1.0, fmin(want, floor(0.25 * as / PPB_BLAS_BUFFER_BYTES)));
    return want;
}

void ppb_memory_blas_reexec(int want, char **argv)
{
    char n[32];
    snprintf(n, sizeof n, "%d", want);
    setenv("OPENBLAS_NUM_THREADS", n, 1);
    setenv("PPB_BLAS_THREADS_SET", "1", 1);
    execv("/proc/self/exe", argv);
    /* No /proc: the library's own count, as before. */
    unsetenv("OPENBLAS_NUM_THREADS");
    unsetenv("PPB_BLAS_THREADS_SET");
}

int ppb_memory_can_have(double bytes)
{
    if (!(bytes >= 0.0) || bytes > (double)SIZE_MAX)
        return 0;
    void *p = malloc((size_t)bytes);
    free(p);
    return p != NULL || bytes == 0.0;
}

double ppb_memory_as_limit(void)
{
    struct rlimit rl;
    if (getrlimit(RLIMIT_AS, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY)
        return 0.0;
    return (double)rl.rlim_cur;
}

int ppb_memory_need(double bytes, const char *what, ppb_err *err)
{
    if (ppb_memory_can_have(bytes))
        return 0;
    double as = ppb_memory_as_limit();
    char lim[128] = "";
    if (as > 0.0)
        snprintf(lim, sizeof lim, " (the address-space limit, ulimit -v, is %.0f MB)", as / 1e6);
    return ppb_fail(err, "out of memory: %s needs about %.0f MB, which cannot be had%s", what,
                    bytes / 1e6, lim);
}
