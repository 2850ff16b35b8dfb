#include "methods/registry.h"

#include <stdio.h>
#include <string.h>

#include "methods/bdipole/method_bdipole.h"
#include "methods/burley/method_burley.h"
#include "methods/dirpole/method_dirpole.h"
#include "methods/external/method_external.h"
#include "methods/mc/method_mc.h"
#include "methods/mc/perf_mc.h"
#include "methods/mp/method_mp.h"
#include "methods/pbd/method_pbd.h"
#include "methods/pp/method_pp.h"
#include "methods/pp/method_ss.h"
#include "methods/pp/perf_march.h"
#include "methods/ppslab/method_ppslab.h"
#include "methods/rte2d/method_rte2d.h"
#include "methods/rte2d/perf_rte2d.h"
#include "physics/ppsolver.h"

static const ppb_method *builtin(const char *id);

/* mp+ss and any other sum of methods (method.h: ppb_method_sum): parts found among the
 * built-in methods. */
static int run_sum(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* ppslab reads [pp] (the slab solver's section, named here where every method may be named):
 * its collars against its directions, before any work. */
static int ppslab_check(const ppb_config *cfg, ppb_err *err)
{
    return pp_collars_check(cfg, "pp", err);
}

/* The registry: the order here is the order of outputs; adding a method is one line here
 * (docs/reference.md: Methods, "Adding a method"). */
static const ppb_method methods[] = {
    {.id = "mc",
     .also = "mc1",
     .reference = 1,
     .summary = "photon Monte Carlo reference (mc1: its once-scattered part)",
     .run = ppb_method_mc,
     .section = "mc",
     .work = ppb_mc_work,
     .perf_title = "Monte Carlo (OpenCL)",
     .perf = ppb_perf_mc,
     .run_channels = ppb_mc_run_channels},
    {.id = "pp",
     .summary = "plane-parallel ray marching, the paper's method",
     .run = ppb_method_pp,
     .check = ppb_pp_check,
     .section = "pp",
     .paper_column = "proposed",
     .work = ppb_pp_work,
     .perf_title = "ray marcher (OpenCL)",
     .perf = ppb_perf_march},
    {.id = "ss",
     .summary = "single scattering by ray marching",
     .run = ppb_method_ss,
     .check = ppb_ss_check,
     .paper_column = "S",
     .work = ppb_ss_work},
    {.id = "mp",
     .summary = "multipole diffusion",
     .run = ppb_method_mp,
     .check = ppb_mp_check,
     .section = "mp",
     .paper_column = "MP"},
    {.id = "mp+ss",
     .summary = "multipole diffusion plus single scattering",
     .run = run_sum,
     .sum_of = (const char *const[]){"mp", "ss", NULL},
     .paper_column = "MP+S"},
    {.id = "burley",
     .summary = "Christensen-Burley normalized diffusion profile, A from the slab solver",
     .run = ppb_method_burley,
     .check = ppb_burley_check,
     .section = "burley"},
    {.id = "burley+ss",
     .summary = "Christensen-Burley profile plus single scattering",
     .run = run_sum,
     .sum_of = (const char *const[]){"burley", "ss", NULL}},
    {.id = "bdipole",
     .summary = "d'Eon's better dipole (Grosjean's D, exact Fresnel moments)",
     .run = ppb_method_bdipole,
     .check = ppb_bdipole_check,
     .section = "bdipole"},
    {.id = "bdipole+ss",
     .summary = "d'Eon's better dipole plus single scattering",
     .run = run_sum,
     .sum_of = (const char *const[]){"bdipole", "ss", NULL}},
    {.id = "pbd",
     .summary = "photon beam diffusion (pbrt-v4's tabulated profile, single scattering included)",
     .run = ppb_method_pbd,
     .check = ppb_pbd_check,
     .section = "pbd"},
    {.id = "dirpole",
     .summary = "directional dipole (Frisvad, Hachisuka & Kjeldsen 2014)",
     .run = ppb_method_dirpole,
     .check = ppb_dirpole_check,
     .section = "dirpole"},
    {.id = "dirpole+ss",
     .summary = "directional dipole plus single scattering",
     .run = run_sum,
     .sum_of = (const char *const[]){"dirpole", "ss", NULL}},
    {.id = "ppslab",
     .slab_only = 1,
     .reference = 2,
     .summary = "plane-parallel solution at the slab faces (slab mode only)",
     .run = ppb_method_ppslab,
     .check = ppslab_check},
    {.id = "rte2d",
     .reference = 2, /* noise-free in the tube: summary_rte2d.csv */
     .summary = "the tube's transfer solved: the paper's refinement iterated",
     .run = ppb_method_rte2d,
     .check = ppb_rte2d_check,
     .section = "rte2d",
     .draw = ppb_rte2d_draw,
     .perf_title = "rte2d: the refinement iterated (OpenCL marches)",
     .perf = ppb_perf_rte2d},
};

static const ppb_method *find_builtin(const ppb_config *cfg, const char *id)
{
    (void)cfg;
    return builtin(id);
}

static int run_sum(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return ppb_method_sum(ctx, out, find_builtin, err);
}

/* Every method a config defines ([method.NAME], model/config.h) is run by
 * methods/method_external.c, which reads its command from the experiment's config: one
 * descriptor serves them all, found through the config's own list (ppb_method_find), so no
 * table of them outlives the config or is shared between configs. */
static const ppb_method external_method = {
    .id = NULL,
    .summary = "external method (the config's [method.NAME] command)",
    .run = ppb_method_external};

int ppb_method_count(void)
{
    return (int)(sizeof methods / sizeof methods[0]);
}

const ppb_method *ppb_method_at(int i)
{
    return (i >= 0 && i < ppb_method_count()) ? &methods[i] : NULL;
}

const ppb_method *ppb_method_reference(void)
{
    for (int i = 0; i < ppb_method_count(); i++)
        if (methods[i].reference == 1)
            return &methods[i];
    return NULL;
}

static const ppb_method *builtin(const char *id)
{
    for (int i = 0; i < ppb_method_count(); i++)
        if (strcmp(methods[i].id, id) == 0)
            return &methods[i];
    return NULL;
}

const ppb_method *ppb_method_find(const ppb_config *cfg, const char *id)
{
    const ppb_method *m = builtin(id);
    if (!m && cfg && ppb_config_external(cfg, id))
        m = &external_method;
    return m;
}

/* The id closest to a mistyped one (model/config.h's ppb_name_distance): a built-in id, its
 * companion (mc1) or a [method.NAME] of the config; NULL when none is close. */
static const char *nearest_id(const ppb_config *cfg, const char *typed)
{
    const char *best = NULL;
    int bestd = 99;
    for (int j = 0; j < ppb_method_count(); j++)
        for (int k = 0; k < 2; k++) {
            const char *id = k ? methods[j].also : methods[j].id;
            int d = id ? ppb_name_distance(typed, id) : -1;
            if (d >= 0 && d < bestd) {
                best = id;
                bestd = d;
            }
        }
    for (int i = 0; i < cfg->nexternal; i++) {
        int d = ppb_name_distance(typed, cfg->external[i].name);
        if (d >= 0 && d < bestd) {
            best = cfg->external[i].name;
            bestd = d;
        }
    }
    return best;
}

int ppb_methods_check(const ppb_config *cfg, ppb_err *err)
{
    /* A [method.NAME] may not take a built-in id: the config would then mean two methods. */
    int nbuiltin = ppb_method_count();
    char where[1200];
    for (int i = 0; i < cfg->nexternal; i++)
        for (int j = 0; j < nbuiltin; j++)
            if (strcmp(cfg->external[i].name, methods[j].id) == 0 ||
                (methods[j].also && strcmp(cfg->external[i].name, methods[j].also) == 0))
                return ppb_fail(
                    err, "%s: '%s' is a built-in method's id",
                    ppb_config_external_where(cfg, &cfg->external[i], NULL, where, sizeof where),
                    cfg->external[i].name);
    for (int i = 0; i < cfg->nexternal; i++)
        if (ppb_external_check(cfg, &cfg->external[i], err))
            return -1;
    /* Unknown ids first, over the whole list, then slab-only methods: the order in which the
     * config used to refuse them when it parsed the list itself. */
    for (int i = 0; i < cfg->nmethods; i++)
        if (!builtin(cfg->methods[i]) && !ppb_config_external(cfg, cfg->methods[i])) {
            const char *near = nearest_id(cfg, cfg->methods[i]);
            return ppb_config_key_fail(
                cfg, "experiment", "methods", err, "unknown method '%s' (%s%s%ssee ppbench --help)",
                cfg->methods[i], near ? "did you mean " : "", near ? near : "", near ? "? " : "");
        }
    int slab = cfg->scene.geometry == PPB_GEOM_SLAB;
    for (int i = 0; i < cfg->nmethods; i++) {
        const ppb_method *m = ppb_method_find(cfg, cfg->methods[i]);
        if (m->slab_only && !slab)
            return ppb_config_key_fail(cfg, "experiment", "methods", err,
                                       "method '%s' runs in slab mode only", cfg->methods[i]);
        /* A point where the method's model has no meaning is refused here, before any work; a
         * sum has a meaning where each of its parts has. */
        if (m->check && m->check(cfg, err))
            return -1;
        for (int k = 0; m->sum_of && m->sum_of[k]; k++) {
            const ppb_method *p = builtin(m->sum_of[k]);
            if (p && p->check && p->check(cfg, err))
                return -1;
        }
    }
    return 0;
}
