/* object_registry.h: the object methods (methods/object_method.h): their table, lookup by id,
 * and the check of an object config's method list against it. The `ppbench object` driver
 * reaches a method only through here (docs/reference.md, Objects). */
#ifndef PPB_OBJECT_REGISTRY_H
#define PPB_OBJECT_REGISTRY_H

#include "methods/object_method.h"

int ppb_object_method_count(void);
const ppb_object_method *ppb_object_method_at(int i); /* NULL outside the table */
const ppb_object_method *ppb_object_method_find(const char *id);
/* The reference (reference == 1): the object Monte Carlo. */
const ppb_object_method *ppb_object_method_reference(void);

/* Every id of cfg->methods names an object method; otherwise fails naming
 * "file:line: [experiment] methods" and the ids there are. */
int ppb_object_methods_check(const ppb_config *cfg, ppb_err *err);

#endif
