/* march.c: host side of the ray marcher (march.h). */
#include "methods/pp/march.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/progress.h"
#include "kernels/ppb_fresnel.h"
#include "physics/medium.h"

_Static_assert(sizeof(ppb_march_params) ==
                   sizeof(ppb_medium) + sizeof(ppb_lit) + 17 * sizeof(double) + 24 * sizeof(int),
               "ppb_march_params: the medium, doubles, an even number of ints, no padding");

static cl_mem upload(ppb_ocl *ocl, const double *data, size_t n, const char *what, ppb_err *err)
{
    static const double zero = 0.0;
    cl_int rc;
    /* A zero-length buffer is not allowed: unused tables get one element. */
    cl_mem m = clCreateBuffer(ocl->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                              (data ? n : 1) * sizeof(double), (void *)(data ? data : &zero), &rc);
    if (rc != CL_SUCCESS) {
        ppb_fail(err, "OpenCL: clCreateBuffer(%s, %zu doubles) failed: %s", what, n,
                 ppb_cl_errname(rc));
        return NULL;
    }
    return m;
}

/* The launch parameters the kernel reads (march_params.h), all but row0, which each launch
 * sets. */
static ppb_march_params march_params(const ppb_scene *sc, const ppb_maps *maps,
                                     const ppb_march_tables *tab, const ppb_march_opts *opts)
{
    double wl[3];
    ppb_scene_light_dir(sc, wl);
    ppb_march_params P = {
        .med = ppb_medium_of(sc),
        .lit = ppb_lit_of(sc),
        .tan_theta_l = ppb_scene_tan_theta_l(sc),
        .cos_theta_l = ppb_scene_cos_theta_l(sc),
        .light_x = wl[0],
        .light_y = wl[1],
        .map_xp0 = maps->xp0,
        .map_h = maps->h,
        .alb0 = tab->alb0,
        .alb_h = tab->alb_h,
        .ds = opts->step,
        .d_cap = opts->d_cap > 0.0 ? opts->d_cap : 40.0,
        .map_nx = maps->nx,
        .map_i0 = maps->i0,
        .map_ny = maps->ny,
        .nalb = tab->nalb,
        .ncols = tab->ncols,
        .with_modes = tab->R != NULL,
        /* Without an S table (ss, or R asked for) the kernel marches with R. */
        .table = (opts->table == PPB_TABLE_S && tab->S) ? PPB_TABLE_S : PPB_TABLE_R,
        .telescope = opts->telescope,
        .nsamp = tab->nsamp,
        .npts = opts->npts < 1 ? 1 : opts->npts,
        .ntheta = sc->ntheta,
        .nphi = sc->nphi,
    };
    if (sc->n > 1.0) {
        /* Inside, the beam runs along the refracted direction (the maps follow it, maps.c). */
        ppb_fresnel_beam b = ppb_fresnel_beam_in(ppb_scene_cos_theta_l(sc), sc->n);
        P.cos_theta_l = b.cos_t;
        P.tan_theta_l = b.sin_t / b.cos_t;
        P.light_x = b.sin_t;
        P.light_y = -b.cos_t;
        P.beam_in = b.irradiance;
        P.beam_fb = b.f_inside;
        P.beam_fs = ppb_fresnel(b.sin_t, 1.0 / sc->n);
    }
    return P;
}

/* The arrays of the parameters: where each surface's cells start in the layout, and the tau
 * grid of each column slab, which the kernel needs to index the tables. */
static void march_params_arrays(ppb_march_params *P, const ppb_layout *lo,
                                const ppb_march_tables *tab)
{
    for (int s = 0; s < PPB_NSURF; s++) {
        P->nseg[s] = lo->nseg[s];
        P->offset[s] = lo->offset[s];
    }
    for (int c = 0; c < tab->ncols; c++) {
        P->tau0[c] = tab->col[c].tau0;
        P->tau_h[c] = tab->col[c].tau_h;
        P->ntau[c] = tab->col[c].ntau;
    }
}

/* The device buffers: the inputs copied once, read by every launch, and the output of every
 * cell. On failure the ones made so far stay in mr for ppb_marcher_free. */
static int march_buffers(ppb_marcher *mr, const ppb_maps *maps, const ppb_march_tables *tab,
                         size_t ncells, ppb_err *err)
{
    ppb_ocl *ocl = mr->ocl;
    size_t tsize = (size_t)tab->nalb * tab->ndir * tab->ntau;
    mr->map = upload(ocl, maps->cells, (size_t)maps->nx * maps->ny * PPB_MAP_STRIDE, "map", err);
    if (!mr->map)
        return -1;
    mr->tab_r = upload(ocl, tab->R, tsize, "R table", err);
    if (!mr->tab_r)
        return -1;
    mr->tab_s = upload(ocl, tab->S, tsize, "S table", err);
    if (!mr->tab_s)
        return -1;
    mr->coef_c =
        upload(ocl, tab->C, (size_t)(tab->nvar > 1 ? 2 : 1) * tab->ncols * tab->nalb * tab->ndir,
               "beam coefficients", err);
    if (!mr->coef_c)
        return -1;
    cl_int rc;
    mr->out = clCreateBuffer(ocl->context, CL_MEM_WRITE_ONLY, ncells * sizeof(double), NULL, &rc);
    return ppb_cl_check(rc, "clCreateBuffer(radiance)", err);
}

/* The buffer arguments are fixed for the marcher's life; only the parameters change per launch
 * (ppb_marcher_run). */
static int march_bind_buffers(ppb_marcher *mr, ppb_err *err)
{
    cl_mem args[] = {[PPB_MARCH_ARG_MAP] = mr->map,
                     [PPB_MARCH_ARG_TAB_R] = mr->tab_r,
                     [PPB_MARCH_ARG_TAB_S] = mr->tab_s,
                     [PPB_MARCH_ARG_COEF_C] = mr->coef_c,
                     [PPB_MARCH_ARG_OUT] = mr->out};
    for (int i = PPB_MARCH_ARG_MAP; i < PPB_MARCH_NARGS; i++)
        if (ppb_cl_check(clSetKernelArg(mr->kernel, i, sizeof(cl_mem), &args[i]),
                         "clSetKernelArg(march)", err))
            return -1;
    return 0;
}

int ppb_marcher_init(ppb_marcher *mr, ppb_ocl *ocl, const ppb_scene *sc, const ppb_maps *maps,
                     const ppb_march_tables *tab, const ppb_march_opts *opts, ppb_err *err)
{
    memset(mr, 0, sizeof *mr);
    mr->ocl = ocl;
    ppb_layout lo = ppb_scene_layout(sc);
    mr->nbins = lo.nbins;
    mr->rows = (int)(lo.ncells / (size_t)lo.nbins);
    mr->params = march_params(sc, maps, tab, opts);
    march_params_arrays(&mr->params, &lo, tab);
    if (ppb_ocl_build(ocl, PPB_MARCH_KERNEL, "", &mr->prog, err) ||
        ppb_ocl_kernel(mr->prog, "ppb_march_kernel", &mr->kernel, err) ||
        march_buffers(mr, maps, tab, lo.ncells, err) || march_bind_buffers(mr, err)) {
        ppb_marcher_free(mr);
        return -1;
    }
    return 0;
}

int ppb_marcher_run(ppb_marcher *mr, int row0, int nrows, ppb_err *err)
{
    if (nrows <= 0)
        return 0;
    mr->params.row0 = row0;
    if (ppb_cl_check(
            clSetKernelArg(mr->kernel, PPB_MARCH_ARG_PARAMS, sizeof mr->params, &mr->params),
            "clSetKernelArg(march params)", err))
        return -1;
    size_t global = (size_t)nrows * (size_t)mr->nbins;
    if (ppb_cl_check(clEnqueueNDRangeKernel(mr->ocl->queue, mr->kernel, 1, NULL, &global, NULL, 0,
                                            NULL, NULL),
                     "clEnqueueNDRangeKernel(march)", err))
        return -1;
    return ppb_cl_check(clFinish(mr->ocl->queue), "clFinish(march)", err);
}

int ppb_marcher_read(ppb_marcher *mr, double *radiance, ppb_err *err)
{
    size_t n = (size_t)mr->rows * (size_t)mr->nbins;
    return ppb_cl_check(clEnqueueReadBuffer(mr->ocl->queue, mr->out, CL_TRUE, 0, n * sizeof(double),
                                            radiance, 0, NULL, NULL),
                        "clEnqueueReadBuffer(march radiance)", err);
}

void ppb_marcher_free(ppb_marcher *mr)
{
    cl_mem bufs[] = {mr->map, mr->tab_r, mr->tab_s, mr->coef_c, mr->out};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++)
        if (bufs[i])
            clReleaseMemObject(bufs[i]);
    if (mr->kernel)
        clReleaseKernel(mr->kernel);
    if (mr->prog)
        clReleaseProgram(mr->prog);
    memset(mr, 0, sizeof *mr);
}

int ppb_march_all(ppb_ocl *ocl, const ppb_scene *sc, const ppb_maps *maps,
                  const ppb_march_tables *tab, const ppb_march_opts *opts, const char *label,
                  int quiet, double *radiance, int *partial, ppb_err *err)
{
    ppb_marcher mr;
    if (ppb_marcher_init(&mr, ocl, sc, maps, tab, opts, err))
        return -1;
    /* Launches of a few rows each let progress lines and Ctrl-C through; a row is 64 cells.
     * Where ss sums the beam's images (n > 1, tube, oblique light) a row may cost up to
     * 1/rows of method_ss.h's PPB_WORK_IMAGE_TERMS_MAX: one row a launch. */
    int images =
        !tab->R && sc->geometry == PPB_GEOM_TUBE && sc->n > 1.0 && ppb_scene_tan_theta_l(sc) > 0.0;
    const int chunk = images ? 1 : 16;
    ppb_progress pr;
    ppb_progress_begin(&pr, label, "rows", mr.rows, quiet);
    int done = 0, rc = 0;
    *partial = 0;
    while (done < mr.rows) {
        if (ppb_interrupted()) {
            *partial = 1;
            break;
        }
        int n = mr.rows - done < chunk ? mr.rows - done : chunk;
        if ((rc = ppb_marcher_run(&mr, done, n, err)))
            break;
        done += n;
        ppb_progress_update(&pr, done);
    }
    ppb_progress_end(&pr, done);
    if (!rc) {
        /* Rows never marched read as zero. */
        memset(radiance, 0, (size_t)mr.rows * mr.nbins * sizeof *radiance);
        rc = ppb_marcher_read(&mr, radiance, err);
        if (*partial)
            memset(radiance + (size_t)done * mr.nbins, 0,
                   (size_t)(mr.rows - done) * mr.nbins * sizeof *radiance);
    }
    ppb_marcher_free(&mr);
    return rc;
}
