/* images.h: shaded images of the tube (paper Fig. 6-7) from every method's radiance, written
 * as OpenEXR (linear) and PNG (tone-mapped, one exposure per view shared by all methods, the
 * light arrow on the top view), plus a false-colour map of each method's error against the
 * Monte Carlo with its own labelled colour bar (scripts/plots.sh adds the titles and figures).
 * Takes results, not an experiment, so the drivers above it (the experiment writer) call down into
 * it and never the other way. */
#ifndef PPB_IMAGES_H
#define PPB_IMAGES_H

#include "base/err.h"
#include "model/result.h"
#include "model/scene.h"

/* What the run was, written into every EXR's header (reference: Outputs) with the
 * method and what the image shows. NULL strings are written as "unknown". */
typedef struct ppb_image_meta {
    const char *case_name; /* experiment.name */
    const char *version;   /* ppbench's version (provenance.txt's ppbench.version) */
    long long seed;        /* mc.seed */
    long long photons;     /* mc.photons, the Monte Carlo's budget */
} ppb_image_meta;

/* Writes the images of n results of one scene under <out_dir>/images/; nothing in slab mode.
 * res[ref] is the reference (exposure and error images); ref < 0: none, the exposure follows
 * res[0] and no error images are written. meta may be NULL (every attribute "unknown"). */
int ppb_images_write(const char *out_dir, const ppb_scene *sc, const ppb_image_meta *meta,
                     const ppb_result *res, int n, int ref, ppb_err *err);

/* A colour run's pictures (docs/reference.md: Colour) under <out_dir>/images/: for each of the
 * n results, res[0][i], res[1][i], res[2][i] its R, G and B channels (one id, one scene but
 * for the medium: sc is any channel's), <id>.exr with R, G, B the channels' radiance (linear
 * Rec. 709 primaries; header: material, primaries, unit (the config's length unit), exposure) and
 * <id>.png, sRGB: each channel times the exposure 1 / L_white (L_white per view: the 99th
 * percentile of the reference's luminance, ref < 0: of res[*][0]), the shoulder of the grey
 * pictures applied to the luminance (every channel scaled alike, so the hue stays), clipped to 1
 * per channel, then the sRGB OETF. The per-channel error maps are the channel subsets'
 * (images_write). */
int ppb_images_write_colour(const char *out_dir, const ppb_scene *sc, const ppb_image_meta *meta,
                            const char *material, const char *unit, const ppb_result *const res[3],
                            int n, int ref, ppb_err *err);

#endif
