/* image_png.h: 8-bit sRGB RGB images as PNG files through libpng's simplified API
 * (png_image_write_to_stdio / png_image_finish_read). Owns nothing but the file I/O: tone
 * mapping and colour maps belong to the callers (images.c).
 *
 * Pixels are interleaved RGB bytes, row 0 at the top. Writing is atomic (atomic_file.h): a
 * failure leaves no file at path and no temporary beside it. */
#ifndef PPB_IMAGE_PNG_H
#define PPB_IMAGE_PNG_H

#include "base/err.h"

int ppb_png_write_rgb(const char *path, int width, int height, const unsigned char *rgb,
                      ppb_err *err);

/* Reads any PNG as 8-bit RGB into a malloc'ed array the caller frees (tests, tools). */
int ppb_png_read_rgb(const char *path, int *width, int *height, unsigned char **rgb, ppb_err *err);

#endif
