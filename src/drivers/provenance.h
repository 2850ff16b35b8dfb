/* provenance.h: what provenance.txt records about the build and the machine beyond the run's
 * own settings (docs/reference.md: Outputs): the compiler, the OpenCL platform's, device's and
 * driver's versions, and the versions of the libraries ppbench links (OpenBLAS, LAPACK,
 * OpenEXR, libpng, xxHash), each asked of the library at run time where it says (the version
 * that ran, not the one built against; inih has no such call: the one built against). Owns nothing
 * but these lines. */
#ifndef PPB_PROVENANCE_H
#define PPB_PROVENANCE_H

#include <stdio.h>

#include "runtime/ocl.h"

/* The versions of an open OpenCL device, as its runtime reports them. */
typedef struct ppb_ocl_versions {
    char platform[256]; /* CL_PLATFORM_VERSION, e.g. "OpenCL 3.0 PoCL 5.0 ..." */
    char device[256];   /* CL_DEVICE_VERSION */
    char driver[256];   /* CL_DRIVER_VERSION */
} ppb_ocl_versions;

void ppb_ocl_versions_get(const ppb_ocl *ocl, ppb_ocl_versions *v);

/* "key = value" lines: ppbench.commit, compiler, opencl.* (when v is not NULL) and lib.*
 * (docs/reference.md). */
void ppb_provenance_write_build(FILE *out, const ppb_ocl_versions *v);

#endif
