/* maps.c: the light maps and the exact light-path quantities behind them (maps.h). */
#include "physics/maps.h"

#include <math.h>
#include <stdlib.h>

#include "kernels/march_params.h"

#include "base/quadrature.h"
#include "kernels/ppb_fresnel.h"
#include "kernels/ppb_sort.h"
#include "physics/medium.h"

/* Fraction of a straight path whose x runs from x0 to x1 that lies right of the step
 * (x >= step_x); a vertical path is wholly on one side. */
static double right_fraction(double x0, double x1, double step_x)
{
    double lo = fmin(x0, x1), hi = fmax(x0, x1);
    if (hi - lo <= 0.0)
        return lo >= step_x ? 1.0 : 0.0;
    double f = (hi - fmax(lo, step_x)) / (hi - lo);
    return f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
}

double ppb_segment_optical_depth(const ppb_scene *sc, double x0, double y0, double x1, double y1)
{
    double len = hypot(x1 - x0, y1 - y0);
    if (sc->geometry == PPB_GEOM_TUBE && sc->step == PPB_STEP_DENSITY) {
        double f = right_fraction(x0, x1, sc->step_x);
        return len * ((1.0 - f) * sc->sigma_t + f * sc->sigma_t_right);
    }
    return len * sc->sigma_t;
}

/* The beam's direction inside: the light's at n = 1 (the scene's own functions, bit for bit),
 * the refracted one at n > 1 (reference: Light and Keys, `medium.n`: shadowing follows it). */
static double beam_cos(const ppb_scene *sc)
{
    return sc->n > 1.0 ? ppb_refract_cos(ppb_scene_cos_theta_l(sc), sc->n)
                       : ppb_scene_cos_theta_l(sc);
}
static double beam_tan(const ppb_scene *sc)
{
    if (!(sc->n > 1.0))
        return ppb_scene_tan_theta_l(sc);
    double c = beam_cos(sc);
    return sqrt(fmax(0.0, 1.0 - c * c)) / c;
}

void ppb_light_path_exact(const ppb_scene *sc, double x, double y, double *D, double *abar,
                          int *lit)
{
    double depth = y < 0.0 ? -y : 0.0;
    if (sc->geometry == PPB_GEOM_SLAB) {
        *D = sc->sigma_t * depth / beam_cos(sc);
        *abar = sc->albedo;
        *lit = 1;
        return;
    }
    /* The path runs from (x, y) along -w_L to S1 at x' = x + y tan(theta_L). */
    double xp = x - depth * beam_tan(sc);
    *D = ppb_segment_optical_depth(sc, x, -depth, xp, 0.0);
    *abar = sc->albedo;
    if (sc->step == PPB_STEP_ALBEDO) {
        /* Paper Sec. 3.3: the length average of alpha from the entry point to x. */
        double f = right_fraction(x, xp, sc->step_x);
        *abar = (1.0 - f) * sc->albedo + f * sc->albedo_right;
    }
    /* Reference: Light: lit only if the path meets S1 inside its lit part; for theta_L >= 0 a
     * path that would meet S1's plane left of -W/2 leaves through S3 first. */
    ppb_medium M = ppb_medium_of(sc);
    ppb_lit L = ppb_lit_of(sc);
    *lit = ppb_lit_at(&M, &L, xp, 0.0) && xp <= ppb_face_line(PPB_S4, sc->width, sc->height);
}

/* The grid of the maps without its cells (ppb_maps_build, ppb_maps_bytes). */
static void maps_grid(const ppb_scene *sc, int map_res, ppb_maps *m)
{
    m->tube = sc->geometry == PPB_GEOM_TUBE;
    m->tan_theta_l = beam_tan(sc);
    m->h = 1.0 / map_res;
    double ny = ceil(sc->height * map_res - 1e-9);
    m->ny = ny < 1 ? 1 : (int)ny;
    m->i0 = 0;
    if (m->tube) {
        /* Columns start at x' = -W/2 (a shadow edge for oblique light) and reach left far enough
         * for the paths of S3's lower end; step_x = 0 then lies on a column edge too. Of the
         * `left` columns beyond -W/2, all in shadow, only the nearest is stored (maps.h). */
        int left = (int)ceil(sc->height * m->tan_theta_l * map_res - 1e-9);
        m->xp0 = ppb_face_line(PPB_S3, sc->width, sc->height) - left * m->h;
        m->i0 = left > 0 ? left - 1 : 0;
        m->nx = left - m->i0 + (int)ceil(sc->width * map_res - 1e-9);
    } else {
        m->xp0 = -0.5 * m->h;
        m->nx = 1;
    }
}

double ppb_maps_bytes(const ppb_scene *sc, int map_res)
{
    if (map_res < 1)
        return 0.0;
    ppb_maps m;
    maps_grid(sc, map_res, &m);
    return (double)m.nx * m.ny * PPB_MAP_STRIDE * sizeof *m.cells;
}

int ppb_maps_build(const ppb_scene *sc, int map_res, ppb_maps *m, ppb_err *err)
{
    if (map_res < 1)
        return ppb_fail(err, "maps: map_res must be at least 1 (got %d)", map_res);
    maps_grid(sc, map_res, m);
    m->cells = malloc((size_t)m->nx * (size_t)m->ny * PPB_MAP_STRIDE * sizeof *m->cells);
    if (!m->cells)
        return ppb_fail(err, "maps: out of memory for %d x %d cells (%.3g GB)", m->nx, m->ny,
                        ppb_maps_bytes(sc, map_res) / 1e9);
    /* Corners are evaluated a hair inside their cell: the limit from inside, which keeps a jump
     * on the cell edge sharp; 1e-9 cells moves D by ~1e-11, far below any tolerance. */
    double eps = 1e-9 * m->h;
    for (int j = 0; j < m->ny; j++)
        for (int i = 0; i < m->nx; i++) {
            double *c = m->cells + ((size_t)j * m->nx + i) * PPB_MAP_STRIDE;
            for (int corner = 0; corner < 4; corner++) {
                int cx = corner & 1, cy = corner >> 1;
                double xp = m->xp0 + (m->i0 + i + cx) * m->h + (cx ? -eps : eps);
                double depth = (j + cy) * m->h + (cy ? -eps : eps);
                double y = -depth, x = xp - y * m->tan_theta_l;
                double D, abar;
                int lit;
                ppb_light_path_exact(sc, x, y, &D, &abar, &lit);
                c[PPB_MAP_D * 4 + corner] = D;
                c[PPB_MAP_ABAR * 4 + corner] = abar;
                c[PPB_MAP_LIT * 4 + corner] = lit;
            }
        }
    return 0;
}

void ppb_maps_free(ppb_maps *m)
{
    free(m->cells);
    m->cells = NULL;
}

void ppb_maps_lookup(const ppb_maps *m, double x, double y, double *D, double *abar, double *lit)
{
    ppb_map_lookup(m->cells, m->xp0, m->h, m->i0, m->nx, m->ny, m->tan_theta_l, x, y, D, abar, lit);
}

double ppb_maps_depth(const ppb_maps *m, double x, double y)
{
    double D, abar, lit;
    ppb_maps_lookup(m, x, y, &D, &abar, &lit);
    return lit > 0.0 ? D : INFINITY;
}

double ppb_beam_depth(const ppb_scene *sc, double xe)
{
    if (sc->geometry == PPB_GEOM_SLAB)
        return sc->sigma_t * sc->height / ppb_scene_cos_theta_l(sc);
    /* It leaves through S2, or through S4 when oblique light reaches x = W/2 first. */
    double t = ppb_scene_tan_theta_l(sc);
    double xb = xe + sc->height * t, yb = -sc->height;
    if (xb > ppb_face_line(PPB_S4, sc->width, sc->height)) {
        xb = ppb_face_line(PPB_S4, sc->width, sc->height);
        yb = -(xb - xe) / t;
    }
    return ppb_segment_optical_depth(sc, xe, 0.0, xb, yb);
}

double ppb_lit_integral(const ppb_scene *sc, ppb_entry_fn f, void *arg, double *width)
{
    ppb_medium M = ppb_medium_of(sc);
    ppb_lit L = ppb_lit_of(sc);
    double a = ppb_lit_lo(&M, &L), b = ppb_lit_hi(&M, &L);
    if (ppb_scene_lit_line(sc)) { /* a line of unit strength: f at it (ppb_scene_lit_measure) */
        *width = 1.0;
        return f(sc, a, arg);
    }
    *width = b > a ? b - a : 0.0;
    if (b <= a)
        return 0.0;
    /* The integrand is smooth between the entry points where the path's end switches from S2 to
     * S4 or where it starts or ends on the step (it may jump there); Gauss-Legendre panels between
     * those breaks never sample a break and are exact to ~1e-14 for these exponentials. */
    double t = ppb_scene_tan_theta_l(sc), brk[5] = {a, b, 0, 0, 0};
    int nb = 2;
    double cand[3] = {ppb_face_line(PPB_S4, sc->width, sc->height) - sc->height * t, sc->step_x,
                      sc->step_x - sc->height * t};
    for (int k = 0; k < 3; k++)
        if (cand[k] > a && cand[k] < b)
            brk[nb++] = cand[k];
    ppb_sort_doubles(brk, nb);
    double gx[5], gw[5]; /* 5-point Gauss-Legendre, summed in ascending x */
    ppb_gauss_legendre(5, gx, gw);
    const int panels = 64;
    double sum = 0.0;
    for (int p = 0; p + 1 < nb; p++) {
        double hstep = (brk[p + 1] - brk[p]) / panels;
        for (int k = 0; hstep > 0.0 && k < panels; k++) {
            double mid = brk[p] + (k + 0.5) * hstep;
            for (int q = 4; q >= 0; q--)
                sum += 0.5 * hstep * gw[q] * f(sc, mid + 0.5 * hstep * gx[q], arg);
        }
    }
    return sum;
}

double ppb_lit_midpoint_sum(const ppb_scene *sc, ppb_entry_fn f, void *arg, int np, double *width)
{
    ppb_medium M = ppb_medium_of(sc);
    ppb_lit L = ppb_lit_of(sc);
    double a = ppb_lit_lo(&M, &L), hi = ppb_lit_hi(&M, &L);
    int line = ppb_scene_lit_line(sc); /* np points all on the line, of measure 1 */
    *width = line ? 1.0 : (hi > a ? hi - a : 0.0);
    if (!(hi > a) && !line)
        return 0.0;
    double sum = 0.0;
    for (int i = 0; i < np; i++)
        sum += f(sc, a + (i + 0.5) * (hi - a) / np, arg);
    return sum;
}

static double unscattered(const ppb_scene *sc, double x_entry, void *arg)
{
    (void)arg;
    return exp(-ppb_beam_depth(sc, x_entry));
}

double ppb_ballistic_fraction(const ppb_scene *sc)
{
    if (sc->geometry == PPB_GEOM_SLAB)
        return exp(-ppb_beam_depth(sc, 0.0)); /* Beer-Lambert: exp(-tau0 / mu0) */
    double width, sum = ppb_lit_integral(sc, unscattered, NULL, &width);
    return width > 0.0 ? sum / width : 0.0;
}
