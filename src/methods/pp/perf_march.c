/* perf_march.c: the ray marcher's benchmark (perf_march.h). */
#include "methods/pp/perf_march.h"

#include "methods/pp/march.h"
#include "base/progress.h"

/* Times one whole case (every row of the layout in one launch) after a warm-up run of the same
 * case, which takes the kernel build, the runtime's work-group compilation and first-touch costs
 * out of the figure. */
static int time_case(FILE *out, ppb_ocl *ocl, const ppb_scene *sc, const ppb_maps *maps,
                     const ppb_march_tables *tab, ppb_march_opts opts, const char *label,
                     ppb_err *err)
{
    ppb_marcher mr;
    if (ppb_marcher_init(&mr, ocl, sc, maps, tab, &opts, err))
        return -1;
    if (ppb_marcher_run(&mr, 0, mr.rows, err)) {
        ppb_marcher_free(&mr);
        return -1;
    }
    double t0 = ppb_now();
    int rc = ppb_marcher_run(&mr, 0, mr.rows, err);
    double dt = ppb_now() - t0;
    if (!rc) {
        double rays = (double)mr.rows * mr.nbins * tab->nsamp * tab->nsamp * opts.npts;
        fprintf(out, "%-34s %4d points x %2d bins x %2d dirs: %7.3f s  %9.3g rays/s\n", label,
                mr.rows * opts.npts, mr.nbins, tab->nsamp * tab->nsamp, dt, rays / dt);
    }
    ppb_marcher_free(&mr);
    return rc;
}

int ppb_perf_march(ppb_run_ctx *ctx, FILE *out, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    ppb_scene sc = cfg->scene;
    sc.geometry = PPB_GEOM_TUBE;
    ppb_ocl *ocl;
    if (ppb_ctx_ocl(ctx, &ocl, err))
        return -1;
    fprintf(out, "device: %s\n", ocl->name);
    ppb_maps maps;
    ppb_march_tables pp = {0}, ss = {0};
    double t0 = ppb_now();
    if (ppb_maps_build(&sc, cfg->pp.map_res, &maps, err))
        return -1;
    double t_maps = ppb_now() - t0;
    ppb_pp_settings pps = cfg->pp;
    pps.table = PPB_TABLE_S; /* builds both tables */
    t0 = ppb_now();
    int rc = ppb_march_tables_pp(&sc, &pps, cfg->samples_dir, PPB_MARCH_TAU_PER_MFP, &pp, err);
    double t_tab = ppb_now() - t0;
    if (!rc)
        rc = ppb_march_tables_ss(&sc, cfg->samples_dir, &ss, err);
    if (!rc) {
        fprintf(out,
                "host: maps (%d cells/mfp) %.3f s; tables R+S (%d directions, %d of %d modes, "
                "%d albedo nodes, %d tau nodes, %d table directions) %.3f s\n",
                cfg->pp.map_res, t_maps, cfg->pp.directions, pp.modes_kept, pp.nmodes, pp.nalb,
                pp.ntau, pp.ndir, t_tab);
        ppb_march_opts o = {.table = PPB_TABLE_S, .step = cfg->pp.step, .telescope = 1, .npts = 1};
        char label[96];
        snprintf(label, sizeof label, "pp, S table, step %g:", cfg->pp.step);
        rc = time_case(out, ocl, &sc, &maps, &pp, o, label, err);
        o.npts = cfg->samples_seg;
        if (!rc && o.npts > 1)
            rc = time_case(out, ocl, &sc, &maps, &pp, o, label, err);
        o.telescope = 0;
        o.npts = 1;
        snprintf(label, sizeof label, "pp, S table stepped, step %g:", cfg->pp.step);
        if (!rc)
            rc = time_case(out, ocl, &sc, &maps, &pp, o, label, err);
        o.table = PPB_TABLE_R;
        o.telescope = 1;
        snprintf(label, sizeof label, "pp, R table, step %g:", cfg->pp.step);
        if (!rc)
            rc = time_case(out, ocl, &sc, &maps, &pp, o, label, err);
        o.table = PPB_TABLE_S;
        snprintf(label, sizeof label, "ss:");
        if (!rc)
            rc = time_case(out, ocl, &sc, &maps, &ss, o, label, err);
        o.npts = cfg->samples_seg;
        if (!rc && o.npts > 1)
            rc = time_case(out, ocl, &sc, &maps, &ss, o, label, err);
    }
    ppb_march_tables_free(&pp);
    ppb_march_tables_free(&ss);
    ppb_maps_free(&maps);
    return rc;
}
