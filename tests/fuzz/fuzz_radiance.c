/* fuzz_radiance.c: the validator of an external method's radiance.csv and totals.csv
 * (methods/method_external.c: ppb_external_read_radiance, ppb_external_totals, then
 * result_check.c's checks, as a run applies them) on arbitrary bytes, against a small tube
 * scene (8 and 3 segments, 2 x 2 bins: the layout of tests/test_external.c's tiny runs). Seeds:
 * tests/fuzz/corpus/radiance (a radiance.csv of such a run, with rows of "x"). */
#include <string.h>

#include "fuzz_util.h"
#include "methods/external/method_external.h"
#include "methods/result_check.h"
#include "model/config.h"
#include "model/result.h"

static ppb_config cfg;
static int ready;

static void setup(void)
{
    ppb_err err;
    if (ppb_config_defaults(&cfg, &err) ||
        ppb_config_set(&cfg, "tube", "segments_top", "8", &err) ||
        ppb_config_set(&cfg, "tube", "segments_side", "3", &err) ||
        ppb_config_set(&cfg, "bins", "theta", "2", &err) ||
        ppb_config_set(&cfg, "bins", "phi", "2", &err))
        abort();
    ready = 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!ready)
        setup();
    ppb_layout lo = ppb_scene_layout(&cfg.scene);
    ppb_result r;
    ppb_err err = {{0}};
    if (ppb_result_init(&r, "x", &lo, &err))
        abort();
    const char *path = fuzz_file(data, size, "csv");
    if (ppb_external_read_radiance(path, "x", size ? data[0] & 1 : 0, &cfg.scene, &r, &err) == 0) {
        if (ppb_external_totals(path, &cfg.scene, &r, &err) == 0 &&
            ppb_radiance_check("fuzz", &r, NULL, &err) == 0)
            (void)ppb_totals_check("fuzz", &r, &err);
    } else if (!err.msg[0]) {
        abort();
    }
    ppb_result_free(&r);
    return 0;
}
