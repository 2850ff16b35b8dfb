/* method.h: the one interface every method implements: what a method receives (ppb_run_ctx,
 * with the OpenCL device opened on first use) and what describes it (ppb_method). The table of
 * methods and the lookup by id are the registry's (methods/registry.h).
 *
 * A method, given the experiment (scene and settings), fills radiance per (surface, segment,
 * bin) and its totals. A method may also produce a second result in the same run (mc writes
 * its once-scattered part as mc1). The runner, metrics and writers never special-case one. */
#ifndef PPB_METHOD_H
#define PPB_METHOD_H

#include "model/config.h"
#include "runtime/ocl.h"
#include "model/result.h"

struct ppb_march_cache;
struct ppb_rte2d_study;

/* What a method gets: the experiment, an OpenCL device opened on first use, caches that
 * outlive one experiment (a sweep reuses the marcher's tables across grid points), and the
 * results of the methods that ran before it in this experiment. */
typedef struct ppb_run_ctx {
    const ppb_config *cfg;
    const char *device_selector; /* --device, or NULL */
    ppb_ocl ocl;
    int ocl_open;
    int quiet; /* 1: no progress lines; 2 (--quiet): nor the reference cache's line */
    struct ppb_march_cache *march_cache; /* owned by the caller; NULL = build afresh */
    /* The experiment's results so far, set by the runner before each method (NULL, 0: none).
     * A method that combines others' results (mp+ss) takes them from here when they ran,
     * byte-identical to computing them again, and computes them itself otherwise. */
    const ppb_result *prior;
    int nprior;
    const char *ref_cache; /* --ref-cache DIR: mc's tallies reused from there (mc_cache.h) */
    /* Owned by the caller: where rte2d records its refinement study (method_rte2d.h), which
     * `run` writes with the output set; NULL: none is run (a sweep point writes no table). */
    struct ppb_rte2d_study *rte2d_study;
} ppb_run_ctx;

/* The device, opened on first call and shared by every method of the run. */
int ppb_ctx_ocl(ppb_run_ctx *ctx, ppb_ocl **ocl, ppb_err *err);
void ppb_ctx_close(ppb_run_ctx *ctx);

/* The complete (not partial) result `id` among ctx->prior, or NULL. */
const ppb_result *ppb_ctx_prior(const ppb_run_ctx *ctx, const char *id);

/* out[0] is the method's result, out[1] its companion when `also` is set; both are already
 * initialised to zero with the scene's layout and their ids. */
typedef int (*ppb_method_fn)(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

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
} ppb_method;

#endif
