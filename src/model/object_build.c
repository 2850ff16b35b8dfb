#include "model/object_build.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"
#include "base/file_read.h"
#include "kernels/ppb_object.h"

void ppb_object_free(ppb_object *o)
{
    free(o->mat);
    free(o->albedo_tex);
    o->mat = NULL, o->albedo_tex = NULL;
}

void ppb_mesh_free(ppb_mesh *m)
{
    free(m->v), free(m->t);
    memset(m, 0, sizeof *m);
}

/* path relative to the config's folder (an absolute path as it is). */
static void beside_config(const ppb_config *cfg, const char *path, char *out, size_t cap)
{
    const char *slash = strrchr(cfg->path, '/');
    if (path[0] == '/' || !slash)
        snprintf(out, cap, "%s", path);
    else
        snprintf(out, cap, "%.*s/%s", (int)(slash - cfg->path), cfg->path, path);
}

static int grow(void **p, int *cap, int need, size_t size)
{
    if (need <= *cap)
        return 0;
    int nc = *cap ? 2 * *cap : 1024;
    while (nc < need)
        nc *= 2;
    void *q = realloc(*p, (size_t)nc * size);
    if (!q)
        return -1;
    *p = q, *cap = nc;
    return 0;
}

/* One f line's vertex: the first number of "i", "i/t", "i//n" or "i/t/n" as a 0-based index
 * (negative: counted back from the last vertex read). -1 when it names no vertex. */
static int obj_index(const char *tok, int nv)
{
    char *end;
    long i = strtol(tok, &end, 10);
    if (end == tok || (*end && *end != '/'))
        return -1;
    long k = i > 0 ? i - 1 : nv + i;
    return i == 0 || k < 0 || k >= nv ? -1 : (int)k;
}

int ppb_mesh_read_obj(const char *path, ppb_mesh *m, ppb_err *err)
{
    memset(m, 0, sizeof *m);
    FILE *f = ppb_fopen_regular(path, (size_t)1 << 30, err);
    if (!f)
        return -1;
    char line[4096];
    int vcap = 0, tcap = 0, lineno = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        if (!strchr(line, '\n') && !feof(f)) {
            fclose(f), ppb_mesh_free(m);
            return ppb_fail(err, "%s:%d: a line longer than %zu characters", path, lineno,
                            sizeof line - 2);
        }
        char *save = NULL, *tok = strtok_r(line, " \t\r\n", &save);
        if (!tok)
            continue;
        if (strcmp(tok, "v") == 0) {
            double x[3];
            for (int k = 0; k < 3; k++) {
                char *s = strtok_r(NULL, " \t\r\n", &save), *end = NULL;
                x[k] = s ? strtod(s, &end) : NAN;
                if (!s || *end || !isfinite(x[k])) {
                    fclose(f), ppb_mesh_free(m);
                    return ppb_fail(err, "%s:%d: a vertex needs three finite coordinates", path,
                                    lineno);
                }
            }
            if (grow((void **)&m->v, &vcap, 3 * (m->nv + 1), sizeof *m->v))
                goto oom;
            memcpy(m->v + 3 * m->nv++, x, sizeof x);
        } else if (strcmp(tok, "f") == 0) {
            int idx[64], n = 0;
            for (char *s; (s = strtok_r(NULL, " \t\r\n", &save)); n++)
                if (n == 64 || (idx[n] = obj_index(s, m->nv)) < 0) {
                    if (n == 64) {
                        fclose(f), ppb_mesh_free(m);
                        return ppb_fail(err, "%s:%d: a face of more than 64 vertices", path,
                                        lineno);
                    }
                    fclose(f), ppb_mesh_free(m);
                    return ppb_fail(err, "%s:%d: face vertex '%.32s' names no vertex read so far",
                                    path, lineno, s);
                }
            if (n < 3) {
                fclose(f), ppb_mesh_free(m);
                return ppb_fail(err, "%s:%d: a face needs at least three vertices", path, lineno);
            }
            for (int k = 1; k + 1 < n; k++) {
                if (grow((void **)&m->t, &tcap, 3 * (m->nt + 1), sizeof *m->t))
                    goto oom;
                int *t = m->t + 3 * m->nt++;
                t[0] = idx[0], t[1] = idx[k], t[2] = idx[k + 1];
            }
        }
    }
    fclose(f);
    if (m->nt == 0) {
        ppb_mesh_free(m);
        return ppb_fail(err, "%s: no triangles (f lines)", path);
    }
    return 0;
oom:
    fclose(f), ppb_mesh_free(m);
    return ppb_fail(err, "%s: out of memory", path);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

void ppb_mesh_voxelize(const ppb_mesh *m, ppb_object *o, unsigned char mat)
{
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (int i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++)
            lo[k] = fmin(lo[k], m->v[3 * i + k]), hi[k] = fmax(hi[k], m->v[3 * i + k]);
    double ext[3] = {o->nx * o->voxel, o->ny * o->voxel, o->nz * o->voxel}, s = 1e300;
    for (int k = 0; k < 3; k++)
        if (hi[k] > lo[k])
            s = fmin(s, ext[k] / (hi[k] - lo[k]));
    /* Grid coordinates in voxels of a mesh point: x_grid = (s (x - centre) + ext / 2) / h. */
    double *xs = malloc((size_t)(m->nt + 1) * sizeof *xs);
    if (!xs)
        return;
    for (int kz = 0; kz < o->nz; kz++)
        for (int jy = 0; jy < o->ny; jy++) {
            /* The row's ray, along +x through the voxel centres, nudged by an irrational
             * fraction of a voxel so that it meets no vertex or edge of a mesh given in round
             * numbers (where the parity of the crossings would be ambiguous). */
            double y = (jy + 0.5 + 1.3e-7 * M_SQRT2) * o->voxel,
                   z = (kz + 0.5 + 1.7e-7 * M_PI) * o->voxel;
            int n = 0;
            for (int t = 0; t < m->nt; t++) {
                double p[3][3];
                for (int a = 0; a < 3; a++)
                    for (int k = 0; k < 3; k++)
                        p[a][k] = s * (m->v[3 * m->t[3 * t + a] + k] - 0.5 * (lo[k] + hi[k])) +
                                  0.5 * ext[k];
                /* The (y, z) point inside the triangle's projection: barycentric weights from
                 * the signed areas. */
                double d = (p[1][1] - p[0][1]) * (p[2][2] - p[0][2]) -
                           (p[2][1] - p[0][1]) * (p[1][2] - p[0][2]);
                if (d == 0)
                    continue;
                double b1 =
                    ((y - p[0][1]) * (p[2][2] - p[0][2]) - (p[2][1] - p[0][1]) * (z - p[0][2])) / d;
                double b2 =
                    ((p[1][1] - p[0][1]) * (z - p[0][2]) - (y - p[0][1]) * (p[1][2] - p[0][2])) / d;
                if (b1 < 0 || b2 < 0 || b1 + b2 > 1)
                    continue;
                xs[n++] = p[0][0] + b1 * (p[1][0] - p[0][0]) + b2 * (p[2][0] - p[0][0]);
            }
            qsort(xs, (size_t)n, sizeof *xs, cmp_double);
            /* A voxel centre is inside when an odd number of crossings lie before it. */
            for (int i = 0, c = 0; i < o->nx; i++) {
                double x = (i + 0.5) * o->voxel;
                while (c < n && xs[c] < x)
                    c++;
                if (c % 2)
                    o->mat[ppb_object_voxel(o, i, jy, kz)] = mat;
            }
        }
    free(xs);
}

int ppb_object_write_voxels(const ppb_object *o, const char *path, ppb_err *err)
{
    json_t *h = json_object(), *mats = json_array();
    json_object_set_new(h, "format", json_string("ppbench-voxels"));
    json_object_set_new(h, "version", json_integer(1));
    json_object_set_new(h, "nx", json_integer(o->nx));
    json_object_set_new(h, "ny", json_integer(o->ny));
    json_object_set_new(h, "nz", json_integer(o->nz));
    json_object_set_new(h, "voxel", json_real(o->voxel));
    for (int i = 1; i <= o->nmat; i++) {
        json_t *m = json_object();
        json_object_set_new(m, "sigma_t", json_real(o->material[i].sigma_t));
        json_object_set_new(m, "albedo", json_real(o->material[i].albedo));
        json_array_append_new(mats, m);
    }
    json_object_set_new(h, "materials", mats);
    char *text = json_dumps(h, JSON_COMPACT | JSON_REAL_PRECISION(17));
    json_decref(h);
    if (!text)
        return ppb_fail(err, "%s: out of memory for the header", path);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err)) {
        free(text);
        return -1;
    }
    size_t nvox = (size_t)o->nx * (size_t)o->ny * (size_t)o->nz;
    fprintf(af.f, "%s\n", text);
    free(text);
    fwrite(o->mat, 1, nvox, af.f);
    return ppb_afile_commit(&af, err);
}

static int header_int(json_t *h, const char *key, int lo, int hi, int *out)
{
    json_t *v = json_object_get(h, key);
    if (!json_is_integer(v) || json_integer_value(v) < lo || json_integer_value(v) > hi)
        return -1;
    *out = (int)json_integer_value(v);
    return 0;
}

static int header_real(json_t *h, const char *key, double lo, double hi, double *out)
{
    json_t *v = json_object_get(h, key);
    if (!json_is_number(v) || !(json_number_value(v) >= lo && json_number_value(v) <= hi))
        return -1;
    *out = json_number_value(v);
    return 0;
}

int ppb_object_read_voxels(const char *path, ppb_object *o, ppb_err *err)
{
    size_t len = 0;
    char *buf = ppb_read_file(path, &len);
    if (!buf)
        return ppb_fail(err, "%s: cannot read the voxel file (%s)", path,
                        errno ? strerror(errno) : "not a regular file");
    json_error_t je;
    json_t *h = json_loadb(buf, len, JSON_DISABLE_EOF_CHECK, &je);
    if (!h || !json_is_object(h)) {
        json_decref(h), free(buf);
        return ppb_fail(err, "%s: line %d: the header is no JSON object: %s", path, je.line,
                        h ? "not an object" : je.text);
    }
    size_t at = (size_t)je.position;
    json_t *fmt = json_object_get(h, "format"), *mats = json_object_get(h, "materials");
    int nx, ny, nz, version;
    double voxel;
    const char *bad = NULL;
    if (!json_is_string(fmt) || strcmp(json_string_value(fmt), "ppbench-voxels") != 0)
        bad = "format is not \"ppbench-voxels\"";
    else if (header_int(h, "version", 1, 1, &version))
        bad = "version is not 1";
    else if (header_int(h, "nx", 1, 512, &nx) || header_int(h, "ny", 1, 512, &ny) ||
             header_int(h, "nz", 1, 512, &nz))
        bad = "nx, ny, nz must be integers in [1, 512]";
    else if (header_real(h, "voxel", 1e-4, 100, &voxel))
        bad = "voxel must be a number in [1e-4, 100]";
    else if (!json_is_array(mats) || json_array_size(mats) < 1 ||
             json_array_size(mats) >= PPB_OBJ_MAX_MAT)
        bad = "materials must be an array of 1 to 7 {sigma_t, albedo}";
    ppb_object_material mat[PPB_OBJ_MAX_MAT] = {{0, 0}};
    for (size_t i = 0; !bad && i < json_array_size(mats); i++)
        if (header_real(json_array_get(mats, i), "sigma_t", 1e-3, 1000, &mat[i + 1].sigma_t) ||
            header_real(json_array_get(mats, i), "albedo", 0, 1, &mat[i + 1].albedo))
            bad = "a material needs sigma_t in [1e-3, 1000] and albedo in [0, 1]";
    int nmat = bad ? 0 : (int)json_array_size(mats);
    json_decref(h);
    if (bad) {
        free(buf);
        return ppb_fail(err, "%s: header: %s", path, bad);
    }
    size_t nvox = (size_t)nx * (size_t)ny * (size_t)nz;
    if (at >= len || buf[at] != '\n' || len - at - 1 != nvox) {
        free(buf);
        return ppb_fail(err, "%s: after the header's newline %zu bytes, not nx ny nz = %zu", path,
                        at < len ? len - at - 1 : 0, nvox);
    }
    unsigned char *v = malloc(nvox);
    if (!v) {
        free(buf);
        return ppb_fail(err, "%s: out of memory for %zu voxels", path, nvox);
    }
    memcpy(v, buf + at + 1, nvox);
    free(buf);
    for (size_t i = 0; i < nvox; i++)
        if (v[i] > nmat) {
            int bad_mat = v[i];
            free(v);
            return ppb_fail(err, "%s: voxel %zu holds material %d; the header has %d", path, i,
                            bad_mat, nmat);
        }
    free(o->mat);
    o->mat = v;
    o->nx = nx, o->ny = ny, o->nz = nz, o->voxel = voxel, o->nmat = nmat;
    memcpy(o->material, mat, sizeof mat);
    return 0;
}

int ppb_object_build(const ppb_config *cfg, ppb_object *o, ppb_err *err)
{
    const ppb_object_settings *s = &cfg->object;
    memset(o, 0, sizeof *o);
    snprintf(o->name, sizeof o->name, "%.63s", cfg->name);
    o->nx = s->nx, o->ny = s->ny, o->nz = s->nz, o->voxel = s->voxel;
    o->nmat = 1;
    o->material[1].sigma_t = cfg->scene.sigma_t;
    o->material[1].albedo = cfg->scene.albedo;
    o->g = cfg->scene.g, o->n = cfg->scene.n;
    double w[3];
    ppb_obj_dir(s->light_theta, s->light_phi, w);
    for (int k = 0; k < 3; k++)
        o->light_dir[k] = -w[k];
    ppb_obj_dir(s->camera_theta, s->camera_phi, w);
    for (int k = 0; k < 3; k++)
        o->view_dir[k] = -w[k];
    o->img_w = s->image_w, o->img_h = s->image_h;
    o->ntheta = cfg->scene.ntheta, o->nphi = cfg->scene.nphi;
    o->patch = s->patch;
    char path[2048];
    if (s->shape == PPB_OBJ_FILE) {
        if (!s->voxels[0])
            return ppb_config_key_fail(cfg, "object", "voxels", err,
                                       "shape = file needs a voxel file");
        beside_config(cfg, s->voxels, path, sizeof path);
        ppb_err e2;
        if (ppb_object_read_voxels(path, o, &e2))
            return ppb_config_key_fail(cfg, "object", "voxels", err, "%s", e2.msg);
        return 0;
    }
    size_t nvox = (size_t)o->nx * (size_t)o->ny * (size_t)o->nz;
    o->mat = calloc(nvox, 1);
    if (!o->mat)
        return ppb_fail(err, "%s: out of memory for %zu voxels", o->name, nvox);
    int nmin = o->nx < o->ny ? o->nx : o->ny;
    nmin = nmin < o->nz ? nmin : o->nz;
    if (s->shape == PPB_OBJ_MESH) {
        if (!s->mesh[0]) {
            ppb_object_free(o);
            return ppb_config_key_fail(cfg, "object", "mesh", err,
                                       "shape = mesh needs a mesh file");
        }
        beside_config(cfg, s->mesh, path, sizeof path);
        ppb_mesh m;
        ppb_err e2;
        if (ppb_mesh_read_obj(path, &m, &e2)) {
            ppb_object_free(o);
            return ppb_config_key_fail(cfg, "object", "mesh", err, "%s", e2.msg);
        }
        ppb_mesh_voxelize(&m, o, 1);
        ppb_mesh_free(&m);
    } else {
        /* Box and yokan fill the grid; the sphere is its inscribed ball (radius nmin h / 2 about
         * the grid's centre); a voxel is in a ball when its centre is. */
        double r = 0.5 * nmin, r2 = r * r;
        for (int k = 0; k < o->nz; k++)
            for (int j = 0; j < o->ny; j++)
                for (int i = 0; i < o->nx; i++) {
                    double x = i + 0.5 - 0.5 * o->nx, y = j + 0.5 - 0.5 * o->ny,
                           z = k + 0.5 - 0.5 * o->nz;
                    int in = s->shape != PPB_OBJ_SPHERE || x * x + y * y + z * z <= r2;
                    o->mat[ppb_object_voxel(o, i, j, k)] = (unsigned char)in;
                }
        if (s->shape == PPB_OBJ_YOKAN) {
            /* The chestnut: a ball of material 2 (Shinya et al. 2009, Fig. 9's yokan). */
            o->nmat = 2;
            o->material[2].sigma_t = s->inc_sigma_t;
            o->material[2].albedo = s->inc_albedo;
            double ri = s->inc_radius * nmin, cx = s->inc_x * o->nx, cy = s->inc_y * o->ny,
                   cz = s->inc_z * o->nz;
            for (int k = 0; k < o->nz; k++)
                for (int j = 0; j < o->ny; j++)
                    for (int i = 0; i < o->nx; i++) {
                        double x = i + 0.5 - cx, y = j + 0.5 - cy, z = k + 0.5 - cz;
                        if (x * x + y * y + z * z <= ri * ri)
                            o->mat[ppb_object_voxel(o, i, j, k)] = 2;
                    }
        }
    }
    size_t med = 0;
    for (size_t i = 0; i < nvox; i++)
        med += o->mat[i] != 0;
    if (!med) {
        ppb_object_free(o);
        return ppb_config_key_fail(cfg, "object", "shape", err,
                                   "the object holds no medium voxel (a grid too coarse for it?)");
    }
    return 0;
}
