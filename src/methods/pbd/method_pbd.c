/* method_pbd.c: the `pbd` method (reference: Methods, `pbd`): photon beam diffusion's tabulated
 * profile Sr(r) (Habel, Christensen & Jarosz 2013, as pbrt-v4's TabulatedBSSRDF and
 * ComputeBeamDiffusionBSSRDF in bssrdf.h / bssrdf.cpp ship it; pbd_table.h, pbd_profile.h)
 * applied to the tube as a renderer applies a BSSRDF.
 *
 * - Table: pbrt's 100 albedos x 64 optical radii at sigma_t = 1 for the scene's g and n, built
 *   once per run for each (g, n) and kept in the run's state (a sweep's points share it).
 * - Profile per stretch of the lit strip with one medium: Sr(r) = sigma_t^2 table(albedo, r
 *   sigma_t) (the single-scattering albedo, not the reduced one: pbrt's rho = sigma_s / sigma_t).
 * - Tube: the flux at an exit point per unit entering irradiance is int Sr(|x_o - x_i|) dA_i over
 *   the lit entry points (3-D distance), by Gauss-Legendre panels in z and in x
 *   (ppb_pbd_strip). Slab: the plane integrals at 0 and H.
 * - Entry, segments, exit lobe and totals: physics/bssrdf_tube.h. pbrt's exit term Sw = (1 -
 *   F(cos theta_o)) / (c pi) is a lobe normalised to the flux; the shared lobe is the same with
 *   the exact normalisation instead of pbrt's moment fit c = 1 - 2 FresnelMoment1(1 / eta). */
#include "methods/pbd/method_pbd.h"

#include <math.h>
#include <stdlib.h>

#include "methods/pbd/pbd_profile.h"
#include "methods/pbd/pbd_table.h"
#include "methods/result_check.h"
#include "physics/bssrdf_tube.h"
#include "physics/medium.h"

#define STATE_KEY  "pbd"
#define MAX_TABLES 4

/* The tables built in this run, one per (g, n), the oldest replaced when all are taken. */
typedef struct pbd_tables {
    ppb_pbd_table *t[MAX_TABLES];
    int n, next;
} pbd_tables;

static void tables_release(void *data)
{
    pbd_tables *s = data;
    for (int i = 0; i < s->n; i++)
        free(s->t[i]);
    free(s);
}

static const ppb_pbd_table *table_for(ppb_run_ctx *ctx, double g, double eta, ppb_err *err)
{
    pbd_tables *s = ppb_ctx_state(ctx, STATE_KEY);
    if (!s) {
        s = calloc(1, sizeof *s);
        if (!s || ppb_ctx_keep(ctx, STATE_KEY, s, tables_release, err)) {
            if (!s)
                ppb_fail(err, "pbd: out of memory");
            return NULL;
        }
    }
    for (int i = 0; i < s->n; i++)
        if (s->t[i]->g == g && s->t[i]->eta == eta)
            return s->t[i];
    ppb_pbd_table *t = malloc(sizeof *t);
    if (!t) {
        ppb_fail(err, "pbd: out of memory");
        return NULL;
    }
    ppb_pbd_table_build(t, g, eta, PPB_PBD_SAMPLES);
    int slot;
    if (s->n < MAX_TABLES) {
        slot = s->n++;
    } else {
        slot = s->next;
        free(s->t[slot]);
        s->next = (slot + 1) % MAX_TABLES;
    }
    s->t[slot] = t;
    return t;
}

typedef struct pbd_model {
    ppb_pbd_profile profile[2]; /* per lit piece (physics/medium.h) */
    int nodes;
} pbd_model;

static double pbd_strip(const void *model, int piece, double xa, double xb, double x, double y,
                        int surf)
{
    (void)surf; /* the profile is radial: only the distance counts */
    const pbd_model *m = model;
    return ppb_pbd_strip(&m->profile[piece], xa - x, xb - x, y, m->nodes);
}

/* A line of entry points along z at x = xa: the table profile's z integral (Gauss-Legendre
 * panels between the table's radii, pbd_profile.h) at the in-plane distance from the line. */
static double pbd_line(const void *model, int piece, double xa, double x, double y, int surf)
{
    (void)surf;
    const pbd_model *m = model;
    return ppb_pbd_line(&m->profile[piece], hypot(x - xa, y), m->nodes);
}

static void pbd_slab(const void *model, double height, double *R, double *T)
{
    const pbd_model *m = model;
    *R = ppb_pbd_plane(&m->profile[0], 0.0);
    *T = ppb_pbd_plane(&m->profile[0], height);
}

int ppb_method_pbd(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    const ppb_scene *sc = &cfg->scene;
    if (ppb_pbd_check(cfg, err))
        return -1;
    const ppb_pbd_table *t = table_for(ctx, sc->g, sc->n, err);
    if (!t)
        return -1;
    pbd_model model = {.nodes = cfg->pbd.nodes};
    if (sc->geometry == PPB_GEOM_SLAB) {
        ppb_pbd_profile_init(&model.profile[0], t, sc->sigma_t, sc->albedo);
    } else {
        ppb_lit_piece lit[2];
        int nlit = ppb_lit_pieces(sc, lit);
        for (int i = 0; i < nlit; i++)
            ppb_pbd_profile_init(&model.profile[i], t, lit[i].sigma_t, lit[i].albedo);
    }
    ppb_bssrdf m = {.model = &model, .strip = pbd_strip, .line = pbd_line, .slab = pbd_slab};
    if (ppb_bssrdf_fill(cfg, &m, ctx->quiet, out, err) ||
        ppb_radiance_check(cfg->name, out, NULL, err))
        return -1;
    return ppb_totals_check_completed(cfg->name, out, err);
}

int ppb_pbd_check(const ppb_config *cfg, ppb_err *err)
{
    return ppb_bssrdf_check(cfg, "pbd", 1, err); /* the line hook above */
}
