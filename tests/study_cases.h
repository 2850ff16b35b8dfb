/* study_cases.h: what the method suites share to run a method on the study's cases: the cases
 * of configs/study.list, a case's config loaded as the runner loads it, and one method run into
 * a fresh result (every failure a test failure). Include after testutil.h. */
#ifndef PPB_TEST_STUDY_CASES_H
#define PPB_TEST_STUDY_CASES_H

#include <stdio.h>
#include <string.h>

#include "methods/registry.h"
#include "model/config.h"

enum { STUDY_MAX_CASES = 64 };

/* The case names of configs/study.list (blank and '#' lines skipped); at least one. */
static inline int study_cases(char names[STUDY_MAX_CASES][64])
{
    FILE *list = fopen(PPB_SOURCE_DIR "/configs/study.list", "r");
    assert_non_null(list);
    char line[128];
    int n = 0;
    while (n < STUDY_MAX_CASES && fgets(line, sizeof line, list)) {
        line[strcspn(line, "\r\n")] = 0;
        if (!line[0] || line[0] == '#')
            continue;
        assert_true(strlen(line) < 64);
        memcpy(names[n++], line, strlen(line) + 1);
    }
    fclose(list);
    assert_true(n > 0);
    return n;
}

/* The study's config NAME, loaded from configs/ (as the runner does). */
static inline void study_load_config(const char *name, ppb_config *cfg)
{
    char path[4096 + 128];
    ppb_err err;
    snprintf(path, sizeof path, "%s/configs/%.64s.ini", PPB_SOURCE_DIR, name);
    if (ppb_config_load(cfg, path, &err))
        fail_msg("%s", err.msg);
}

/* Runs method id on ctx's config into out (initialised here with the scene's layout). */
static inline void study_run_id(ppb_run_ctx *ctx, const char *id, ppb_result *out)
{
    ppb_err err;
    ppb_layout lo = ppb_scene_layout(&ctx->cfg->scene);
    assert_int_equal(ppb_result_init(out, id, &lo, &err), 0);
    const ppb_method *m = ppb_method_find(ctx->cfg, id);
    assert_non_null(m);
    ctx->self = m;
    if (m->run(ctx, out, &err))
        fail_msg("%s: %s", id, err.msg);
}

/* A registry sum `model`+ss is `model` + ss cell by cell, on a coarse oblique tube at n = 1.4
 * (ss through the OpenCL marcher), and its totals are the model's with ss's R, T and sides
 * added (method.h: ppb_method_sum). */
static inline void study_check_sum_with_ss(const char *model)
{
    char sum_id[64];
    snprintf(sum_id, sizeof sum_id, "%s+ss", model);
    ppb_config cfg;
    study_load_config("uniform_g0_oblique_n14", &cfg);
    cfg.scene.segments_top = 16;
    cfg.scene.segments_side = 6;
    cfg.samples_dir = 2;
    cfg.samples_seg = 2;
    ppb_run_ctx ctx = {.cfg = &cfg, .quiet = 1};
    ppb_result sum, b, s;
    study_run_id(&ctx, sum_id, &sum);
    study_run_id(&ctx, model, &b);
    study_run_id(&ctx, "ss", &s);
    double ss_total = 0;
    for (size_t i = 0; i < sum.layout.ncells; i++) {
        assert_close(sum.radiance[i], b.radiance[i] + s.radiance[i], 0.0);
        ss_total += s.radiance[i];
    }
    assert_lt(0, ss_total); /* ss did add light */
    assert_rel(sum.totals.R, b.totals.R + s.totals.R, 1e-15);
    assert_rel(sum.totals.T, b.totals.T + s.totals.T, 1e-15);
    assert_rel(sum.totals.sides, b.totals.sides + s.totals.sides, 1e-15);
    ppb_result_free(&sum);
    ppb_result_free(&b);
    ppb_result_free(&s);
    ppb_ctx_close(&ctx);
}

#endif
