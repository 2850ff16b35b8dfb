/* object_registry.c: the one place that names every object method (methods/object_method.h),
 * as registry.c does for the tube's. */
#include "methods/object_registry.h"

#include <string.h>

#include "methods/mc3d/method_mc3d.h"
#include "methods/pp3d/pp3d.h"

static const ppb_object_method methods[] = {
    {.id = "mc3d",
     .also = "mc3d1",
     .reference = 1,
     .summary = "photon Monte Carlo through the voxel grid (reference); mc3d1 its "
                "once-scattered part",
     .run = ppb_object_method_mc3d},
    {.id = "ss3d",
     .summary = "single scattering by ray marching through the light's optical-depth map (exact)",
     .run = ppb_pp3d_run_ss3d},
    {.id = "pp3d",
     .summary = "the paper's method on an object: the march with the local slabs' R tables "
                "(Sec. 3.4-3.5)",
     .run = ppb_pp3d_run_pp3d},
};

#define NMETHODS ((int)(sizeof methods / sizeof methods[0]))

int ppb_object_method_count(void)
{
    return NMETHODS;
}

const ppb_object_method *ppb_object_method_at(int i)
{
    return i >= 0 && i < NMETHODS ? &methods[i] : NULL;
}

const ppb_object_method *ppb_object_method_find(const char *id)
{
    for (int i = 0; i < NMETHODS; i++)
        if (strcmp(methods[i].id, id) == 0)
            return &methods[i];
    return NULL;
}

const ppb_object_method *ppb_object_method_reference(void)
{
    for (int i = 0; i < NMETHODS; i++)
        if (methods[i].reference == 1)
            return &methods[i];
    return NULL;
}

int ppb_object_methods_check(const ppb_config *cfg, ppb_err *err)
{
    char known[256] = "";
    for (int i = 0; i < NMETHODS; i++)
        snprintf(known + strlen(known), sizeof known - strlen(known), "%s%s", i ? ", " : "",
                 methods[i].id);
    if (cfg->nmethods == 0)
        return ppb_config_key_fail(cfg, "experiment", "methods", err,
                                   "no method given (object methods: %s)", known);
    for (int i = 0; i < cfg->nmethods; i++)
        if (!ppb_object_method_find(cfg->methods[i]))
            return ppb_config_key_fail(cfg, "experiment", "methods", err,
                                       "'%s' is no object method (`ppbench object` runs: %s)",
                                       cfg->methods[i], known);
    return 0;
}
