/* fuzz_config.c: the INI reader (model/config.c, ppb_config_load_grid: a config file, its keys,
 * values, lists and ranges) on arbitrary bytes. A config either loads or is refused with a
 * message; the sanitizers (address, undefined) and libFuzzer find everything else. Seeds:
 * tests/fuzz/corpus/config (the repository's configs). */
#include <string.h>

#include "fuzz_util.h"
#include "model/config.h"
#include "model/grid.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static ppb_config cfg;
    ppb_grid *grid = ppb_grid_new();
    ppb_err err = {{0}};
    const char *path = fuzz_file(data, size, "ini");
    if (!grid)
        abort();
    if (ppb_config_load_grid(&cfg, grid, path, &err) != 0 && !err.msg[0])
        abort(); /* a refusal always says why */
    ppb_grid_free(grid);
    return 0;
}
