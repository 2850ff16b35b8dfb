/* method_ss.c: single scattering by ray marching (method_ss.h). */
#include "methods/method_ss.h"

#include "methods/method_pp.h"
#include "methods/work_estimate.h"

int ppb_method_ss(ppb_run_ctx *ctx, ppb_result *out, ppb_err *err)
{
    return ppb_pp_pipeline(ctx, out, 0, err);
}

/* At n > 1 ss marches the refracted beam and its reflections (kernels/march.cl): off S2 and S1
 * in the slab and in the tube at normal incidence, off all four faces by the cross-section's
 * mirror images at oblique incidence, where a density step's images enter the beam's optical
 * depth (ppb_image_depth). Every n in range has a meaning; what is refused is a cost: an image
 * series whose terms, estimated before any work (work_estimate.h), exceed
 * PPB_WORK_IMAGE_TERMS_MAX (a thin tube at grazing light near the critical angle, where F_b is
 * near 1 and a row of images adds little depth). */
int ppb_ss_check(const ppb_config *cfg, ppb_err *err)
{
    ppb_work_img w;
    if (!ppb_work_images(cfg, &w) || w.terms <= PPB_WORK_IMAGE_TERMS_MAX)
        return 0;
    return ppb_fail(err,
                    "ss: the beam's images need up to %.3g terms (%.3g rays x up to %.3g legs x "
                    "%.3g rows x %.3g tiles), above the %.3g ss runs (docs/reference.md: "
                    "Methods): a thicker tube, light nearer the normal or fewer bins",
                    w.terms, w.rays, w.legs, w.rows, w.per_row, PPB_WORK_IMAGE_TERMS_MAX);
}
