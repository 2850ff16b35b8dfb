/* hash.h: the 64-bit content hash of ppbench (sweep point names, Monte Carlo tally
 * fingerprints), over Debian's libxxhash (XXH3_64bits, seed 0): a well-kept library, not a
 * hand-written loop. The value is part of file names and the tally file format: changing the
 * function renames every sweep point and needs a new tally file version (mc_tally.c). */
#ifndef PPB_HASH_H
#define PPB_HASH_H

#include <stddef.h>
#include <stdint.h>

uint64_t ppb_hash64(const void *data, size_t len);

#endif
