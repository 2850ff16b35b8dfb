#include "base/hash.h"

#include <stdlib.h>
#include <xxhash.h>

uint64_t ppb_hash64(const void *data, size_t len)
{
    return (uint64_t)XXH3_64bits(data, len);
}

struct ppb_hasher {
    XXH3_state_t *st;
};

ppb_hasher *ppb_hash64_begin(void)
{
    ppb_hasher *h = malloc(sizeof *h);
    if (!h)
        return NULL;
    if (!(h->st = XXH3_createState()) || XXH3_64bits_reset(h->st) != XXH_OK) {
        XXH3_freeState(h->st);
        free(h);
        return NULL;
    }
    return h;
}

void ppb_hash64_update(ppb_hasher *h, const void *data, size_t len)
{
    XXH3_64bits_update(h->st, data, len);
}

uint64_t ppb_hash64_end(ppb_hasher *h)
{
    uint64_t v = (uint64_t)XXH3_64bits_digest(h->st);
    XXH3_freeState(h->st);
    free(h);
    return v;
}
