/* err.h: one error value passed down every fallible call.
 *
 * Functions that can fail return 0 on success and -1 on failure, having written a complete,
 * user-facing message ("file:line: key: reason", "OpenCL: CL_BUILD_PROGRAM_FAILURE: ...")
 * into the caller's ppb_err. Nothing prints on the way up; main() prints once. */
#ifndef PPB_ERR_H
#define PPB_ERR_H

#include <stddef.h>

typedef struct ppb_err {
    char msg[2048];
} ppb_err;

/* Formats the message into err (if non-NULL) and returns -1, so callers can write
 * `return ppb_fail(err, "...", ...);`. */
int ppb_fail(ppb_err *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
