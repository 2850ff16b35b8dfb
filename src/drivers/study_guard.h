/* study_guard.h: the committed study's output sets (results/<case>, docs/reference.md: Outputs,
 * "The committed study") are written by `make bench` alone: a run whose output directory is
 * one of them (results/<case>, case in configs/study.list; results/materials/<case>, case in
 * configs/materials.list), or results/ itself, is refused unless scripts/bench.sh's marker is
 * set (PPB_BENCH_STUDY=1 in the environment). */
#ifndef PPB_STUDY_GUARD_H
#define PPB_STUDY_GUARD_H

#include "base/err.h"

/* 0 when out_dir may be written; -1 (err says to give --out) when it is the committed study's
 * and the marker is not set. */
int ppb_study_guard(const char *out_dir, ppb_err *err);

/* The source tree: $PPBENCH_SOURCE, else the directory ppbench was built in. */
const char *ppb_source_dir(void);

#endif
