/* method.h: the one interface every method implements: what a method receives (ppb_run_ctx,
 * with the OpenCL device opened on first use) and what describes it (ppb_method). The table of
 * methods and the lookup by id are the registry's (methods/registry.h).
 *
 * A method, given the experiment (scene and settings), fills radiance per (surface, segment,
 * bin) and its totals. A method may also produce a second result in the same run (mc writes
 * its once-scattered part as mc1). The runner, metrics and writers never special-case one. */
#ifndef PPB_METHOD_H
#define PPB_METHOD_H

#include "io/plots.h"
#include "model/config.h"
#include "runtime/ocl.h"
#include "model/result.h"

#include <stdio.h>

/* State a method keeps for the rest of the run (the marcher's tables, which a sweep's points
 * share), under a key of its own; the context releases it when it closes. */
typedef struct ppb_method_state {
    char key[32];
    void *data;
    void (*release)(void *data);
} ppb_method_state;

#define PPB_MAX_STATES 8

struct ppb_method;

/* What a method gets: the experiment, an OpenCL device opened on first use, the state methods
 * keep across the experiments of one run (a sweep's points), and the results of the methods
 * that ran before it in this experiment. */
typedef struct ppb_run_ctx {
    const ppb_config *cfg;
    const char *device_selector; /* --device, or NULL */
    ppb_ocl ocl;
    int ocl_open;
    int quiet; /* 1: no progress lines; 2 (--quiet): nor the reference cache's line */
    /* 1: methods attach their own outputs to their results (ppb_result.extra; `run` writes them
     * with the output set); 0: none are made (a sweep point, which writes no set). */
    int extras;
    /* The experiment's results so far, set by the runner before each method (NULL, 0: none).
     * A method that combines others' results (a sum) takes them from here when they ran,
     * byte-identical to computing them again, and computes them itself otherwise. */
    const ppb_result *prior;
    int nprior;
    const struct ppb_method *self; /* the method running, set by the runner */
    /* The Monte Carlo (the registry's method with reference == 1), set by `ppbench perf` for
     * the benchmarks that time a method against it (a slice cannot reach the registry); NULL
     * elsewhere. */
    const struct ppb_method *reference;
    const char *ref_cache; /* --ref-cache DIR: mc's tallies reused from there */
    /* The reference's file in the cache or the shipped layer (mc_cache.h), set by mc: the one
     * it was loaded from or stored into; "" when none (provenance.txt's mc.reference). */
    char mc_reference[4096 + 160];
    char mc_shipped_key[64];  /* its shipped layer's name, mc-<key>.bin (mc_cache.h) */
    int mc_reference_shipped; /* 1: mc_reference is the shipped layer's */
    /* The same per channel (R, G, B) of a colour run whose reference served every channel from
     * its own single-channel file (run_channels); "" when they were traced together. Each
     * channel's output set names its own (provenance.txt), which `make references` ships. */
    char mc_channel_reference[3][4096 + 160];
    char mc_channel_shipped_key[3][64];
    ppb_method_state state[PPB_MAX_STATES];
    int nstate;
} ppb_run_ctx;

/* The device, opened on first call and shared by every method of the run. */
int ppb_ctx_ocl(ppb_run_ctx *ctx, ppb_ocl **ocl, ppb_err *err);
/* Closes the device and releases every method's state. */
void ppb_ctx_close(ppb_run_ctx *ctx);
/* Releases every method's state only (a context that borrows its device). */
void ppb_ctx_drop_state(ppb_run_ctx *ctx);

/* The state kept under key, or NULL. */
void *ppb_ctx_state(const ppb_run_ctx *ctx, const char *key);
/* Keeps data under key until the context closes (release(data) then); fails, releasing data,
 * when every slot is taken. */
int ppb_ctx_keep(ppb_run_ctx *ctx, const char *key, void *data, void (*release)(void *),
                 ppb_err *err);

/* The complete (not partial) result `id` among ctx->prior, or NULL. */
const ppb_result *ppb_ctx_prior(const ppb_run_ctx *ctx, const char *id);

/* out[0] is the method's result, out[1] its companion when `also` is set; both are already
 * initialised to zero with the scene's layout and their ids. */
typedef int (*ppb_method_fn)(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Everything the runner, the writers, the report and the benchmarks need from a method; none
 * of them names one (docs/reference.md: Methods, "Adding a method"). */
typedef struct ppb_method {
    const char *id;
    const char *also; /* id of a companion result, or NULL */
    int slab_only;    /* ppslab */
    int reference;    /* 1: the Monte Carlo, which every other method is measured against;
                         2: an exact answer methods are also checked against (ppslab) */
    const char *summary;
    ppb_method_fn run;
    /* Refuses, before any work, a config where the method's model has no meaning (mp at albedo
     * 1); NULL: every valid config is fine. */
    int (*check)(const ppb_config *cfg, ppb_err *err);
    /* A sum of other methods' results, cell by cell (mp+ss = mp + ss): their ids, NULL-ended;
     * run and check are then ppb_method_sum's (method.c). NULL: not a sum. */
    const char *const *sum_of;
    /* The config section of the method's settings ("rte2d"), or NULL. */
    const char *section;
    /* Its column in the paper's Table 2 ("MP+S"; model/paper.h), or NULL: not in the paper. */
    const char *paper_column;
    /* Prints "NAME: ID: work: ..." for a method whose work scales with the settings, before it
     * runs (id: the config's id, a sum's for its parts); NULL: nothing to say. */
    void (*work)(const ppb_config *cfg, const char *id, FILE *f);
    /* Draws the method's own figures from its own files in the output set dir (rte2d's
     * refinement study), the experiment called name; one not drawn is added to fig. NULL:
     * none (the common figures are scripts/plots.sh's). */
    void (*draw)(const char *dir, const char *name, ppb_figures *fig);
    /* Its benchmark in `ppbench perf` under the heading perf_title; NULL: none. */
    const char *perf_title;
    int (*perf)(ppb_run_ctx *ctx, FILE *out, ppb_err *err);
    /* Runs every channel of a colour experiment at once: cfgs[c] is channel c's experiment, and
     * out[2 * c], out[2 * c + 1] its result and companion (initialised as for run). NULL: the
     * runner runs the method once per channel. */
    int (*run_channels)(ppb_run_ctx *ctx, const ppb_config *cfgs, int nch, ppb_result *out,
                        ppb_err *err);
} ppb_method;

/* A sum method's run and check (ppb_method.sum_of): the parts are found through the registry
 * by the caller-supplied lookup, taken from ctx->prior when they ran before and computed
 * otherwise. The sum's totals are its first part's with R, T and sides of the others added:
 * a part's light counts as often as it is summed (the paper's MP+S counts single scattering
 * twice, docs/reference.md: Methods). */
int ppb_method_sum(ppb_run_ctx *ctx, ppb_result *out,
                   const ppb_method *(*find)(const ppb_config *, const char *), ppb_err *err);

#endif
