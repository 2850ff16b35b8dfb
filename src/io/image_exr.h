/* image_exr.h: linear float RGB images as scanline OpenEXR files, through the OpenEXR 3.1 C API
 * (OpenEXRCore: exr_start_write, exr_add_channel, the encode/decode pipelines). Owns nothing
 * else: the file format itself is the library's business, never coded here.
 *
 * Pixels are interleaved RGB floats, row 0 at the top (EXR's INCREASING_Y), 32-bit FLOAT
 * channels "R", "G", "B", ZIP compression (lossless, so a read-back reproduces the values bit for
 * bit). Writing is atomic: the file is written under a temporary name beside the target and
 * renamed into place; on any failure the temporary is removed and nothing appears at path.
 *
 * A file may carry string attributes in its header (as pbrt-v4 writes its settings into its
 * EXRs): ppbench's images name the method, case, seed, photons, version and what they show
 * (images.c; reference: Outputs). */
#ifndef PPB_IMAGE_EXR_H
#define PPB_IMAGE_EXR_H

#include "base/err.h"

/* A string attribute of the header: name (at most 31 bytes, EXR's short names) and value. */
typedef struct ppb_exr_attr {
    const char *name, *value;
} ppb_exr_attr;

/* Writes the image with nattrs string attributes (attrs may be NULL when nattrs is 0). */
int ppb_exr_write_rgb(const char *path, int width, int height, const float *rgb,
                      const ppb_exr_attr *attrs, int nattrs, ppb_err *err);

/* Reads an RGB EXR written by any tool (missing channels read as 0) into a malloc'ed
 * interleaved array the caller frees. Used by the tests and by tools that check outputs. */
int ppb_exr_read_rgb(const char *path, int *width, int *height, float **rgb, ppb_err *err);

#endif
