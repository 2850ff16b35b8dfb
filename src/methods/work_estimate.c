/* work_estimate.c: work and result memory estimated before allocating (work_estimate.h). */
#include "methods/work_estimate.h"

#include "methods/registry.h"
#include "physics/march_tables.h"
#include "model/scene.h"

double ppb_work_results_bytes(const ppb_config *cfg)
{
    double nres = 0;
    for (int m = 0; m < cfg->nmethods; m++) {
        const ppb_method *me = ppb_method_find(cfg, cfg->methods[m]);
        nres += me && me->also ? 2 : 1;
    }
    return nres * (double)ppb_scene_layout(&cfg->scene).ncells * 2.0 * sizeof(double);
}

void ppb_work_print(FILE *f, const ppb_config *cfg)
{
    for (int m = 0; m < cfg->nmethods; m++) {
        const char *id = cfg->methods[m];
        const ppb_method *me = ppb_method_find(cfg, id);
        if (!me)
            continue;
        if (!me->sum_of) {
            if (me->work)
                me->work(cfg, id, f);
            continue;
        }
        /* A sum's work is its parts' (said once, under the sum's id). */
        for (int i = 0; me->sum_of[i]; i++) {
            const ppb_method *part = ppb_method_find(cfg, me->sum_of[i]);
            if (part && part->work) {
                part->work(cfg, id, f);
                break;
            }
        }
    }
}
