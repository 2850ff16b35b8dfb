/* fuzz_csv.c: the CSV reader (base/csv_read.c) on arbitrary bytes: header, every record, every
 * field by index and as a number. Seeds: tests/fuzz/corpus/csv (outputs of a run). */
#include <string.h>

#include "base/csv_read.h"
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ppb_csv c;
    ppb_err err = {{0}};
    const char *path = fuzz_file(data, size, "csv");
    if (ppb_csv_open(&c, path, &err) != 0) {
        if (!err.msg[0])
            abort();
        return 0;
    }
    (void)ppb_csv_col(&c, "method");
    int got;
    while ((got = ppb_csv_next(&c, &err)) == 1)
        for (int i = -1; i <= c.nfield; i++) {
            double v;
            (void)strlen(ppb_csv_get(&c, i));
            (void)ppb_csv_double(&c, i, &v);
        }
    if (got < 0 && !err.msg[0])
        abort();
    ppb_csv_close(&c);
    return 0;
}
