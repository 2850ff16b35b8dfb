#include "runtime/ocl.h"

#include <ctype.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "base/atomic_file.h"
#include "base/hash.h"
#include "base/memory.h"

#ifndef PPB_SOURCE_DIR
#define PPB_SOURCE_DIR "."
#endif
#define MAX_PLATFORMS 16
#define MAX_DEVICES   64

const char *ppb_cl_errname(cl_int code)
{
    switch (code) {
#define E(c)                                                                                       \
    case c:                                                                                        \
        return #c;
        /* clang-format off */
        E(CL_SUCCESS)
        E(CL_DEVICE_NOT_FOUND)
        E(CL_DEVICE_NOT_AVAILABLE)
        E(CL_COMPILER_NOT_AVAILABLE)
        E(CL_MEM_OBJECT_ALLOCATION_FAILURE)
        E(CL_OUT_OF_RESOURCES)
        E(CL_OUT_OF_HOST_MEMORY)
        E(CL_PROFILING_INFO_NOT_AVAILABLE)
        E(CL_MEM_COPY_OVERLAP)
        E(CL_IMAGE_FORMAT_MISMATCH)
        E(CL_IMAGE_FORMAT_NOT_SUPPORTED)
        E(CL_BUILD_PROGRAM_FAILURE)
        E(CL_MAP_FAILURE)
        E(CL_MISALIGNED_SUB_BUFFER_OFFSET)
        E(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
        E(CL_COMPILE_PROGRAM_FAILURE)
        E(CL_LINKER_NOT_AVAILABLE)
        E(CL_LINK_PROGRAM_FAILURE)
        E(CL_DEVICE_PARTITION_FAILED)
        E(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
        E(CL_INVALID_VALUE)
        E(CL_INVALID_DEVICE_TYPE)
        E(CL_INVALID_PLATFORM)
        E(CL_INVALID_DEVICE)
        E(CL_INVALID_CONTEXT)
        E(CL_INVALID_QUEUE_PROPERTIES)
        E(CL_INVALID_COMMAND_QUEUE)
        E(CL_INVALID_HOST_PTR)
        E(CL_INVALID_MEM_OBJECT)
        E(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
        E(CL_INVALID_IMAGE_SIZE)
        E(CL_INVALID_SAMPLER)
        E(CL_INVALID_BINARY)
        E(CL_INVALID_BUILD_OPTIONS)
        E(CL_INVALID_PROGRAM)
        E(CL_INVALID_PROGRAM_EXECUTABLE)
        E(CL_INVALID_KERNEL_NAME)
        E(CL_INVALID_KERNEL_DEFINITION)
        E(CL_INVALID_KERNEL)
        E(CL_INVALID_ARG_INDEX)
        E(CL_INVALID_ARG_VALUE)
        E(CL_INVALID_ARG_SIZE)
        E(CL_INVALID_KERNEL_ARGS)
        E(CL_INVALID_WORK_DIMENSION)
        E(CL_INVALID_WORK_GROUP_SIZE)
        E(CL_INVALID_WORK_ITEM_SIZE)
        E(CL_INVALID_GLOBAL_OFFSET)
        E(CL_INVALID_EVENT_WAIT_LIST)
        E(CL_INVALID_EVENT)
        E(CL_INVALID_OPERATION)
        E(CL_INVALID_GL_OBJECT)
        E(CL_INVALID_BUFFER_SIZE)
        E(CL_INVALID_MIP_LEVEL)
        E(CL_INVALID_GLOBAL_WORK_SIZE)
        E(CL_INVALID_PROPERTY)
        E(CL_INVALID_IMAGE_DESCRIPTOR)
        E(CL_INVALID_COMPILER_OPTIONS)
        E(CL_INVALID_LINKER_OPTIONS)
        E(CL_INVALID_DEVICE_PARTITION_COUNT)
        /* clang-format on */
#undef E
    case -1001:
        return "CL_PLATFORM_NOT_FOUND_KHR (no OpenCL platform: is pocl-opencl-icd installed?)";
    default:
        return "unknown OpenCL error";
    }
}

int ppb_cl_check(cl_int code, const char *what, ppb_err *err)
{
    if (code == CL_SUCCESS)
        return 0;
    return ppb_fail(err, "OpenCL: %s failed: %s (%d)", what, ppb_cl_errname(code), (int)code);
}

/* Every (platform, device) pair in a fixed order: platforms as the ICD loader lists them,
 * devices of all types within each. This order is what indices refer to. */
typedef struct dev_entry {
    cl_platform_id platform;
    cl_device_id device;
    char name[512];
} dev_entry;

static int enumerate(dev_entry *out, int cap, ppb_err *err)
{
    cl_platform_id plats[MAX_PLATFORMS];
    cl_uint np = 0;
    cl_int rc = clGetPlatformIDs(MAX_PLATFORMS, plats, &np);
    /* The ICD loader says "no platform" too when the driver cannot be loaded for want of
     * memory (an address-space limit): then memory is what is reported. */
    if ((rc == -1001 || (rc == CL_SUCCESS && np == 0)) && ppb_memory_as_limit() > 0.0 &&
        !ppb_memory_can_have(PPB_OCL_LOAD_BYTES))
        return ppb_memory_need(PPB_OCL_LOAD_BYTES, "loading the OpenCL platform", err);
    if (rc == -1001 || (rc == CL_SUCCESS && np == 0))
        return ppb_fail(err, "OpenCL: no platform found (install pocl-opencl-icd: make deps)");
    if (ppb_cl_check(rc, "clGetPlatformIDs", err))
        return -1;
    int n = 0;
    for (cl_uint p = 0; p < np && p < MAX_PLATFORMS; p++) {
        cl_device_id devs[MAX_DEVICES];
        cl_uint nd = 0;
        if (clGetDeviceIDs(plats[p], CL_DEVICE_TYPE_ALL, MAX_DEVICES, devs, &nd) != CL_SUCCESS)
            continue;
        char pname[200] = "";
        clGetPlatformInfo(plats[p], CL_PLATFORM_NAME, sizeof pname, pname, NULL);
        for (cl_uint d = 0; d < nd && n < cap; d++, n++) {
            char dname[256] = "";
            clGetDeviceInfo(devs[d], CL_DEVICE_NAME, sizeof dname, dname, NULL);
            out[n].platform = plats[p];
            out[n].device = devs[d];
            snprintf(out[n].name, sizeof out[n].name, "%s / %s", pname, dname);
        }
    }
    if (n == 0)
        return ppb_fail(err, "OpenCL: no device found: %s", ppb_cl_errname(CL_DEVICE_NOT_FOUND));
    return n;
}

int ppb_ocl_list(FILE *out, ppb_err *err)
{
    dev_entry devs[MAX_DEVICES];
    int n = enumerate(devs, MAX_DEVICES, err);
    for (int i = 0; i < n; i++) {
        cl_uint cu = 0;
        cl_ulong mem = 0;
        char ver[128] = "";
        clGetDeviceInfo(devs[i].device, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cu, &cu, NULL);
        clGetDeviceInfo(devs[i].device, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof mem, &mem, NULL);
        clGetDeviceInfo(devs[i].device, CL_DEVICE_VERSION, sizeof ver, ver, NULL);
        fprintf(out, "%d: %s (%u compute units, %.1f GiB, %s)\n", i, devs[i].name, cu,
                (double)mem / (1024.0 * 1024.0 * 1024.0), ver);
    }
    return n;
}

static int contains_nocase(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; *hay; hay++) {
        size_t i = 0;
        while (i < n && hay[i] &&
               tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
            i++;
        if (i == n)
            return 1;
    }
    return 0;
}

/* Index when the selector is all digits, else the first name containing it; `what` names where
 * the selector came from ("--device" or "$PPBENCH_DEVICE") in the error. */
static int choose(const dev_entry *devs, int n, const char *sel, const char *what, ppb_err *err)
{
    if (!sel || !*sel)
        return 0;
    char *end;
    long idx = strtol(sel, &end, 10);
    if (*end == '\0') {
        if (idx < 0 || idx >= n)
            return ppb_fail(err, "%s %s: no such device (there are %d; see `ppbench devices`)",
                            what, sel, n);
        return (int)idx;
    }
    for (int i = 0; i < n; i++)
        if (contains_nocase(devs[i].name, sel))
            return i;
    return ppb_fail(err, "%s %s: no device name contains it (see `ppbench devices`)", what, sel);
}

/* The selector in effect: the given one, else $PPBENCH_DEVICE; *what names its origin. */
static const char *effective(const char *selector, const char **what)
{
    *what = "--device";
    if (selector && *selector)
        return selector;
    *what = "$PPBENCH_DEVICE";
    return getenv("PPBENCH_DEVICE");
}

int ppb_ocl_select(const char *selector, ppb_err *err)
{
    const char *what;
    const char *sel = effective(selector, &what);
    dev_entry devs[MAX_DEVICES];
    int n = enumerate(devs, MAX_DEVICES, err);
    if (n < 0) {
        if (sel && *sel) {
            ppb_err why = *err;
            return ppb_fail(err, "%s %s: %s", what, sel, why.msg);
        }
        return -1;
    }
    return choose(devs, n, sel, what, err);
}

/* The device limits the launches are sized by; a query that fails, or a work-group limit of
 * zero (the launch size would divide by it), is an error naming the query. */
static int device_info(ppb_ocl *ocl, ppb_err *err)
{
    const struct {
        cl_device_info what;
        const char *name;
        void *dst;
        size_t size;
    } q[] = {
        {CL_DEVICE_MAX_COMPUTE_UNITS, "CL_DEVICE_MAX_COMPUTE_UNITS", &ocl->compute_units,
         sizeof ocl->compute_units},
        {CL_DEVICE_MAX_WORK_GROUP_SIZE, "CL_DEVICE_MAX_WORK_GROUP_SIZE", &ocl->max_workgroup,
         sizeof ocl->max_workgroup},
        {CL_DEVICE_GLOBAL_MEM_SIZE, "CL_DEVICE_GLOBAL_MEM_SIZE", &ocl->global_mem,
         sizeof ocl->global_mem},
        {CL_DEVICE_MAX_MEM_ALLOC_SIZE, "CL_DEVICE_MAX_MEM_ALLOC_SIZE", &ocl->max_alloc,
         sizeof ocl->max_alloc},
    };
    for (size_t i = 0; i < sizeof q / sizeof q[0]; i++) {
        char what[96];
        snprintf(what, sizeof what, "clGetDeviceInfo(%s)", q[i].name);
        if (ppb_cl_check(clGetDeviceInfo(ocl->device, q[i].what, q[i].size, q[i].dst, NULL), what,
                         err))
            return -1;
    }
    if (ocl->max_workgroup == 0 || ocl->compute_units == 0)
        return ppb_fail(err, "OpenCL: %s reports %s 0", ocl->name,
                        ocl->max_workgroup == 0 ? "CL_DEVICE_MAX_WORK_GROUP_SIZE"
                                                : "CL_DEVICE_MAX_COMPUTE_UNITS");
    return 0;
}

int ppb_ocl_open(ppb_ocl *ocl, const char *selector, ppb_err *err)
{
    memset(ocl, 0, sizeof *ocl);
    dev_entry devs[MAX_DEVICES];
    int n = enumerate(devs, MAX_DEVICES, err);
    if (n < 0)
        return -1;
    const char *what;
    selector = effective(selector, &what);
    int i = choose(devs, n, selector, what, err);
    if (i < 0)
        return -1;
    ocl->platform = devs[i].platform;
    ocl->device = devs[i].device;
    snprintf(ocl->name, sizeof ocl->name, "%s", devs[i].name);
    if (device_info(ocl, err))
        return -1;
    cl_int rc;
    cl_context_properties props[] = {CL_CONTEXT_PLATFORM, (cl_context_properties)ocl->platform, 0};
    ocl->context = clCreateContext(props, 1, &ocl->device, NULL, NULL, &rc);
    if (ppb_cl_check(rc, "clCreateContext", err))
        return -1;
    ocl->queue = clCreateCommandQueue(ocl->context, ocl->device, 0, &rc);
    if (ppb_cl_check(rc, "clCreateCommandQueue", err)) {
        clReleaseContext(ocl->context);
        ocl->context = NULL;
        return -1;
    }
    return 0;
}

void ppb_ocl_close(ppb_ocl *ocl)
{
    for (int i = 0; i < ocl->nbuilt; i++)
        clReleaseProgram(ocl->built[i].prog);
    ocl->nbuilt = 0;
    if (ocl->queue)
        clReleaseCommandQueue(ocl->queue);
    if (ocl->context)
        clReleaseContext(ocl->context);
    ocl->queue = NULL;
    ocl->context = NULL;
}

/* The tree kernel files are named in: the repository (kernels/ holds the headers every kernel
 * shares, src/methods/<slice>/ each method's own kernels); $PPBENCH_SOURCE overrides it. */
static const char *source_root(void)
{
    const char *d = getenv("PPBENCH_SOURCE");
    return (d && *d) ? d : PPB_SOURCE_DIR;
}

/* The build's include path, in the compiler's order: the kernel's own folder (its slice),
 * then the shared kernels/ headers, then Random123 under /usr/include. */
enum { NINC = 3 };
static void include_dirs(const char *path, char dirs[NINC][1024])
{
    const char *slash = strrchr(path, '/');
    snprintf(dirs[0], sizeof dirs[0], "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
    snprintf(dirs[1], sizeof dirs[1], "%s/kernels", source_root());
    snprintf(dirs[2], sizeof dirs[2], "/usr/include");
}

static char *read_file(const char *path, ppb_err *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        ppb_fail(err,
                 "%s: cannot open kernel source (set PPBENCH_SOURCE to the ppbench source tree)",
                 path);
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        fclose(f);
        ppb_fail(err, "%s: cannot read kernel source", path);
        return NULL;
    }
    buf[n] = '\0';
    fclose(f);
    return buf;
}

/* The source-text hash (ocl.h): the file, then each file it includes that the build would
 * find, depth first, each once. "x" is looked up beside its includer first, as the compiler
 * does; both forms then in the build's -I dirs (ppb_ocl_build). */
typedef struct src_walk {
    ppb_hasher *h;
    const char *root; /* the kernel file the walk started from: its include path */
    char seen[64][1024];
    int nseen;
} src_walk;

static int hash_source(src_walk *w, const char *path, int depth, ppb_err *err)
{
    for (int i = 0; i < w->nseen; i++)
        if (strcmp(w->seen[i], path) == 0)
            return 0;
    if (depth > 16 || w->nseen == (int)(sizeof w->seen / sizeof w->seen[0]))
        return ppb_fail(err, "%s: kernel sources include too many files to hash", path);
    snprintf(w->seen[w->nseen++], sizeof w->seen[0], "%s", path);
    char *src = read_file(path, err);
    if (!src)
        return -1;
    ppb_hash64_update(w->h, src, strlen(src) + 1); /* + 1: the NUL ends one file's text */
    int rc = 0;
    for (char *line = src; rc == 0 && line && *line; line = strchr(line, '\n'), line += !!line) {
        char *p = line + strspn(line, " \t");
        if (*p != '#')
            continue;
        p += 1 + strspn(p + 1, " \t");
        if (strncmp(p, "include", 7) != 0)
            continue;
        p += 7 + strspn(p + 7, " \t");
        char close = *p == '"' ? '"' : *p == '<' ? '>' : 0;
        char *end = close ? strchr(p + 1, close) : NULL;
        char *eol = strchr(p, '\n');
        if (!end || (eol && end > eol))
            continue;
        char name[512], cand[1024];
        snprintf(name, sizeof name, "%.*s", (int)(end - p - 1), p + 1);
        /* "x" beside its includer first, as the compiler does; both forms then on the
         * build's include path. */
        char inc[NINC][1024], here[1024];
        include_dirs(w->root, inc);
        const char *slash = strrchr(path, '/');
        const char *dirs[NINC + 1] = {NULL, inc[0], inc[1], inc[2]};
        if (close == '"' && slash) {
            snprintf(here, sizeof here, "%.*s", (int)(slash - path), path);
            dirs[0] = here;
        }
        for (int d = 0; d < NINC + 1; d++) {
            if (!dirs[d])
                continue;
            snprintf(cand, sizeof cand, "%s/%s", dirs[d], name);
            if (access(cand, R_OK) == 0) {
                rc = hash_source(w, cand, depth + 1, err);
                break;
            }
        }
        /* Not found: a header of the OpenCL compiler itself, or one under a branch the kernel
         * build never takes; the text that includes it is hashed. */
    }
    free(src);
    return rc;
}

int ppb_ocl_source_hash(const char *file, uint64_t *hash, ppb_err *err)
{
    src_walk *w = calloc(1, sizeof *w);
    if (!w || !(w->h = ppb_hash64_begin())) {
        free(w);
        return ppb_fail(err, "out of memory hashing kernel %s", file);
    }
    char path[2048];
    snprintf(path, sizeof path, "%s/%s", source_root(), file);
    w->root = path;
    int rc = hash_source(w, path, 0, err);
    uint64_t h = ppb_hash64_end(w->h);
    free(w);
    if (rc == 0)
        *hash = h;
    return rc;
}

/* The program's build log (malloc'ed, "" when empty; NULL without memory). */
static char *build_log(ppb_ocl *ocl, cl_program prog)
{
    size_t n = 0;
    clGetProgramBuildInfo(prog, ocl->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &n);
    char *log = malloc(n + 1);
    if (log) {
        log[0] = '\0';
        clGetProgramBuildInfo(prog, ocl->device, CL_PROGRAM_BUILD_LOG, n, log, NULL);
        log[n] = '\0';
    }
    return log;
}

/* Whether s holds more than blanks. */
static int said_something(const char *s)
{
    for (; s && *s; s++)
        if (!isspace((unsigned char)*s))
            return 1;
    return 0;
}

/* What the OpenCL compiler writes to the process's stderr while it builds (PoCL's clang prints
 * its diagnostics and "56 warnings generated." there, outside the build log) is caught in a
 * temporary file: fd 2 points there during clBuildProgram. begin returns the saved fd 2 (-1
 * when nothing could be redirected, and the compiler then writes where it always did). */
static int stderr_catch_begin(FILE **tmp)
{
    fflush(stderr);
    *tmp = tmpfile();
    int saved = *tmp ? dup(2) : -1;
    if (saved >= 0 && dup2(fileno(*tmp), 2) < 0) {
        close(saved);
        saved = -1;
    }
    return saved;
}

/* Puts fd 2 back; returns what was written meanwhile (malloc'ed; NULL when nothing). */
static char *stderr_catch_end(int saved, FILE *tmp)
{
    char *text = NULL;
    fflush(stderr);
    if (saved >= 0) {
        dup2(saved, 2);
        close(saved);
    }
    if (!tmp)
        return NULL;
    long n = ftell(tmp);
    if (saved >= 0 && n > 0 && (text = malloc((size_t)n + 1))) {
        rewind(tmp);
        size_t got = fread(text, 1, (size_t)n, tmp);
        text[got] = '\0';
    }
    fclose(tmp);
    return text;
}

int ppb_ocl_build_log_path(char *buf, size_t cap)
{
    const char *env = getenv("PPBENCH_BUILD_LOG"), *xdg = getenv("XDG_CACHE_HOME"),
               *home = getenv("HOME");
    int n;
    if (env)
        n = snprintf(buf, cap, "%s", env);
    else if (xdg && xdg[0])
        n = snprintf(buf, cap, "%s/ppbench/kernel-build.log", xdg);
    else if (home && home[0])
        n = snprintf(buf, cap, "%s/.cache/ppbench/kernel-build.log", home);
    else
        n = -1;
    return n > 0 && (size_t)n < cap ? 0 : -1;
}

/* Appends one build's diagnostics to the kernel build log (ppb_ocl_build_log_path), as one
 * write on an O_APPEND file so that concurrent processes (sweep --jobs) do not interleave;
 * nothing is said when the log cannot be written (the build itself succeeded). */
static void log_build(const ppb_ocl *ocl, const char *path, const char *opts, const char *said,
                      const char *log)
{
    char file[4096];
    if (ppb_ocl_build_log_path(file, sizeof file))
        return;
    char *slash = strrchr(file, '/');
    if (slash && slash != file) {
        *slash = '\0';
        ppb_err ignored = {{0}};
        int rc = ppb_mkdirs(file, &ignored);
        *slash = '/';
        if (rc)
            return;
    }
    char when[32];
    time_t now = time(NULL);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    size_t cap = strlen(path) + strlen(opts) + strlen(ocl->name) + (said ? strlen(said) : 0) +
                 (log ? strlen(log) : 0) + 256;
    char *entry = malloc(cap);
    if (!entry)
        return;
    int n = snprintf(entry, cap, "== %s pid %d: %s (options %s) on %s\n%s%s%s%s", when,
                     (int)getpid(), path, opts, ocl->name, said ? said : "",
                     said && said[0] && said[strlen(said) - 1] != '\n' ? "\n" : "",
                     said_something(log) ? "build log:\n" : "", said_something(log) ? log : "");
    int fd = open(file, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd >= 0) {
        if (n > 0 && write(fd, entry, strlen(entry)) < 0) {
            /* a log that cannot take it: the build succeeded all the same */
        }
        close(fd);
    }
    free(entry);
}

/* Reports the build log and what the compiler said on stderr, and releases the program; the
 * caller's handle is cleared by ppb_ocl_build, so no caller can release it a second time (PoCL
 * aborts on that). */
static int build_failed(ppb_ocl *ocl, cl_program prog, const char *path, cl_int rc,
                        const char *said, ppb_err *err)
{
    char *log = build_log(ocl, prog);
    ppb_fail(err, "OpenCL: building %s failed: %s\nbuild log:\n%s%s%s", path, ppb_cl_errname(rc),
             said_something(log) ? log : "(no log)\n",
             said_something(said) ? "\nthe compiler's output:\n" : "",
             said_something(said) ? said : "");
    free(log);
    clReleaseProgram(prog);
    return -1;
}

int ppb_ocl_build(ppb_ocl *ocl, const char *file, const char *extra, cl_program *prog, ppb_err *err)
{
    char path[2048], opts[4096], key[256];
    int keyed = snprintf(key, sizeof key, "%s\n%s", file, extra ? extra : "") < (int)sizeof key;
    for (int i = 0; keyed && i < ocl->nbuilt; i++)
        if (strcmp(ocl->built[i].key, key) == 0 && clRetainProgram(ocl->built[i].prog) == 0) {
            *prog = ocl->built[i].prog;
            return 0;
        }
    snprintf(path, sizeof path, "%s/%s", source_root(), file);
    char *src = read_file(path, err);
    if (!src)
        return -1;
    cl_int rc;
    const char *srcs[1] = {src};
    *prog = clCreateProgramWithSource(ocl->context, 1, srcs, NULL, &rc);
    free(src);
    if (ppb_cl_check(rc, "clCreateProgramWithSource", err)) {
        *prog = NULL;
        return -1;
    }
    /* Random123's headers sit under /usr/include; -cl-fp32-correctly-rounded-divide-sqrt is
     * left out on purpose: kernels that need exact results use double. */
    char inc[NINC][1024];
    include_dirs(path, inc);
    snprintf(opts, sizeof opts, "-I %s -I %s -I %s %s", inc[0], inc[1], inc[2], extra ? extra : "");
    /* Warnings go to the kernel build log, not the user's terminal (reference: Outputs); a
     * failure's log is in the error, which is printed. */
    FILE *tmp;
    int saved = stderr_catch_begin(&tmp);
    rc = clBuildProgram(*prog, 1, &ocl->device, opts, NULL, NULL);
    char *said = stderr_catch_end(saved, tmp);
    if (rc != CL_SUCCESS) {
        cl_program failed = *prog;
        *prog = NULL;
        build_failed(ocl, failed, path, rc, said, err);
        free(said);
        return -1;
    }
    char *log = build_log(ocl, *prog);
    if (said_something(said) || said_something(log))
        log_build(ocl, path, opts, said, log);
    free(log);
    free(said);
    int n = ocl->nbuilt;
    if (keyed && n < (int)(sizeof ocl->built / sizeof ocl->built[0]) &&
        clRetainProgram(*prog) == CL_SUCCESS) {
        snprintf(ocl->built[n].key, sizeof ocl->built[n].key, "%s", key);
        ocl->built[n].prog = *prog;
        ocl->nbuilt = n + 1;
    }
    return 0;
}

int ppb_ocl_kernel(cl_program prog, const char *name, cl_kernel *k, ppb_err *err)
{
    cl_int rc;
    *k = clCreateKernel(prog, name, &rc);
    if (rc != CL_SUCCESS) {
        *k = NULL;
        return ppb_fail(err, "OpenCL: clCreateKernel(%s) failed: %s", name, ppb_cl_errname(rc));
    }
    return 0;
}
