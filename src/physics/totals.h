/* totals.h: R, T, sides and the ballistic fraction from bin-averaged exit radiance, for the
 * deterministic methods that march every (segment, bin) cell (`pp`, `ss`, `rte2d`; reference:
 * Bins, Metrics). */
#ifndef PPB_PHYSICS_TOTALS_H
#define PPB_PHYSICS_TOTALS_H

#include "model/result.h"
#include "model/scene.h"

/* R, T, sides: radiance x bin projected solid angle x segment length summed per surface,
 * over the power entering the lit part of S1 (lit width x cos theta_L); ballistic exact (at
 * n > 1 the refracted beam's, followed through its Fresnel reflections). */
void ppb_bin_totals(const ppb_scene *sc, const ppb_layout *lo, const double *radiance,
                    ppb_totals *t);

/* The same ballistic fraction split by the face it leaves through (S1 .. S4, PPB_S*): their
 * sum is ppb_bin_totals' ballistic. What delta-M's scaled beam carries beyond the exact one
 * leaves through these faces as scattered light (method_rte2d.c). */
void ppb_ballistic_faces(const ppb_scene *sc, double out[PPB_NSURF]);

#endif
