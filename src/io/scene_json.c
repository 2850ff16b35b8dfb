#include "io/scene_json.h"

#include <jansson.h>
#include <math.h>
#include <string.h>

#include "kernels/ppb_bin_samples.h"
#include "base/atomic_file.h"
#include "model/scene.h"

/* The units and conventions of the conventions of docs/reference.md (Medium to Metrics) in words,
 * for a reader who has only this file. */
static const char *const conventions[][2] = {
    {"lengths", "in the config's length unit: mean free paths of the left medium (sigma_t = 1 "
                "there by default), or mm for a measured material ([experiment] unit = mm), "
                "every coefficient per that unit; positions (x, y) in the tube's cross-section, "
                "z along the tube (uniform)"},
    {"geometry", "tube: x in [-W/2, W/2], y in [-H, 0], infinite along z; S1 top (y = 0), S2 "
                 "bottom (y = -H), S3 left (x = -W/2), S4 right (x = W/2); slab: only S1 and S2, "
                 "W infinite, segment 0 and s = 0"},
    {"light", "a collimated beam w_L = (sin theta_L, -cos theta_L, 0) into S1, irradiance 1 on a "
              "plane perpendicular to it (S1 receives cos theta_L per unit area); only S1 is lit, "
              "and with the shadow step only x < step_x"},
    {"medium", "sigma_t, albedo, Henyey-Greenstein g, piecewise constant: the *_right values hold "
               "for x >= step_x under the density or albedo step; n is the medium's refractive "
               "index, 1 outside (n = 1: matched boundaries, no reflection or refraction)"},
    {"radiance", "outgoing radiance of SCATTERED light only, divided by the beam's irradiance "
                 "E_perp: units 1/sr; the unscattered beam is not radiance"},
    {"frame", "at each sample point: n the outward normal, b = +z, t = n x b (given per point); "
              "a direction is w = cos(theta) n + sin(theta) (cos(phi) t + sin(phi) b)"},
    {"bins", "bin = theta_bin * phi_bins + phi_bin; theta edges at sin^2(theta) = k / "
             "theta_bins (equal projected solid angle), phi folded to [0, pi] (the set-up is "
             "symmetric in z: a bin holds phi and -phi); w_k = projected solid angle of the bin "
             "including both halves"},
    {"bin_value", "a bin's value is its AVERAGE radiance over the segment and over the bin's "
                  "directions weighted by projected solid angle (uniform in sin^2(theta) and "
                  "phi): energy through the segment within the bin / (segment length x w_k) per "
                  "unit length in z; bins[].directions are the n x n directions (samples_dir) "
                  "the built-in deterministic methods average, in the local frame (n, t, b), "
                  "bins[].weights their weights (mean 1: the bin's value is the weighted "
                  "mean; the last theta row's samples are graded toward the tangent plane)"},
    {"metrics", "rms_rel(m; P) = sqrt(sum w_k (L_m - L_r)^2 / sum w_k L_r^2) over points P and "
                "bins k, L_r the Monte Carlo reference; noise_rel from its standard errors; "
                "rms_excess = sqrt(max(0, rms_rel^2 - noise_rel^2))"},
    {"output", "the method writes {out}/radiance.csv with the header "
               "method,surface,segment,s,theta_bin,phi_bin,radiance,stderr and one row per "
               "(sample point, bin) of this file: radiance finite and >= 0, stderr 0 for a "
               "deterministic method; totals.csv (method,R,T,sides,absorbed,ballistic) is "
               "optional"},
};

static const char *step_name(int step)
{
    switch (step) {
    case PPB_STEP_DENSITY:
        return "density";
    case PPB_STEP_ALBEDO:
        return "albedo";
    case PPB_STEP_SHADOW:
        return "shadow";
    default:
        return "none";
    }
}

/* Sets key to val (NULL: a json_pack failed); 0 on success. */
static int add(json_t *obj, const char *key, json_t *val)
{
    return val ? json_object_set_new(obj, key, val) : -1;
}

/* "+ 0.0" makes a negative zero (t = -n_x with n_x = 0) print as 0. */
static json_t *vec(double a, double b, double c)
{
    return json_pack("[fff]", a, b, c);
}

static json_t *sample_points(const ppb_scene *sc, const ppb_layout *lo)
{
    json_t *pts = json_array();
    for (int surf = 0; pts && surf < lo->nsurf; surf++)
        for (int seg = 0; seg < lo->nseg[surf]; seg++) {
            double x, y;
            double s = ppb_scene_sample_point(sc, surf, seg, &x, &y);
            double len = ppb_scene_segment_length(sc, surf);
            int slab = sc->geometry == PPB_GEOM_SLAB;
            json_t *p = json_pack("{sssisisfsf}", "surface", ppb_surface_name(surf), "segment", seg,
                                  "row", lo->offset[surf] + seg, "s", s, "length", len);
            if (!p || add(p, "position", vec(x, y, 0.0)) ||
                add(p, "normal", vec(ppb_normal_x(surf), ppb_normal_y(surf), 0.0)) ||
                add(p, "tangent", vec(ppb_tangent_x(surf) + 0.0, ppb_tangent_y(surf) + 0.0, 0.0)) ||
                add(p, "s_range",
                    slab ? json_null() : json_pack("[ff]", s - 0.5 * len, s + 0.5 * len)) ||
                json_array_append_new(pts, p)) {
                json_decref(p);
                json_decref(pts);
                return NULL;
            }
        }
    return pts;
}

/* A direction of bin (it, ip) at (u, v) in the local frame (n, t, b), from the S1 frame of
 * ppb_bin_direction (the frame is the same on every surface). */
static void local_dir(int it, int ip, double u, double v, const ppb_scene *sc, double w[3])
{
    double wx, wy, wz;
    ppb_bin_direction(PPB_S1, it, ip, u, v, sc->ntheta, sc->nphi, &wx, &wy, &wz);
    w[0] = wx * ppb_normal_x(PPB_S1) + wy * ppb_normal_y(PPB_S1);
    w[1] = wx * ppb_tangent_x(PPB_S1) + wy * ppb_tangent_y(PPB_S1);
    w[2] = wz;
}

static json_t *bins(const ppb_scene *sc, int n)
{
    json_t *arr = json_array();
    double wk = ppb_bin_proj_solid_angle(sc->ntheta, sc->nphi);
    for (int it = 0; arr && it < sc->ntheta; it++)
        for (int ip = 0; ip < sc->nphi; ip++) {
            /* Edges from the bin's own corner directions: theta from the normal component at
             * u = 0 and 1, phi from (t, b) at v = 0 and 1 on the outer edge (u = 1). */
            double lo[3], hi[3], p0[3], p1[3];
            local_dir(it, ip, 0.0, 0.0, sc, lo);
            local_dir(it, ip, 1.0, 0.0, sc, hi);
            local_dir(it, ip, 1.0, 0.0, sc, p0);
            local_dir(it, ip, 1.0, 1.0, sc, p1);
            double cx, cy, cz; /* the index as the tallies compute it, from the centre */
            ppb_bin_direction(PPB_S1, it, ip, 0.5, 0.5, sc->ntheta, sc->nphi, &cx, &cy, &cz);
            int index = ppb_dir_bin(PPB_S1, cx, cy, cz, sc->ntheta, sc->nphi);
            /* The built-in methods' samples and weights (ppb_bin_sample_u, reference: Bins). */
            json_t *dirs = json_array(), *wts = json_array();
            int ok = dirs && wts;
            for (int a = 0; ok && a < n; a++)
                for (int b = 0; ok && b < n; b++) {
                    double w[3], u, weight = ppb_bin_sample_u(it, a, n, sc->ntheta, &u);
                    local_dir(it, ip, u, (b + 0.5) / n, sc, w);
                    ok = !json_array_append_new(dirs, vec(w[0], w[1], w[2])) &&
                         !json_array_append_new(wts, json_real(weight));
                }
            json_t *bn = ok ? json_pack("{sisisis[ff]s[ff]sfsfsf}", "index", index, "theta_bin", it,
                                        "phi_bin", ip, "theta_edges", acos(lo[0]), acos(hi[0]),
                                        "phi_edges", atan2(p0[2], p0[1]), atan2(p1[2], p1[1]),
                                        "theta_centre", ppb_theta_bin_centre(it, sc->ntheta),
                                        "phi_centre", ppb_phi_bin_centre(ip, sc->nphi), "w_k", wk)
                            : NULL;
            /* json_object_set_new takes its value's reference even when it fails. */
            if (!bn || json_object_set_new(bn, "directions", json_incref(dirs)) ||
                json_object_set_new(bn, "weights", json_incref(wts)) ||
                json_array_append_new(arr, json_incref(bn))) {
                json_decref(dirs);
                json_decref(wts);
                json_decref(bn);
                json_decref(arr);
                return NULL;
            }
            json_decref(dirs);
            json_decref(wts);
            json_decref(bn);
        }
    return arr;
}

static json_t *scene_doc(const ppb_config *cfg)
{
    const ppb_scene *sc = &cfg->scene;
    ppb_layout lo = ppb_scene_layout(sc);
    double wl[3], lit_lo, lit_hi; /* S1's lit part (reference: Light) */
    ppb_scene_light_dir(sc, wl);
    ppb_scene_lit_range(sc, &lit_lo, &lit_hi);
    int tube = sc->geometry == PPB_GEOM_TUBE;
    json_t *doc = json_pack(
        "{sssisssss{sssfsfsisi}}", "format", "ppbench-scene", "version", PPB_SCENE_JSON_VERSION,
        "experiment", cfg->name, "config", cfg->path, "geometry", "kind", tube ? "tube" : "slab",
        "width", tube ? sc->width : 0.0, "height", sc->height, "segments_top",
        tube ? sc->segments_top : 1, "segments_side", tube ? sc->segments_side : 0);
    json_t *conv = json_object();
    for (size_t i = 0; conv && i < sizeof conventions / sizeof conventions[0]; i++)
        if (add(conv, conventions[i][0], json_string(conventions[i][1]))) {
            json_decref(conv);
            conv = NULL;
        }
    if (!doc || add(doc, "conventions", conv) ||
        add(doc, "medium",
            json_pack("{sfsfsfsssssfsfsfsf}", "sigma_t", sc->sigma_t, "albedo", sc->albedo, "g",
                      sc->g, "phase", "Henyey-Greenstein", "step", step_name(sc->step), "step_x",
                      sc->step_x, "sigma_t_right", sc->sigma_t_right, "albedo_right",
                      sc->albedo_right, "n", sc->n)) ||
        add(doc, "light",
            json_pack("{sfsfsfs[fff]sfsfs[ff]sb}", "theta_deg", sc->theta_deg, "irradiance_perp",
                      1.0, "irradiance_s1", ppb_scene_cos_theta_l(sc), "direction", wl[0], wl[1],
                      wl[2], "lit_width", ppb_scene_lit_width(sc), "power_in",
                      ppb_scene_power_in(sc), "lit", lit_lo, lit_hi, "line",
                      ppb_scene_lit_line(sc))) ||
        add(doc, "averaging",
            json_pack("{sisi}", "directions_per_bin", cfg->samples_dir * cfg->samples_dir,
                      "points_per_segment", cfg->samples_seg)) ||
        add(doc, "layout",
            json_pack("{sisisisi}", "surfaces", lo.nsurf, "bins", lo.nbins, "theta_bins",
                      sc->ntheta, "phi_bins", sc->nphi)) ||
        add(doc, "sample_points", sample_points(sc, &lo)) ||
        add(doc, "bins", bins(sc, cfg->samples_dir))) {
        json_decref(doc);
        return NULL;
    }
    return doc;
}

int ppb_scene_json_write(const ppb_config *cfg, const char *path, ppb_err *err)
{
    json_t *doc = scene_doc(cfg);
    if (!doc)
        return ppb_fail(err, "%s: could not build the scene document (out of memory)", path);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err)) {
        json_decref(doc);
        return -1;
    }
    int rc = json_dumpf(doc, af.f, JSON_INDENT(1) | JSON_REAL_PRECISION(17) | JSON_PRESERVE_ORDER);
    json_decref(doc);
    if (rc != 0 || fputc('\n', af.f) == EOF) {
        ppb_afile_abort(&af);
        return ppb_fail(err, "%s: write failed", path);
    }
    return ppb_afile_commit(&af, err);
}
