/* totals.c: totals from bin radiance (totals.h). */
#include "physics/totals.h"

#include <math.h>
#include <string.h>

#include "kernels/ppb_fresnel.h"
#include "kernels/ppb_tube.h"
#include "physics/maps.h"

/* At n > 1: the fraction of the entering beam's power that leaves unscattered. From the beam
 * of optical depth tau between S1 and S2, (1 - F_b) e^{-tau} leaves at S2, F_b (1 - F_b)
 * e^{-2 tau} at S1 after one reflection, and so on: (1 - F_b) e^{-tau} / (1 - F_b e^{-tau}).
 * Slab, and the tube at normal incidence (a vertical beam meets only S2 and S1; the column's
 * tau is ppb_beam_depth's). */
static double fresnel_unscattered(const ppb_scene *sc, double x_entry, void *arg)
{
    double fb = *(const double *)arg, e = exp(-ppb_beam_depth(sc, x_entry));
    return (1.0 - fb) * e / (1.0 - fb * e);
}

/* The tube at oblique incidence: the beam from x_e followed through its reflections off all four
 * faces, adding at each face the part that leaves, (1 - F) of what arrives, until what is left
 * is below 1e-16. With a density step a leg's optical depth counts its part at x >= step_x with
 * sigma_t_right: a straight leg's x is monotone, so that part is the overlap of its x range with
 * [step_x, W/2], over |dx|. arg: the ppb_fresnel_beam. */
static double fresnel_walk(const ppb_scene *sc, double x_e, void *arg)
{
    const ppb_fresnel_beam *b = arg;
    double W = sc->width, H = sc->height, fs = ppb_fresnel(b->sin_t, 1.0 / sc->n);
    double x = x_e, y = 0.0, dx = b->sin_t, dy = -b->cos_t, w = 1.0, tau = 0.0, out = 0.0;
    for (int hit = 0; hit < 100000 && w * exp(-tau) > 1e-16; hit++) {
        double l;
        int face = ppb_exit_face(1, W, H, x, y, dx, dy, &l);
        double f = ppb_face_is_side(face) ? fs : b->f_inside;
        double x1 = x + l * dx;
        if (sc->step == PPB_STEP_DENSITY && sc->sigma_t_right != sc->sigma_t) {
            double right = fmax(0.0, fmax(x, x1) - fmax(sc->step_x, fmin(x, x1)));
            tau += sc->sigma_t * l + (sc->sigma_t_right - sc->sigma_t) * right / fabs(dx);
        } else
            tau += sc->sigma_t * l;
        out += w * (1.0 - f) * exp(-tau);
        w *= f;
        ppb_tube_reflect(face, W, H, l, &x, &y, &dx, &dy);
    }
    return out;
}

static double fresnel_ballistic(const ppb_scene *sc, const ppb_fresnel_beam *b)
{
    double fb = b->f_inside, width;
    if (sc->geometry == PPB_GEOM_TUBE && sc->theta_deg != 0.0) {
        /* The walk's mean over the lit part of S1, by midpoints (maps.h). */
        const int np = PPB_LIT_MIDPOINTS;
        double sum = ppb_lit_midpoint_sum(sc, fresnel_walk, (void *)b, np, &width);
        return (1.0 - b->specular) * sum / np;
    }
    if (sc->geometry == PPB_GEOM_SLAB) {
        double e = exp(-sc->sigma_t * sc->height / b->cos_t);
        return (1.0 - b->specular) * (1.0 - fb) * e / (1.0 - fb * e);
    }
    double sum = ppb_lit_integral(sc, fresnel_unscattered, &fb, &width);
    return width > 0.0 ? (1.0 - b->specular) * sum / width : 0.0;
}

void ppb_bin_totals(const ppb_scene *sc, const ppb_layout *lo, const double *radiance,
                    ppb_totals *t)
{
    double flux[PPB_NSURF] = {0};
    for (int s = 0; s < lo->nsurf; s++) {
        /* A cell's energy: its average radiance times segment length x projected solid angle. */
        double measure = ppb_scene_cell_measure(sc, s);
        for (int seg = 0; seg < lo->nseg[s]; seg++)
            for (int b = 0; b < lo->nbins; b++)
                flux[s] += radiance[ppb_cell(lo, s, seg, b)] * measure;
    }
    double entering = ppb_scene_power_in(sc);
    memset(t, 0, sizeof *t);
    if (entering > 0.0) {
        t->R = flux[PPB_S1] / entering;
        t->T = flux[PPB_S2] / entering;
        t->sides = (flux[PPB_S3] + flux[PPB_S4]) / entering;
    }
    t->ballistic = ppb_ballistic_fraction(sc);
    if (sc->n > 1.0) {
        ppb_fresnel_beam b = ppb_fresnel_beam_in(ppb_scene_cos_theta_l(sc), sc->n);
        t->ballistic = fresnel_ballistic(sc, &b);
        t->specular = b.specular;
    }
    t->absorbed_tracked = 0;
    ppb_totals_complete(t);
}
