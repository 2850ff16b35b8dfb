/* image_exr.c: RGB float images through the OpenEXR 3.1 C API (see image_exr.h). */
#include "io/image_exr.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <OpenEXR/openexr.h>

#include "base/atomic_file.h"

enum { RGB = 3 };

/* OpenEXRCore prints every error to stderr unless given a handler; library code must not
 * print (err.h), so the handler is silent and the result code becomes the message. */
static void quiet_handler(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    (void)code;
    (void)msg;
}

static int exr_fail(ppb_err *err, const char *path, const char *what, exr_result_t rv)
{
    return ppb_fail(err, "%s: OpenEXR: %s: %s (%s)", path, what, exr_get_error_code_as_string(rv),
                    exr_get_default_error_message(rv));
}

/* Offset of a channel inside an interleaved RGB pixel, -1 for channels this module ignores. */
static int channel_slot(const char *name)
{
    if (strcmp(name, "R") == 0)
        return 0;
    if (strcmp(name, "G") == 0)
        return 1;
    if (strcmp(name, "B") == 0)
        return 2;
    return -1;
}

static exr_context_initializer_t quiet_init(void)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = quiet_handler;
    return init;
}

static exr_result_t define_part(exr_context_t ctxt, int width, int height,
                                const ppb_exr_attr *attrs, int nattrs)
{
    int part = 0;
    exr_result_t rv = exr_add_part(ctxt, "rgb", EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctxt, part, width, height, EXR_COMPRESSION_ZIP);
    const char *names[RGB] = {"R", "G", "B"};
    for (int c = 0; c < RGB && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(ctxt, part, names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1,
                             1);
    for (int a = 0; a < nattrs && rv == EXR_ERR_SUCCESS; a++)
        rv = exr_attr_set_string(ctxt, part, attrs[a].name, attrs[a].value);
    return rv;
}

/* The channel layout both pipelines share: every channel read or written as 32-bit floats
 * in interleaved RGB rows of `width` pixels. Returns the byte offset of the channel's slot in
 * a pixel, -1 for channels other than R, G, B (skipped: a NULL pointer). */
static long set_layout(exr_coding_channel_info_t *ch, int width)
{
    int slot = channel_slot(ch->channel_name);
    ch->user_data_type = EXR_PIXEL_FLOAT;
    ch->user_bytes_per_element = (int16_t)sizeof(float);
    ch->user_pixel_stride = (int32_t)(RGB * sizeof(float));
    ch->user_line_stride = (int32_t)((size_t)width * RGB * sizeof(float));
    return slot < 0 ? -1 : (long)(slot * sizeof(float));
}

/* Points every channel of the pipeline at its slot of the chunk's first row. */
static void point_encode(exr_coding_channel_info_t *ch, int nch, const uint8_t *row, int width)
{
    for (int c = 0; c < nch; c++) {
        long off = set_layout(&ch[c], width);
        ch[c].encode_from_ptr = off < 0 ? NULL : row + off;
    }
}

static void point_decode(exr_coding_channel_info_t *ch, int nch, uint8_t *row, int width)
{
    for (int c = 0; c < nch; c++) {
        long off = set_layout(&ch[c], width);
        ch[c].decode_to_ptr = off < 0 ? NULL : row + off;
    }
}

static exr_result_t write_chunks(exr_context_t ctxt, int width, int height, const float *rgb)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines);
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int started = 0;
    for (int y = 0; y < height && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_write_scanline_chunk_info(ctxt, 0, y, &ci);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = started ? exr_encoding_update(ctxt, 0, &ci, &enc)
                     : exr_encoding_initialize(ctxt, 0, &ci, &enc);
        if (rv != EXR_ERR_SUCCESS)
            break;
        const uint8_t *row = (const uint8_t *)(rgb + (size_t)y * (size_t)width * RGB);
        point_encode(enc.channels, enc.channel_count, row, width);
        if (!started)
            rv = exr_encoding_choose_default_routines(ctxt, 0, &enc);
        started = 1;
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(ctxt, 0, &enc);
    }
    if (started)
        exr_encoding_destroy(ctxt, &enc);
    return rv;
}

int ppb_exr_write_rgb(const char *path, int width, int height, const float *rgb,
                      const ppb_exr_attr *attrs, int nattrs, ppb_err *err)
{
    if (width <= 0 || height <= 0)
        return ppb_fail(err, "%s: empty image %dx%d", path, width, height);
    /* OpenEXR opens the file by name: it writes the temporary, committed once complete. */
    ppb_apath ap;
    if (ppb_apath_begin(&ap, path, err))
        return -1;
    exr_context_initializer_t init = quiet_init();
    exr_context_t ctxt = NULL;
    const char *stage = "cannot start writing";
    exr_result_t rv = exr_start_write(&ctxt, ap.tmp, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS) {
        stage = "cannot define the image";
        rv = define_part(ctxt, width, height, attrs, nattrs);
    }
    if (rv == EXR_ERR_SUCCESS) {
        stage = "cannot write the header";
        rv = exr_write_header(ctxt);
    }
    if (rv == EXR_ERR_SUCCESS) {
        stage = "cannot write pixels";
        rv = write_chunks(ctxt, width, height, rgb);
    }
    exr_result_t fin = ctxt ? exr_finish(&ctxt) : EXR_ERR_SUCCESS;
    if (rv == EXR_ERR_SUCCESS && fin != EXR_ERR_SUCCESS) {
        stage = "cannot finish the file";
        rv = fin;
    }
    if (rv != EXR_ERR_SUCCESS) {
        ppb_apath_abort(&ap);
        return exr_fail(err, path, stage, rv);
    }
    return ppb_apath_commit(&ap, err);
}

/* Decoding mirrors write_chunks; channels other than R, G, B are skipped (NULL pointer). */
static exr_result_t read_chunks(exr_context_t ctxt, int y0, int width, int height, float *rgb)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines);
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    int started = 0;
    for (int y = 0; y < height && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_read_scanline_chunk_info(ctxt, 0, y0 + y, &ci);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = started ? exr_decoding_update(ctxt, 0, &ci, &dec)
                     : exr_decoding_initialize(ctxt, 0, &ci, &dec);
        if (rv != EXR_ERR_SUCCESS)
            break;
        uint8_t *row = (uint8_t *)(rgb + (size_t)y * (size_t)width * RGB);
        point_decode(dec.channels, dec.channel_count, row, width);
        if (!started)
            rv = exr_decoding_choose_default_routines(ctxt, 0, &dec);
        started = 1;
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_decoding_run(ctxt, 0, &dec);
    }
    if (started)
        exr_decoding_destroy(ctxt, &dec);
    return rv;
}

int ppb_exr_read_rgb(const char *path, int *width, int *height, float **rgb, ppb_err *err)
{
    *rgb = NULL;
    exr_context_initializer_t init = quiet_init();
    exr_context_t ctxt = NULL;
    exr_result_t rv = exr_start_read(&ctxt, path, &init);
    if (rv != EXR_ERR_SUCCESS)
        return exr_fail(err, path, "cannot read", rv);
    exr_attr_box2i_t box;
    rv = exr_get_data_window(ctxt, 0, &box);
    int w = box.max.x - box.min.x + 1, h = box.max.y - box.min.y + 1;
    float *buf = NULL;
    if (rv == EXR_ERR_SUCCESS) {
        buf = calloc((size_t)w * (size_t)h * RGB, sizeof *buf);
        rv = buf ? read_chunks(ctxt, box.min.y, w, h, buf) : EXR_ERR_OUT_OF_MEMORY;
    }
    exr_finish(&ctxt);
    if (rv != EXR_ERR_SUCCESS) {
        free(buf);
        return exr_fail(err, path, "cannot decode", rv);
    }
    *width = w;
    *height = h;
    *rgb = buf;
    return 0;
}
