/* deviceutil.h: the OpenCL device a kernel suite opens once for all its tests (cmocka's group
 * setup and teardown), for the suites that launch kernels themselves. */
#ifndef PPB_DEVICEUTIL_H
#define PPB_DEVICEUTIL_H

#include <stdio.h>

#include "runtime/ocl.h"

/* The suite's device (one per test program). */
static inline ppb_ocl *tu_ocl(void)
{
    static ppb_ocl ocl;
    return &ocl;
}

static inline int tu_open_device(void **state)
{
    (void)state;
    ppb_err err;
    if (ppb_ocl_open(tu_ocl(), NULL, &err)) {
        fprintf(stderr, "no OpenCL device: %s\n", err.msg);
        return -1;
    }
    return 0;
}

static inline int tu_close_device(void **state)
{
    (void)state;
    ppb_ocl_close(tu_ocl());
    return 0;
}

#endif
