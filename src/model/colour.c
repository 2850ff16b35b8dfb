#include "model/colour.h"

#include <string.h>

const double ppb_luma[3] = {0.2126, 0.7152, 0.0722};

int ppb_result_luminance(const ppb_result *const ch[3], ppb_result *out, ppb_err *err)
{
    const ppb_layout *lo = &ch[0]->layout;
    for (int c = 1; c < 3; c++)
        if (ch[c]->layout.ncells != lo->ncells)
            return ppb_fail(err, "%s: the channels' layouts differ", ch[0]->method);
    if (ppb_result_init(out, ch[0]->method, lo, err))
        return -1;
    for (size_t k = 0; k < lo->ncells; k++) {
        double L = 0, se = 0;
        for (int c = 0; c < 3; c++) {
            L += ppb_luma[c] * ch[c]->radiance[k];
            se += ppb_luma[c] * ch[c]->se[k];
        }
        out->radiance[k] = L;
        out->se[k] = se;
    }
    ppb_totals *t = &out->totals;
    t->absorbed_tracked = 1;
    for (int c = 0; c < 3; c++) {
        ppb_totals v = ch[c]->totals, *u = &v;
        ppb_totals_complete(u); /* absorbed as the writer reports it (reference: Bins) */
        double w = ppb_luma[c];
        t->R += w * u->R;
        t->T += w * u->T;
        t->sides += w * u->sides;
        t->absorbed += w * u->absorbed;
        t->ballistic += w * u->ballistic;
        t->specular += w * u->specular;
        t->absorbed_tracked &= u->absorbed_tracked;
        out->partial |= ch[c]->partial;
    }
    out->photons = ch[0]->photons; /* each channel's budget (the same in every channel) */
    return 0;
}
