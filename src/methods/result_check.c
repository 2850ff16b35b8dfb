/* result_check.c: output checks of the deterministic methods (result_check.h). */
#include "methods/result_check.h"

#include <math.h>
#include <stdio.h>

int ppb_radiance_check(const char *name, ppb_result *r, long *clamped, ppb_err *err)
{
    const ppb_layout *lo = &r->layout;
    long neg = 0;
    double low = 0.0;
    for (int s = 0; s < lo->nsurf; s++)
        for (int seg = 0; seg < lo->nseg[s]; seg++)
            for (int b = 0; b < lo->nbins; b++) {
                double *v = &r->radiance[ppb_cell(lo, s, seg, b)];
                if (!isfinite(*v))
                    return ppb_fail(err,
                                    "%s: non-finite radiance %g at surface S%d, segment %d, bin "
                                    "%d: not written",
                                    r->method, *v, s + 1, seg, b);
                if (*v < 0.0) {
                    neg++;
                    low = fmin(low, *v);
                    *v = 0.0;
                }
            }
    if (neg)
        fprintf(stderr,
                "%s: %s: warning: %ld of %zu cells had negative radiance (down to %.3g); set "
                "to 0\n",
                name, r->method, neg, lo->ncells, low);
    if (clamped)
        *clamped = neg;
    return 0;
}

int ppb_totals_check(const char *name, ppb_result *r, ppb_err *err)
{
    ppb_totals *t = &r->totals;
    double v[5] = {t->R, t->T, t->sides, t->absorbed, t->ballistic}, scale = 0.0;
    for (int i = 0; i < 5; i++)
        if (!isfinite(v[i]))
            return ppb_fail(err,
                            "%s: non-finite totals (R %g, T %g, sides %g, absorbed %g): not "
                            "written",
                            r->method, t->R, t->T, t->sides, t->absorbed);
        else
            scale += fabs(v[i]);
    static const char *const names[] = {"R", "T", "sides", "ballistic"};
    double *own[] = {&t->R, &t->T, &t->sides, &t->ballistic};
    for (int i = 0; i < 4; i++)
        if (*own[i] < 0.0 && -*own[i] <= PPB_TOTAL_ROUNDOFF * scale)
            *own[i] = 0.0;
        else if (*own[i] < 0.0)
            return ppb_fail(err,
                            "%s: %s = %.6g is negative beyond round-off (%g of the totals' sum "
                            "%.6g): not written",
                            r->method, names[i], *own[i], PPB_TOTAL_ROUNDOFF, scale);
    double sum = t->R + t->T + t->sides + t->ballistic;
    if (sum > 1.0 + PPB_ENERGY_TOL)
        fprintf(stderr,
                "%s: %s: warning: R + T + sides + ballistic = %.4g exceeds 1 (the model does not "
                "conserve energy here)\n",
                name, r->method, sum);
    return 0;
}

int ppb_totals_check_completed(const char *name, ppb_result *r, ppb_err *err)
{
    ppb_result probe = *r;
    ppb_totals_complete(&probe.totals);
    int rc = ppb_totals_check(name, &probe, err);
    double absorbed = r->totals.absorbed;
    r->totals = probe.totals;
    r->totals.absorbed = absorbed;
    return rc;
}
