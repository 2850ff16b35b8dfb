#include "base/hash.h"

#include <xxhash.h>

uint64_t ppb_hash64(const void *data, size_t len)
{
    return (uint64_t)XXH3_64bits(data, len);
}
