/* external_partial.c: methods that answer only some surfaces (docs/external.md, "Partial
 * coverage"; method_external.h). A surface not computed is NaN in the result, so every metric
 * over it is NaN (docs/reference.md, Metrics: "not computed") and the radiance writer leaves its
 * rows out: never zero. */
#include "methods/external/method_external.h"

#include <math.h>

unsigned ppb_external_answered(const ppb_layout *lo, const long *seen, unsigned surfaces)
{
    unsigned all = (1u << lo->nsurf) - 1;
    if (surfaces == 0)
        return all;
    if (surfaces != PPB_SURFACES_FROM_ROWS)
        return surfaces & all;
    unsigned got = 0;
    for (int surf = 0; surf < lo->nsurf; surf++)
        for (int seg = 0; seg < lo->nseg[surf] && !(got & (1u << surf)); seg++)
            for (int bin = 0; bin < lo->nbins; bin++)
                if (seen[ppb_cell(lo, surf, seg, bin)]) {
                    got |= 1u << surf;
                    break;
                }
    return got;
}

void ppb_external_not_computed(ppb_result *r, unsigned answered)
{
    const ppb_layout *lo = &r->layout;
    for (int surf = 0; surf < lo->nsurf; surf++)
        if (!(answered & (1u << surf)))
            for (int seg = 0; seg < lo->nseg[surf]; seg++)
                for (int bin = 0; bin < lo->nbins; bin++) {
                    size_t c = ppb_cell(lo, surf, seg, bin);
                    r->radiance[c] = r->se[c] = NAN;
                }
}

int ppb_external_is_partial(const ppb_layout *lo, unsigned surfaces)
{
    unsigned all = (1u << lo->nsurf) - 1;
    return surfaces != 0 && (surfaces & all) != all;
}
