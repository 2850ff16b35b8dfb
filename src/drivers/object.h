/* object.h: `ppbench object CONFIG --out DIR` (docs/reference.md, Objects): builds the config's
 * three-dimensional object, runs every object method the config names (methods/object_registry.h),
 * scores each against the object Monte Carlo per patch and per pixel, over the whole object and
 * per region (faces, edges, corners, shadowed patches, the inclusion), and writes the output
 * set whole or not at all: radiance.csv, regions.csv, totals_<method>.csv, timings.csv, images
 * (linear EXR and PNG, the error images), the object's voxel file, provenance.txt and config.ini.
 */
#ifndef PPB_DRIVER_OBJECT_H
#define PPB_DRIVER_OBJECT_H

#include "base/err.h"
#include "model/config.h"

/* The object's regions (ppb_object_patch.region, a bit set; docs/reference.md, Objects). */
enum {
    PPB_REGION_FACE = 1,      /* every voxel of the patch has boundary faces of one axis only */
    PPB_REGION_EDGE = 2,      /* some voxel has boundary faces of two axes */
    PPB_REGION_CORNER = 4,    /* some voxel has boundary faces of all three axes */
    PPB_REGION_SHADOW = 8,    /* facing away from the light, or its centre occluded */
    PPB_REGION_INCLUSION = 16 /* the inclusion (material 2) lies beneath the patch's centre */
};

/* Exit codes as main's: 0 done, 1 a run failed, 2 a config or option to fix (nothing done). */
int ppb_object_command(const ppb_config *cfg, const char *device, int quiet, const char *version,
                       ppb_err *err);

#endif
