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
typedef struct walk_arg {
    const ppb_fresnel_beam *b;
    double face[PPB_NSURF]; /* what leaves through each face, summed over the walks */
} walk_arg;

static double fresnel_walk(const ppb_scene *sc, double x_e, void *arg)
{
    walk_arg *a = arg;
    const ppb_fresnel_beam *b = a->b;
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
        double leaves = w * (1.0 - f) * exp(-tau);
        out += leaves;
        a->face[face] += leaves;
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
        walk_arg a = {b, {0}};
        double sum = ppb_lit_midpoint_sum(sc, fresnel_walk, &a, np, &width);
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

/* At n = 1 the beam leaves at the first face it meets: S2, or S4 for oblique light that reaches
 * x = W/2 first (ppb_beam_depth); the unscattered part through face *arg, else 0. */
static double unscattered_on(const ppb_scene *sc, double x_e, void *arg)
{
    int face = *(const int *)arg;
    double xb = x_e + sc->height * ppb_scene_tan_theta_l(sc);
    int out = xb > ppb_face_line(PPB_S4, sc->width, sc->height) ? PPB_S4 : PPB_S2;
    return out == face ? exp(-ppb_beam_depth(sc, x_e)) : 0.0;
}

/* At n > 1, normal incidence (a vertical beam meets S2 and S1 alone), the beam's series of
 * fresnel_unscattered split by face: the terms e^{-(2k+1) tau} leave at S2, e^{-(2k+2) tau} at
 * S1; e = e^{-tau}. */
static double series_on(double fb, double e, int face)
{
    double s2 = (1.0 - fb) * e / (1.0 - fb * fb * e * e);
    return face == PPB_S2 ? s2 : face == PPB_S1 ? s2 * fb * e : 0.0;
}

static double fresnel_unscattered_on(const ppb_scene *sc, double x_entry, void *arg)
{
    const double *fa = arg; /* F_b, face */
    return series_on(fa[0], exp(-ppb_beam_depth(sc, x_entry)), (int)fa[1]);
}

void ppb_ballistic_faces(const ppb_scene *sc, double out[PPB_NSURF])
{
    double width;
    ppb_fresnel_beam b = ppb_fresnel_beam_in(ppb_scene_cos_theta_l(sc), sc->n);
    if (sc->n > 1.0 && sc->geometry == PPB_GEOM_TUBE && sc->theta_deg != 0.0) {
        /* one walk per entry point gives every face its share */
        walk_arg a = {&b, {0}};
        ppb_lit_midpoint_sum(sc, fresnel_walk, &a, PPB_LIT_MIDPOINTS, &width);
        for (int face = 0; face < PPB_NSURF; face++)
            out[face] = (1.0 - b.specular) * a.face[face] / PPB_LIT_MIDPOINTS;
        return;
    }
    for (int face = 0; face < PPB_NSURF; face++) {
        if (sc->n <= 1.0 && sc->geometry == PPB_GEOM_SLAB) {
            out[face] = face == PPB_S2 ? ppb_ballistic_fraction(sc) : 0.0;
        } else if (sc->n <= 1.0) {
            double sum = ppb_lit_integral(sc, unscattered_on, &face, &width);
            out[face] = width > 0.0 ? sum / width : 0.0;
        } else if (sc->geometry == PPB_GEOM_SLAB) {
            double e = exp(-sc->sigma_t * sc->height / b.cos_t);
            out[face] = (1.0 - b.specular) * series_on(b.f_inside, e, face);
        } else {
            double fa[2] = {b.f_inside, face};
            double sum = ppb_lit_integral(sc, fresnel_unscattered_on, fa, &width);
            out[face] = width > 0.0 ? (1.0 - b.specular) * sum / width : 0.0;
        }
    }
}
