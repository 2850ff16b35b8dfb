/* image_png.c: RGB PNG files through libpng's simplified API (see image_png.h). */
#include "io/image_png.h"

#include <stdlib.h>
#include <string.h>

#include <png.h>

#include "base/atomic_file.h"

int ppb_png_write_rgb(const char *path, int width, int height, const unsigned char *rgb,
                      ppb_err *err)
{
    if (width <= 0 || height <= 0)
        return ppb_fail(err, "%s: empty image %dx%d", path, width, height);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = (png_uint_32)width;
    img.height = (png_uint_32)height;
    img.format = PNG_FORMAT_RGB;
    /* The simplified API reports failure in img.message instead of printing or longjmp'ing
     * through our frames, which is why it is used here. */
    if (!png_image_write_to_stdio(&img, af.f, 0, rgb, 0, NULL)) {
        png_image_free(&img);
        ppb_afile_abort(&af);
        return ppb_fail(err, "%s: libpng: %s", path, img.message);
    }
    png_image_free(&img);
    return ppb_afile_commit(&af, err);
}

int ppb_png_read_rgb(const char *path, int *width, int *height, unsigned char **rgb, ppb_err *err)
{
    *rgb = NULL;
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path))
        return ppb_fail(err, "%s: libpng: %s", path, img.message);
    img.format = PNG_FORMAT_RGB;
    unsigned char *buf = malloc(PNG_IMAGE_SIZE(img));
    if (!buf) {
        png_image_free(&img);
        return ppb_fail(err, "%s: out of memory", path);
    }
    if (!png_image_finish_read(&img, NULL, buf, 0, NULL)) {
        free(buf);
        png_image_free(&img);
        return ppb_fail(err, "%s: libpng: %s", path, img.message);
    }
    *width = (int)img.width;
    *height = (int)img.height;
    *rgb = buf;
    return 0;
}
