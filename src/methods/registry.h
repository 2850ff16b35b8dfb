/* registry.h: the method ids: the table of every method (its order is the order of outputs),
 * lookup by id, and the check of a config's method list against the table.
 *
 * The config knows no methods (model/config.h keeps `methods` as id strings), so every driver
 * that loads a config calls ppb_methods_check() right after loading it. */
#ifndef PPB_REGISTRY_H
#define PPB_REGISTRY_H

#include "base/err.h"
#include "methods/method.h"
#include "model/config.h"

/* The method `id` names: a built-in one, or, when cfg defines [method.<id>], the descriptor
 * every external method shares (its `id` is NULL: the id is the caller's, the NAME of the
 * config's section). NULL when no method has that id (cfg NULL: built-in ones only). The
 * lookup goes through cfg's own list: the registry keeps no state of its own. */
const ppb_method *ppb_method_find(const ppb_config *cfg, const char *id);
int ppb_method_count(void);
/* The reference every other method is measured against (reference == 1: the Monte Carlo),
 * whose shards `ppbench mc-shard` traces and `mc-merge` joins. */
const ppb_method *ppb_method_reference(void);
const ppb_method *ppb_method_at(int i); /* NULL outside [0, ppb_method_count()) */

/* Every id of cfg->methods names a method, and no slab-only method runs in tube mode (reference:
 * Methods); otherwise fails with "file:line: [experiment] methods: reason" (or "--set
 * experiment.methods: reason" when --set gave the list). */
int ppb_methods_check(const ppb_config *cfg, ppb_err *err);

#endif
