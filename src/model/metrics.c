#include "model/metrics.h"

#include <math.h>

ppb_rms ppb_rms_points(const ppb_result *m, const ppb_result *ref, const ppb_point *pts, int n)
{
    return ppb_rms_points_w(m, ref, pts, n, NULL);
}

ppb_rms ppb_rms_points_w(const ppb_result *m, const ppb_result *ref, const ppb_point *pts, int n,
                         const double *w)
{
    const ppb_layout *lo = &ref->layout;
    double num = 0, den = 0, noise = 0;
    for (int p = 0; p < n; p++)
        for (int k = 0; k < lo->nbins; k++) {
            /* Equal bins (reference: Bins): w_k is a common factor of both sums and cancels; 1.0
             * keeps the sums exactly those of the unweighted formula. */
            double wk = w ? w[k] : 1.0;
            size_t c = ppb_cell(lo, pts[p].surf, pts[p].seg, k);
            double d = m->radiance[c] - ref->radiance[c];
            num += wk * d * d;
            den += wk * ref->radiance[c] * ref->radiance[c];
            noise += wk * (ref->se[c] * ref->se[c] + m->se[c] * m->se[c]);
        }
    ppb_rms r = {NAN, NAN, NAN};
    if (den > 0) {
        r.rms_rel = sqrt(num / den);
        r.noise_rel = sqrt(noise / den);
        double ex = r.rms_rel * r.rms_rel - r.noise_rel * r.noise_rel;
        /* NaN stays NaN: a method's surface not computed (docs/reference.md: Metrics) */
        r.rms_excess = isnan(ex) ? NAN : sqrt(ex > 0 ? ex : 0);
    }
    return r;
}

double ppb_noise_points(const ppb_result *r, const ppb_point *pts, int n)
{
    double num = 0, den = 0; /* equal w_k cancel, as in ppb_rms_points */
    for (int p = 0; p < n; p++)
        for (int k = 0; k < r->layout.nbins; k++) {
            size_t c = ppb_cell(&r->layout, pts[p].surf, pts[p].seg, k);
            num += r->se[c] * r->se[c];
            den += r->radiance[c] * r->radiance[c];
        }
    return den > 0 ? sqrt(num / den) : NAN;
}

const char *ppb_cell_name(int cell)
{
    static const char *names[PPB_NCELLS] = {"R_x0", "T_x0", "S1_all", "S2_all", "S3_all", "S4_all"};
    return (cell >= 0 && cell < PPB_NCELLS) ? names[cell] : "?";
}

int ppb_cell_points(const ppb_layout *lo, int cell, ppb_point *pts, int cap)
{
    if (cell == PPB_CELL_R_X0 || cell == PPB_CELL_T_X0) {
        int surf = cell == PPB_CELL_R_X0 ? PPB_S1 : PPB_S2;
        int n = lo->nseg[surf];
        /* The two segments whose centres flank x = 0; the middle one when n is odd. */
        int count = 0;
        if (n % 2 == 0 && n >= 2 && cap >= 2) {
            pts[count++] = (ppb_point){surf, n / 2 - 1};
            pts[count++] = (ppb_point){surf, n / 2};
        } else if (n >= 1 && cap >= 1) {
            pts[count++] = (ppb_point){surf, n / 2};
        }
        return count;
    }
    int surf = cell - PPB_CELL_S1_ALL;
    int n = lo->nseg[surf] < cap ? lo->nseg[surf] : cap;
    for (int i = 0; i < n; i++)
        pts[i] = (ppb_point){surf, i};
    return n;
}

const char *ppb_region_name(int region)
{
    static const char *names[PPB_NREGIONS] = {
        "S1:x<x0-2", "S1:x>x0+2", "S1:|x-x0|<=2", "S1:x<-W/2+3", "S1:x>W/2-3",
        "S2:x<x0-2", "S2:x>x0+2", "S2:|x-x0|<=2", "S2:x<-W/2+3", "S2:x>W/2-3"};
    return (region >= 0 && region < PPB_NREGIONS) ? names[region] : "?";
}

/* Whether a segment centre s lies in a region (of the PPB_REGION_* kinds). The bounds are
 * strict for the one-sided regions and inclusive for the middle one, so that left, right and
 * the step region partition the surface. */
static int in_region(const ppb_scene *sc, int kind, double s)
{
    double x0 = sc->step != PPB_STEP_NONE   ? sc->step_x
                : ppb_scene_searchlight(sc) ? sc->light_x0
                                            : 0.0; /* reference: Metrics, Regions */
    double half = 0.5 * sc->width;
    switch (kind) {
    case PPB_REGION_LEFT:
        return s < x0 - 2;
    case PPB_REGION_RIGHT:
        return s > x0 + 2;
    case PPB_REGION_STEP:
        return fabs(s - x0) <= 2;
    case PPB_REGION_WALL_LEFT:
        return s < -half + 3;
    case PPB_REGION_WALL_RIGHT:
        return s > half - 3;
    default:
        return 0;
    }
}

int ppb_region_points(const ppb_scene *sc, const ppb_layout *lo, int region, ppb_point *pts,
                      int cap)
{
    if (sc->geometry != PPB_GEOM_TUBE || region < 0 || region >= PPB_NREGIONS)
        return 0;
    int surf = region < PPB_NREGIONS_PER_SURF ? PPB_S1 : PPB_S2;
    int kind = region % PPB_NREGIONS_PER_SURF;
    int count = 0;
    for (int seg = 0; seg < lo->nseg[surf] && count < cap; seg++) {
        double x, y;
        if (in_region(sc, kind, ppb_scene_sample_point(sc, surf, seg, &x, &y)))
            pts[count++] = (ppb_point){surf, seg};
    }
    return count;
}
