/* ocl.h: the OpenCL runtime: platform and device discovery and choice, program builds from
 * the source tree (a slice's kernel with its own folder and the shared kernels/ headers and
 * Random123 on the include path), and error names.
 * A ppb_ocl owns its context, queue and device; ppb_ocl_close releases them. Device choice:
 * an index into the flattened list that `ppbench devices` prints, or a case-insensitive
 * substring of "platform / device" names; NULL or "" falls back to $PPBENCH_DEVICE, then 0. */
#ifndef PPB_OCL_H
#define PPB_OCL_H

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#include <stdint.h>
#include <stdio.h>

#include "base/err.h"

typedef struct ppb_ocl {
    cl_platform_id platform;
    cl_device_id device;
    cl_context context;
    cl_command_queue queue;
    char name[512]; /* "platform / device" */
    cl_uint compute_units;
    size_t max_workgroup;
    cl_ulong global_mem;
    cl_ulong max_alloc;
    /* Programs built so far, by file and options (ppb_ocl_build): a process that runs many
     * points (a sweep, the robustness test) builds each kernel once, not once per point. */
    struct {
        char key[256];
        cl_program prog;
    } built[8];
    int nbuilt;
} ppb_ocl;

const char *ppb_cl_errname(cl_int code);

/* Prints one line per device ("index: platform / device, units, memory"); returns the count. */
int ppb_ocl_list(FILE *out, ppb_err *err);

/* Resolves a selector as ppb_ocl_open does, opening nothing: the device's index, or -1 with an
 * error naming the selector and its origin (--device, or $PPBENCH_DEVICE when selector is NULL
 * or ""). The command line calls it before any work, so a bad choice is a usage error. */
int ppb_ocl_select(const char *selector, ppb_err *err);

int ppb_ocl_open(ppb_ocl *ocl, const char *selector, ppb_err *err);
void ppb_ocl_close(ppb_ocl *ocl);

/* Builds <root>/<file>, the root being the source tree ($PPBENCH_SOURCE, else the build-time
 * path) and file a kernel such as "src/methods/mc/mc.cl", with options "-I <file's folder>
 * -I <root>/kernels -I <Random123> <extra>". On failure err holds the build log and what the
 * compiler printed; a successful build's warnings go to the kernel build log
 * (ppb_ocl_build_log_path), not to stderr. A program built before on this ocl with the same
 * file and extra is returned again (retained: the caller releases it as a fresh one);
 * ppb_ocl_close releases them. */
int ppb_ocl_build(ppb_ocl *ocl, const char *file, const char *extra, cl_program *prog,
                  ppb_err *err);

/* The kernel build log, where a successful build's warnings go (the compiler's stderr output
 * and the program's build log, appended with a header line naming the time, process, file,
 * options and device): $PPBENCH_BUILD_LOG, else $XDG_CACHE_HOME/ppbench/kernel-build.log, else
 * ~/.cache/ppbench/kernel-build.log. 0 and the path in buf, or -1 when none can be named. */
int ppb_ocl_build_log_path(char *buf, size_t cap);

/* A hash of the source text a build of <root>/<file> compiles: the file and, transitively,
 * every header it includes that the build's include path finds (the shared kernels/ headers,
 * Random123), so a cache of a kernel's results (methods/mc_cache.h) can tell a changed kernel.
 * Fails as ppb_ocl_build does when a file cannot be read. */
int ppb_ocl_source_hash(const char *file, uint64_t *hash, ppb_err *err);

/* Creates kernel `name` from prog, naming it in the error. */
int ppb_ocl_kernel(cl_program prog, const char *name, cl_kernel *k, ppb_err *err);

/* Turns a failing OpenCL call into an error naming the call and the code: returns 0 when
 * code == CL_SUCCESS. */
int ppb_cl_check(cl_int code, const char *what, ppb_err *err);

#endif
