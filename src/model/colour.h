/* colour.h: the colour conventions of a colour run (`[medium] channel = rgb`, docs/reference.md:
 * Colour). A material's R, G and B channels are taken as linear Rec. 709 / sRGB primaries (the
 * tables give no spectra; pbrt-v4 and Mitsuba read them the same way), and the luminance is
 * Y = 0.2126 R + 0.7152 G + 0.0722 B (ITU-R BT.709's weights, linear). Owns the weights and the
 * luminance of three channel results, cell by cell, which the metrics and writers then take as
 * any result. */
#ifndef PPB_COLOUR_H
#define PPB_COLOUR_H

#include "model/result.h"

/* BT.709 luminance weights of R, G, B (they sum to 1: Y of a grey R = G = B is that grey). */
extern const double ppb_luma[3];

/* out = sum_c ppb_luma[c] ch[c], every cell and total (a weighted sum of power fractions, so
 * R + T + sides + absorbed = 1 holds for Y when it holds for every channel). Standard errors:
 * sum_c ppb_luma[c] se_c, the bound for fully correlated channels (a colour run traces every
 * channel with the same seed, so their estimates share random numbers and are not
 * independent; for independent ones it is at most sqrt(3) times too large). The three results
 * share a layout; out is initialised here under ch[0]'s id (the caller frees it). */
int ppb_result_luminance(const ppb_result *const ch[3], ppb_result *out, ppb_err *err);

#endif
