/* memory.c: the memory limit of a run (memory.h). */
#include "base/memory.h"

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
