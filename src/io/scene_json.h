/* scene_json.h: the experiment as scene.json, what an external method reads (docs/external.md;
 * docs/external.md): geometry, medium, light, every sample point (surface, segment, s, position,
 * normal, tangent, segment extent) and every bin (index, theta/phi edges, projected solid angle
 * w_k, the directions a deterministic method averages over), with the units and conventions in
 * words. Every number comes from the conventions' own functions (kernels/ppb_conventions.h,
 * model/scene.h), never re-derived here.
 *
 * Written with jansson (Debian's libjansson-dev): reals printed with 17 significant digits so a
 * reader gets the same doubles back. */
#ifndef PPB_SCENE_JSON_H
#define PPB_SCENE_JSON_H

#include "base/err.h"
#include "model/config.h"

#define PPB_SCENE_JSON_VERSION 1

/* Writes scene.json for cfg to path, atomically (nothing under path on failure). */
int ppb_scene_json_write(const ppb_config *cfg, const char *path, ppb_err *err);

#endif
