/* medium.h: the host's one packer of the medium block every kernel receives
 * (kernels/ppb_medium.h; reference: Medium, Geometry).
 *
 * ppb_medium_of fills it from the scene: the cross-section, both sides of the step, n and g; the
 * step's kind is PPB_STEP_NONE in slab mode (a slab config with a step is refused, reference:
 * Medium). march.c, rte2d_grid.c and method_mc.c embed its result in their launch parameters,
 * and the host's own walks through the tube (ppb_tube.h) read it. */
#ifndef PPB_PHYSICS_MEDIUM_H
#define PPB_PHYSICS_MEDIUM_H

#include "kernels/ppb_light.h"
#include "model/scene.h"

ppb_medium ppb_medium_of(const ppb_scene *sc);

/* S1's lit part as the marchers' parameters carry it (kernels/ppb_light.h): the searchlight's
 * strip from ppb_scene_lit_range, strip 0 for the whole face. */
ppb_lit ppb_lit_of(const ppb_scene *sc);

/* A piece of S1's lit strip over which the medium is one (reference: Light, Medium): [xa, xb],
 * and sigma_t and albedo at its entry points. */
typedef struct ppb_lit_piece {
    double xa, xb, sigma_t, albedo;
} ppb_lit_piece;

/* S1's lit strip (ppb_scene_lit_range: the tube's top, ended at a shadow step, or a
 * searchlight's strip), cut where a density or albedo step inside it changes the medium: at most
 * two pieces, the empty ones left out; returns how many. A line searchlight is one piece with
 * xa == xb. The diffusion models integrate their profiles over it (mp, burley). */
int ppb_lit_pieces(const ppb_scene *sc, ppb_lit_piece piece[2]);

#endif
