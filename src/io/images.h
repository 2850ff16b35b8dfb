/* images.h: shaded images of the tube (paper Fig. 6-7) from every method's radiance, written
 * as OpenEXR (linear) and PNG (tone-mapped, one exposure for all methods), plus a false-colour
 * image of each method's error against the Monte Carlo. Called by the experiment writer. */
#ifndef PPB_IMAGES_H
#define PPB_IMAGES_H

#include "base/err.h"

struct ppb_experiment;

/* Writes the images of an experiment under its output directory; nothing in slab mode. */
int ppb_images_write(const struct ppb_experiment *ex, ppb_err *err);

#endif
