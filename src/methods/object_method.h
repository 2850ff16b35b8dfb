/* object_method.h: the one interface of the methods that render a three-dimensional object
 * (model/object.h; docs/reference.md, Objects): given the object, its patches and the run's
 * settings (ctx->cfg: the [mc], [pp] and other method sections of the object's config), fill
 * radiance per (patch, bin) and per camera pixel, with standard errors. The `ppbench object`
 * driver, its metrics and writers never name one; the object registry lists them. */
#ifndef PPB_OBJECT_METHOD_H
#define PPB_OBJECT_METHOD_H

#include "methods/method.h"
#include "model/object.h"

/* out is already initialised (ppb_object_result_init) with the patches' count, the bins and the
 * camera's pixels. */
typedef int (*ppb_object_method_fn)(ppb_run_ctx *ctx, const ppb_object *o,
                                    const ppb_object_patches *p, ppb_object_result *out,
                                    ppb_err *err);

typedef struct ppb_object_method {
    const char *id;
    const char *also; /* id of a companion result (mc's mc1), or NULL */
    int reference;    /* 1: the Monte Carlo every other method is measured against */
    const char *summary;
    /* out[0] the method's result, out[1] its companion when `also` is set. */
    ppb_object_method_fn run;
} ppb_object_method;

#endif
