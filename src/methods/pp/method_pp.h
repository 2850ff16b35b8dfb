/* method_pp.h: the paper's method `pp` (reference: Methods; paper Sec. 3, Eq. 13-17): the
 * plane-parallel solution of a slab of the tube's thickness, re-integrated along every viewing
 * ray through the optical-depth and average-albedo maps with the integral tables R or S. */
#ifndef PPB_METHOD_PP_H
#define PPB_METHOD_PP_H

#include <stdio.h>

#include "methods/method.h"

/* Fills out[0] with the bin-averaged exit radiance and the totals (reference: Bins). */
int ppb_method_pp(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err);

/* Whether pp has a meaning at cfg's point (the registry's check hook). */
int ppb_pp_check(const ppb_config *cfg, ppb_err *err);

/* The pipeline itself: maps, tables, march, totals. with_modes = 0 keeps only the attenuated
 * direct beam's single scattering in the tables: that is `ss` (method_ss.h). */
int ppb_pp_pipeline(ppb_run_ctx *ctx, ppb_result *out, int with_modes, ppb_err *err);

/* The march's work line, rays x steps (pp's and ss's work hooks begin with it). */
void ppb_pp_march_work(const ppb_config *cfg, const char *id, FILE *f);
/* pp's work hook: the march, then the tables' build. */
void ppb_pp_work(const ppb_config *cfg, const char *id, FILE *f);

#endif
