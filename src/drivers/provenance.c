#include "drivers/provenance.h"

#include <OpenEXR/openexr.h>
#include <cblas.h>
#include <lapacke.h>
#include <png.h>
#include <string.h>
#include <xxhash.h>

#ifndef PPB_COMMIT
#define PPB_COMMIT "unknown"
#endif
#ifndef PPB_INIH_VERSION
#define PPB_INIH_VERSION "unknown"
#endif

static void cl_string(cl_int rc, char *buf, size_t cap)
{
    buf[cap - 1] = '\0';
    if (rc != CL_SUCCESS)
        snprintf(buf, cap, "(unknown)");
    /* A value is one line of provenance.txt: no line breaks from the runtime. */
    for (char *c = buf; *c; c++)
        if (*c == '\n' || *c == '\r')
            *c = ' ';
}

void ppb_ocl_versions_get(const ppb_ocl *ocl, ppb_ocl_versions *v)
{
    cl_string(clGetPlatformInfo(ocl->platform, CL_PLATFORM_VERSION, sizeof v->platform - 1,
                                v->platform, NULL),
              v->platform, sizeof v->platform);
    cl_string(
        clGetDeviceInfo(ocl->device, CL_DEVICE_VERSION, sizeof v->device - 1, v->device, NULL),
        v->device, sizeof v->device);
    cl_string(
        clGetDeviceInfo(ocl->device, CL_DRIVER_VERSION, sizeof v->driver - 1, v->driver, NULL),
        v->driver, sizeof v->driver);
}

void ppb_provenance_write_build(FILE *out, const ppb_ocl_versions *v)
{
    fprintf(out, "ppbench.commit = %s\n", PPB_COMMIT);
#ifdef __clang__
    fprintf(out, "compiler = clang %s\n", __clang_version__);
#elif defined(__GNUC__)
    fprintf(out, "compiler = gcc %s\n", __VERSION__);
#else
    fprintf(out, "compiler = unknown\n");
#endif
    if (v)
        fprintf(out,
                "opencl.platform_version = %s\nopencl.device_version = %s\n"
                "opencl.driver_version = %s\n",
                v->platform, v->device, v->driver);
    const char *blas = openblas_get_config();
    fprintf(out, "lib.openblas = %s\n", blas ? blas : "(unknown)");
    lapack_int maj = 0, min = 0, patch = 0;
    LAPACKE_ilaver(&maj, &min, &patch);
    fprintf(out, "lib.lapack = %d.%d.%d\n", (int)maj, (int)min, (int)patch);
    int emaj = 0, emin = 0, epatch = 0;
    const char *extra = NULL;
    exr_get_library_version(&emaj, &emin, &epatch, &extra);
    fprintf(out, "lib.openexr = %d.%d.%d%s\n", emaj, emin, epatch, extra ? extra : "");
    fprintf(out, "lib.libpng = %s\n", png_get_libpng_ver(NULL));
    fprintf(out, "lib.inih = %s\n", PPB_INIH_VERSION);
    unsigned x = XXH_versionNumber();
    fprintf(out, "lib.xxhash = %u.%u.%u\n", x / 10000, x / 100 % 100, x % 100);
}
