#include "io/csv.h"

#include <math.h>
#include <string.h>

#include "base/atomic_file.h"
#include "model/metrics.h"

int ppb_write_radiance_csv(const char *path, const ppb_scene *sc, const ppb_result *rs, int n,
                           ppb_err *err)
{
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    fprintf(af.f, "method,surface,segment,s,theta_bin,phi_bin,radiance,stderr\n");
    for (int m = 0; m < n; m++) {
        const ppb_layout *lo = &rs[m].layout;
        for (int surf = 0; surf < lo->nsurf; surf++)
            for (int seg = 0; seg < lo->nseg[surf]; seg++) {
                double x, y;
                double s = ppb_scene_sample_point(sc, surf, seg, &x, &y);
                for (int b = 0; b < lo->nbins; b++) {
                    size_t c = ppb_cell(lo, surf, seg, b);
                    if (isnan(rs[m].radiance[c]))
                        continue; /* not computed (docs/reference.md: Outputs) */
                    fprintf(af.f, "%s,%s,%d,%.6g,%d,%d,%.10g,%.10g\n", rs[m].method,
                            ppb_surface_name(surf), seg, s, b / sc->nphi, b % sc->nphi,
                            rs[m].radiance[c], rs[m].se[c]);
                }
            }
    }
    return ppb_afile_commit(&af, err);
}

static int measured(const ppb_result *r, const ppb_result *ref, const char *skip)
{
    return r != ref && !(skip && strcmp(r->method, skip) == 0);
}

int ppb_write_rms_csv(const char *path, const ppb_scene *sc, const ppb_result *rs, int n,
                      const ppb_result *ref, const char *skip, ppb_err *err)
{
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    fprintf(af.f, "method,surface,segment,s,rms_rel,noise_rel,rms_excess\n");
    const ppb_layout *lo = &ref->layout;
    for (int m = 0; m < n; m++) {
        if (!measured(&rs[m], ref, skip))
            continue;
        for (int surf = 0; surf < lo->nsurf; surf++)
            for (int seg = 0; seg < lo->nseg[surf]; seg++) {
                double x, y;
                double s = ppb_scene_sample_point(sc, surf, seg, &x, &y);
                ppb_point p = {surf, seg};
                ppb_rms e = ppb_rms_points(&rs[m], ref, &p, 1);
                fprintf(af.f, "%s,%s,%d,%.6g,%.6g,%.6g,%.6g\n", rs[m].method,
                        ppb_surface_name(surf), seg, s, e.rms_rel, e.noise_rel, e.rms_excess);
            }
    }
    return ppb_afile_commit(&af, err);
}

int ppb_write_summary_csv(const char *path, const ppb_result *rs, int n, const ppb_result *ref,
                          const char *skip, ppb_err *err)
{
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    fprintf(af.f, "method,cell,rms_rel,noise_rel,rms_excess\n");
    const ppb_layout *lo = &ref->layout;
    int cap = lo->nseg[PPB_S1] > lo->nseg[PPB_S3] ? lo->nseg[PPB_S1] : lo->nseg[PPB_S3];
    ppb_point pts[cap > 2 ? cap : 2];
    for (int m = 0; m < n; m++) {
        if (!measured(&rs[m], ref, skip))
            continue;
        for (int cell = 0; cell < PPB_NCELLS; cell++) {
            int np = ppb_cell_points(lo, cell, pts, cap > 2 ? cap : 2);
            if (np == 0)
                continue;
            ppb_rms e = ppb_rms_points(&rs[m], ref, pts, np);
            fprintf(af.f, "%s,%s,%.6g,%.6g,%.6g\n", rs[m].method, ppb_cell_name(cell), e.rms_rel,
                    e.noise_rel, e.rms_excess);
        }
    }
    return ppb_afile_commit(&af, err);
}

int ppb_write_regions_csv(const char *path, const ppb_scene *sc, const ppb_result *rs, int n,
                          const ppb_result *ref, const char *skip, ppb_err *err)
{
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    fprintf(af.f, "method,region,rms_rel,noise_rel,rms_excess\n");
    const ppb_layout *lo = &ref->layout;
    int cap = lo->nseg[PPB_S1] > 1 ? lo->nseg[PPB_S1] : 1;
    ppb_point pts[cap];
    for (int m = 0; m < n; m++) {
        if (!measured(&rs[m], ref, skip))
            continue;
        for (int region = 0; region < PPB_NREGIONS; region++) {
            int np = ppb_region_points(sc, lo, region, pts, cap);
            if (np == 0)
                continue; /* slab mode, or a region no segment centre falls in */
            ppb_rms e = ppb_rms_points(&rs[m], ref, pts, np);
            fprintf(af.f, "%s,%s,%.6g,%.6g,%.6g\n", rs[m].method, ppb_region_name(region),
                    e.rms_rel, e.noise_rel, e.rms_excess);
        }
    }
    return ppb_afile_commit(&af, err);
}

/* One surface's Table 2 cell of one result, bin by bin: the mean over the cell's points and the
 * standard error of that mean (independent segments: sqrt(sum se^2) / n). */
static void write_angular_cell(FILE *f, const ppb_scene *sc, const ppb_result *r, int cell,
                               const char *surf)
{
    const ppb_layout *lo = &r->layout;
    int cap = lo->nseg[PPB_S1] > lo->nseg[PPB_S2] ? lo->nseg[PPB_S1] : lo->nseg[PPB_S2];
    ppb_point pts[cap > 0 ? cap : 1];
    int np = ppb_cell_points(lo, cell, pts, cap);
    for (int it = 0; np > 0 && it < sc->ntheta; it++)
        for (int ip = 0; ip < sc->nphi; ip++) {
            int b = ppb_bin_index(it, ip, sc->nphi);
            double sum = 0.0, var = 0.0;
            for (int i = 0; i < np; i++) {
                size_t c = ppb_cell(lo, pts[i].surf, pts[i].seg, b);
                sum += r->radiance[c];
                var += r->se[c] * r->se[c];
            }
            double theta = ppb_theta_bin_centre(it, sc->ntheta) * 180.0 / PPB_PI;
            double phi = ppb_phi_bin_centre(ip, sc->nphi) * 180.0 / PPB_PI;
            fprintf(f, "%s,%s,%d,%d,%.6g,%.6g,%.10g,%.6g\n", r->method, surf, it, ip, theta, phi,
                    sum / np, sqrt(var) / np);
        }
}

int ppb_write_angular_csv(const char *path, const ppb_scene *sc, const ppb_result *rs, int n,
                          ppb_err *err)
{
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    fprintf(af.f, "method,surface,theta_bin,phi_bin,theta_deg,phi_deg,radiance,se\n");
    for (int m = 0; m < n; m++) {
        write_angular_cell(af.f, sc, &rs[m], PPB_CELL_R_X0, "S1");
        write_angular_cell(af.f, sc, &rs[m], PPB_CELL_T_X0, "S2");
    }
    return ppb_afile_commit(&af, err);
}

int ppb_write_totals_csv(const char *path, const ppb_result *rs, int n, ppb_err *err)
{
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    fprintf(af.f, "method,R,T,sides,absorbed,ballistic,specular\n");
    for (int m = 0; m < n; m++) {
        ppb_totals t = rs[m].totals;
        ppb_totals_complete(&t);
        fprintf(af.f, "%s,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", rs[m].method, t.R, t.T, t.sides,
                t.absorbed, t.ballistic, t.specular);
    }
    return ppb_afile_commit(&af, err);
}
