/* bssrdf_tube.h: a BSSRDF model applied to the tube (or the slab) as a renderer applies it
 * (reference: Methods, "Diffusion profiles in the tube"): the part every profile model shares
 * (`burley`, `bdipole`, `dirpole`, `pbd`), so that each model's slice holds only its profile.
 *
 * - Entry: the irradiance entering S1, E_in = cos(theta_L) (1 - F(theta_L)) (1 - F: n > 1), over
 *   each lit piece [xa, xb] of S1 (physics/medium.h: ppb_lit_pieces, the strip cut where the
 *   medium changes); the model's strip hook gives the flux leaving an exit point per unit
 *   entering irradiance from one piece, integrated over the piece and the whole z axis; a line
 *   searchlight (the piece xa == xb) takes the model's line hook instead: the flux per unit line
 *   strength (reference: Light: a strip of width w under E_perp = 1 / w as w -> 0).
 * - Segments: the flux averaged over a segment on `samples_seg` points spread evenly over it
 *   (the midpoint rule), every surface S1..S4; a segment of S1 that a line crosses is split
 *   there, each part by its own midpoint rule (no point lies on the line, where the profile's
 *   line integral may diverge logarithmically).
 * - Exit: radiance J / pi in every bin at n = 1, J lobe / pi at n > 1 (physics/diffuse_exit.h's
 *   normalised exit lobe): the model's flux is the power that crosses the boundary, and the lobe
 *   only distributes it over the bins.
 * - Totals: R, T, sides from the segments' fluxes; ballistic and specular the scene's exact
 *   ones; absorbed = 1 - the rest (the writer's). Slab mode: the model's plane integrals. */
#ifndef PPB_PHYSICS_BSSRDF_TUBE_H
#define PPB_PHYSICS_BSSRDF_TUBE_H

#include "base/err.h"
#include "model/config.h"
#include "model/result.h"

/* The exit lobe's theta bins the shared code holds at most (bins.theta's own limit). */
#define PPB_BSSRDF_MAX_THETA 64

typedef struct ppb_bssrdf {
    const void *model; /* the model's own parameters, per lit piece */
    /* The flux leaving surface `surf` (PPB_S1..PPB_S4) at the exit point (x, y) of the tube's
     * frame (kernels/ppb_tube.h) per unit irradiance entering S1 over [xa, xb] x all z, where
     * the lit piece `piece` (ppb_lit_pieces' order) has its medium. */
    double (*strip)(const void *model, int piece, double xa, double xb, double x, double y,
                    int surf);
    /* Optional (NULL: a line searchlight is refused): the flux leaving surface `surf` at the exit
     * point (x, y) per unit strength of a line of entry points along z at x = xa on S1 (the
     * limit of strip(xa, xa + w) / w as w -> 0; reference: Light), of piece `piece`'s medium.
     * Called only at points off the line. */
    double (*line)(const void *model, int piece, double xa, double x, double y, int surf);
    /* Slab mode: the reflected and transmitted fractions of the power that enters, for a slab
     * of thickness `height` (the model's profile integrated over the plane at 0 and at
     * height), of the medium of piece 0. */
    void (*slab)(const void *model, double height, double *R, double *T);
} ppb_bssrdf;

/* Fills out (initialised with the scene's layout): radiance and totals as above; reports
 * progress under out->method unless quiet; checks the radiance and totals it wrote
 * (methods' result checks are the caller's). */
int ppb_bssrdf_fill(const ppb_config *cfg, const ppb_bssrdf *m, int quiet, ppb_result *out,
                    ppb_err *err);

/* Refuses settings the shared code cannot honour (more theta bins than the lobe holds; a line
 * searchlight when the model has no line hook: has_line 0), naming the key; id is the
 * method's. */
int ppb_bssrdf_check(const ppb_config *cfg, const char *id, int has_line, ppb_err *err);

#endif
