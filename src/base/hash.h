/* hash.h: the 64-bit content hash of ppbench (sweep point names, Monte Carlo tally
 * fingerprints), over Debian's libxxhash (XXH3_64bits, seed 0): a well-kept library, not a
 * hand-written loop. The value is part of file names and the tally file format: changing the
 * function renames every sweep point and needs a new tally file version (mc_tally.c). */
#ifndef PPB_HASH_H
#define PPB_HASH_H

#include <stddef.h>
#include <stdint.h>

uint64_t ppb_hash64(const void *data, size_t len);

/* The same hash over data given in pieces (a file written or read in blocks): ppb_hash64_end
 * returns what ppb_hash64 returns over the pieces' concatenation, and frees the state.
 * ppb_hash64_begin returns NULL when out of memory. */
typedef struct ppb_hasher ppb_hasher;
ppb_hasher *ppb_hash64_begin(void);
void ppb_hash64_update(ppb_hasher *h, const void *data, size_t len);
uint64_t ppb_hash64_end(ppb_hasher *h);

#endif
