#include "model/config.h"

#include <ctype.h>
#include <errno.h>
#include <ini.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "kernels/march_params.h"

typedef enum { K_INT, K_LLONG, K_REAL, K_ENUM, K_NAME, K_PATH, K_METHODS } key_type;

/* What `ppbench keys` calls each type. */
static const char *const type_names[] = {
    [K_INT] = "integer",
    [K_LLONG] = "integer",
    [K_REAL] = "real",
    [K_ENUM] = "one of",
    [K_NAME] = "name",
    [K_PATH] = "path",
    [K_METHODS] = "list of method ids",
};

/* The names of an enum key's values, each paired with its C enum value, so that parsing,
 * printing and `ppbench keys` never depend on the order of the enum. Ends at name NULL; the
 * order here is the order `ppbench keys` lists them. */
typedef struct enum_name {
    int value;
    const char *name;
} enum_name;

static const enum_name geometry_names[] = {
    {PPB_GEOM_TUBE, "tube"}, {PPB_GEOM_SLAB, "slab"}, {0, NULL}};
static const enum_name step_names[] = {{PPB_STEP_NONE, "none"},
                                       {PPB_STEP_DENSITY, "density"},
                                       {PPB_STEP_ALBEDO, "albedo"},
                                       {PPB_STEP_SHADOW, "shadow"},
                                       {0, NULL}};
static const enum_name table_names[] = {{PPB_TABLE_R, "R"}, {PPB_TABLE_S, "S"}, {0, NULL}};

/* An enum key is stored as an int (ppb_scene.geometry is a ppb_geometry). */
_Static_assert(sizeof(ppb_geometry) == sizeof(int), "enum keys are stored as int");

typedef struct key_def {
    const char *section, *key;
    key_type type;
    size_t offset;
    double min, max;
    const char *def;
    const enum_name *enums; /* K_ENUM: the value names */
    const char *help;
} key_def;

#define F(field) offsetof(ppb_config, field)
/* The one table: parsing, defaults, ranges, sweeps and configs/README.md all come from it. */
static const key_def keys[] = {
    {"experiment", "name", K_NAME, F(name), 0, 0, "", NULL,
     "experiment name; default: the config file's base name"},
    {"experiment", "geometry", K_ENUM, F(scene.geometry), 0, 0, "tube", geometry_names,
     "the tube of SPEC.md 2, or the infinite slab of thickness `height`"},
    {"experiment", "methods", K_METHODS, F(methods), 0, 0, "mc, pp, ss, mp, mp+ss", NULL,
     "method ids, comma-separated (`ppbench --help` lists them)"},
    {"tube", "width", K_REAL, F(scene.width), 0.01, 1000, "10", NULL, "W, mfp (ignored by slab)"},
    {"tube", "height", K_REAL, F(scene.height), 1e-3, 1000, "3", NULL,
     "H, mfp; the slab thickness in slab mode"},
    {"tube", "segments_top", K_INT, F(scene.segments_top), 1, 4096, "128", NULL,
     "segments of S1 and S2"},
    {"tube", "segments_side", K_INT, F(scene.segments_side), 1, 4096, "36", NULL,
     "segments of S3 and S4"},
    {"medium", "sigma_t", K_REAL, F(scene.sigma_t), 1e-3, 1000, "1", NULL,
     "extinction, 1/mfp (left of the step)"},
    {"medium", "albedo", K_REAL, F(scene.albedo), 0, 1, "0.95", NULL,
     "single-scattering albedo (left of the step)"},
    {"medium", "g", K_REAL, F(scene.g), -0.95, 0.95, "0", NULL, "Henyey-Greenstein asymmetry"},
    {"medium", "step", K_ENUM, F(scene.step), 0, 0, "none", step_names,
     "what changes at x = step_x (tube only)"},
    {"medium", "step_x", K_REAL, F(scene.step_x), -500, 500, "0", NULL,
     "position of the step, mfp; inside the tube"},
    {"medium", "sigma_t_right", K_REAL, F(scene.sigma_t_right), 1e-3, 1000, "0.5", NULL,
     "extinction for x >= step_x (step = density)"},
    {"medium", "albedo_right", K_REAL, F(scene.albedo_right), 0, 1, "0.475", NULL,
     "albedo for x >= step_x (step = albedo)"},
    {"light", "theta_deg", K_REAL, F(scene.theta_deg), 0, 89, "0", NULL,
     "incidence angle from the S1 normal, degrees"},
    {"bins", "theta", K_INT, F(scene.ntheta), 1, 64, "8", NULL,
     "theta bins (equal projected solid angle)"},
    {"bins", "phi", K_INT, F(scene.nphi), 1, 64, "8", NULL, "phi bins over [0, 180] deg"},
    {"bins", "samples_dir", K_INT, F(samples_dir), 1, 64, "4", NULL,
     "deterministic methods: n x n directions averaged per bin"},
    {"bins", "samples_seg", K_INT, F(samples_seg), 1, 64, "4", NULL,
     "deterministic methods: points averaged per segment"},
    {"mc", "photons", K_LLONG, F(mc.photons), 1, 1e13, "1e7", NULL, "photon budget"},
    {"mc", "batches", K_INT, F(mc.batches), 2, 1024, "16", NULL,
     "independent batches for standard errors"},
    {"mc", "seed", K_LLONG, F(mc.seed), 0, 9.2e18, "1", NULL, "random seed (Philox key)"},
    {"mc", "workgroup", K_INT, F(mc.workgroup), 0, 4096, "0", NULL,
     "work-group size, 0 = ppbench picks (64); results do not depend on it"},
    {"mc", "chunk", K_LLONG, F(mc.chunk), 0, 1e12, "0", NULL,
     "photons per kernel launch, 0 = sized to the device (results do not depend on it)"},
    {"mc", "first", K_LLONG, F(mc.first), 0, 1e13, "0", NULL,
     "index of the first photon (a shard of one run)"},
    {"mc", "target_noise", K_REAL, F(mc.target_noise), 0, 1, "0", NULL,
     "stop when noise_rel at the x = 0 cells falls below this; 0 = run the whole budget"},
    {"pp", "directions", K_INT, F(pp.directions), 2, 4000, "334", NULL,
     "direction cells per hemisphere (M = 2 x directions)"},
    {"pp", "modes", K_INT, F(pp.modes), 0, 8000, "0", NULL,
     "n_e: modes kept by the march, 0 = all"},
    {"pp", "table", K_ENUM, F(pp.table), 0, 0, "S", table_names,
     "integral table of the march: R (Eq. 15) or S (Eq. 16-17)"},
    {"pp", "step", K_REAL, F(pp.step), 1e-4, 1, "0.05", NULL, "ray-march step, mfp"},
    {"pp", "albedos", K_INT, F(pp.albedos), 2, 64, "9", NULL,
     "albedo nodes of the tables (Sec. 3.3)"},
    {"pp", "map_res", K_INT, F(pp.map_res), 1, 4096, "64", NULL,
     "cells per mfp of the optical-depth and albedo maps"},
    {"mp", "pairs", K_INT, F(mp.pairs), 0, 200, "10", NULL,
     "dipole pairs beyond the first (0 = dipole)"},
    {"mp", "samples", K_INT, F(mp.samples), 1, 256, "16", NULL,
     "quadrature nodes per mfp over the lit strip"},
    {"output", "dir", K_PATH, F(out_dir), 0, 0, "", NULL,
     "output directory; default results/<name>"},
    {"run", "memory_limit", K_REAL, F(memory_limit), 0, 1e6, "0", NULL,
     "GB a method may allocate, estimated before it allocates (over it: refused); 0 = half "
     "the machine's memory"},
};
#undef F
#define NKEYS ((int)(sizeof keys / sizeof keys[0]))
_Static_assert(sizeof keys / sizeof keys[0] <= PPB_MAX_KEYS, "raise PPB_MAX_KEYS");

static int find_key(const char *section, const char *key)
{
    for (int i = 0; i < NKEYS; i++)
        if (strcmp(keys[i].section, section) == 0 && strcmp(keys[i].key, key) == 0)
            return i;
    return -1;
}

static int section_known(const char *section)
{
    for (int i = 0; i < NKEYS; i++)
        if (strcmp(keys[i].section, section) == 0)
            return 1;
    return 0;
}

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    char *e = s + strlen(s);
    while (e > s && isspace((unsigned char)e[-1]))
        *--e = '\0';
    return s;
}

/* A number, with the key's type and range; integers accept "1e7" when exact. */
static int parse_number(const key_def *k, const char *text, double *v, char *why, size_t n)
{
    char *end;
    errno = 0;
    double x = strtod(text, &end);
    if (end == text || *trim(end) != '\0' || errno == ERANGE || !isfinite(x)) {
        snprintf(why, n, "'%s' is not a number", text);
        return -1;
    }
    if ((k->type == K_INT || k->type == K_LLONG) && x != floor(x)) {
        snprintf(why, n, "'%s' is not an integer", text);
        return -1;
    }
    if (x < k->min || x > k->max) {
        snprintf(why, n, "%s is out of range [%g, %g]", text, k->min, k->max);
        return -1;
    }
    *v = x;
    return 0;
}

/* "a, b, c" or "start:stop:step" (inclusive, step > 0), or a mix. */
static int parse_list(const key_def *k, const char *text, double *vals, int *count, char *why,
                      size_t n)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", text);
    *count = 0;
    char *rest = buf;
    for (char *tok = strsep(&rest, ","); tok; tok = strsep(&rest, ",")) {
        tok = trim(tok);
        if (!*tok) {
            snprintf(why, n, "empty value in list '%s'", text);
            return -1;
        }
        char *c1 = strchr(tok, ':');
        if (!c1) {
            if (*count >= PPB_MAX_LIST || parse_number(k, tok, &vals[*count], why, n))
                return *count >= PPB_MAX_LIST ? (snprintf(why, n, "list too long"), -1) : -1;
            (*count)++;
            continue;
        }
        char *c2 = strchr(c1 + 1, ':');
        if (!c2) {
            snprintf(why, n, "range '%s' must read start:stop:step", tok);
            return -1;
        }
        *c1 = *c2 = '\0';
        double a, b, st;
        key_def wide = *k;
        wide.min = -INFINITY;
        wide.max = INFINITY;
        if (parse_number(k, trim(tok), &a, why, n) || parse_number(k, trim(c1 + 1), &b, why, n) ||
            parse_number(&wide, trim(c2 + 1), &st, why, n))
            return -1;
        if (!(st > 0) || b < a) {
            snprintf(why, n, "range %g:%g:%g needs step > 0 and stop >= start", a, b, st);
            return -1;
        }
        long long m = (long long)floor((b - a) / st * (1 + 1e-12)) + 1;
        if (*count + m > PPB_MAX_LIST) {
            snprintf(why, n, "range %g:%g:%g has more than %d values", a, b, st, PPB_MAX_LIST);
            return -1;
        }
        for (long long i = 0; i < m; i++)
            vals[(*count)++] = a + (double)i * st;
    }
    if (*count == 0) {
        snprintf(why, n, "empty value");
        return -1;
    }
    return 0;
}

static void store_number(ppb_config *cfg, const key_def *k, double v)
{
    char *p = (char *)cfg + k->offset;
    if (k->type == K_INT)
        *(int *)p = (int)v;
    else if (k->type == K_LLONG)
        *(long long *)p = (long long)v;
    else
        *(double *)p = v;
}

/* "a|b|c": the names of an enum key, as errors and `ppbench keys` show them. */
static void enum_list(const enum_name *e, char *buf, size_t cap)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int j = 0; e[j].name && len < cap; j++)
        len += (size_t)snprintf(buf + len, cap - len, "%s%s", j ? "|" : "", e[j].name);
}

static const char *enum_value_name(const enum_name *e, int value)
{
    for (int j = 0; e[j].name; j++)
        if (e[j].value == value)
            return e[j].name;
    return "?";
}

static int parse_enum(const key_def *k, const char *text, int *out, char *why, size_t n)
{
    for (int j = 0; k->enums[j].name; j++)
        if (strcasecmp(k->enums[j].name, text) == 0) {
            *out = k->enums[j].value;
            return 0;
        }
    char names[256];
    enum_list(k->enums, names, sizeof names);
    snprintf(why, n, "'%s' is not one of %s", text, names);
    return -1;
}

/* Method ids as a list of strings: whether each names a method is the method registry's
 * business (ppb_methods_check), checked once the config is loaded. */
static int parse_methods(ppb_config *cfg, const char *text, char *why, size_t n)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", text);
    cfg->nmethods = 0;
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok;
         tok = strtok_r(NULL, ",", &save)) {
        tok = trim(tok);
        if (strlen(tok) >= sizeof cfg->methods[0]) {
            snprintf(why, n, "method id '%s' is longer than %zu characters", tok,
                     sizeof cfg->methods[0] - 1);
            return -1;
        }
        for (int i = 0; i < cfg->nmethods; i++)
            if (strcmp(cfg->methods[i], tok) == 0) {
                snprintf(why, n, "method '%s' listed twice", tok);
                return -1;
            }
        if (cfg->nmethods == PPB_MAX_METHODS) {
            snprintf(why, n, "more than %d methods", PPB_MAX_METHODS);
            return -1;
        }
        snprintf(cfg->methods[cfg->nmethods++], sizeof cfg->methods[0], "%s", tok);
    }
    if (cfg->nmethods == 0) {
        snprintf(why, n, "no method given");
        return -1;
    }
    return 0;
}

static int parse_string(const key_def *k, char *dst, size_t cap, const char *text, char *why,
                        size_t n)
{
    if (strlen(text) >= cap) {
        snprintf(why, n, "longer than %zu characters", cap - 1);
        return -1;
    }
    for (const char *c = text; k->type == K_NAME && *c; c++)
        if (!isalnum((unsigned char)*c) && !strchr("_-.+", *c)) {
            snprintf(why, n, "'%s' may hold only letters, digits and _-.+", text);
            return -1;
        }
    snprintf(dst, cap, "%s", text);
    return 0;
}

/* Sets key i from text; a list on a numeric key becomes an axis of grid (NULL: refused). */
static int set_key(ppb_config *cfg, ppb_grid *grid, int i, const char *text, char *why, size_t n)
{
    const key_def *k = &keys[i];
    char *p = (char *)cfg + k->offset;
    switch (k->type) {
    case K_ENUM:
        return parse_enum(k, text, (int *)p, why, n);
    case K_NAME:
        return parse_string(k, p, sizeof cfg->name, text, why, n);
    case K_PATH:
        return parse_string(k, p, sizeof cfg->out_dir, text, why, n);
    case K_METHODS:
        return parse_methods(cfg, text, why, n);
    default:
        break;
    }
    double vals[PPB_MAX_LIST];
    int count;
    if (parse_list(k, text, vals, &count, why, n))
        return -1;
    store_number(cfg, k, vals[0]);
    if (count == 1)
        return 0;
    if (!grid) {
        snprintf(why, n, "a list (a sweep) is not accepted here");
        return -1;
    }
    if (grid->naxes == PPB_MAX_AXES) {
        snprintf(why, n, "more than %d swept keys", PPB_MAX_AXES);
        return -1;
    }
    if (ppb_grid_add(grid, i, vals, count)) {
        snprintf(why, n, "out of memory");
        return -1;
    }
    return 0;
}

/* inih reports the line of the first error but passes no line to the handler (the system
 * library is built without INI_HANDLER_LINENO); reading through this counter gives the line
 * inih is on, which inih itself counts once per read. */
typedef struct line_reader {
    FILE *f;
    int line;
} line_reader;

static char *read_line(char *str, int num, void *stream)
{
    line_reader *r = stream;
    char *s = fgets(str, num, r->f);
    r->line += s != NULL;
    return s;
}

typedef struct parse_state {
    ppb_config *cfg;
    ppb_grid *grid;
    line_reader *in;
    char seen[PPB_MAX_KEYS];
    int err_line; /* line of the first key error, 0 = none */
    char why[1200];
    char what[128];
} parse_state;

static int on_key(void *user, const char *section, const char *name, const char *value)
{
    parse_state *st = user;
    if (st->err_line)
        return 1; /* inih reads on after an error; the first one is reported */
    int i = find_key(section, name);
    snprintf(st->what, sizeof st->what, "[%s] %s", section, name);
    st->err_line = st->in->line;
    if (i < 0) {
        snprintf(st->why, sizeof st->why, "%s",
                 section_known(section) ? "unknown key" : "unknown section");
        return 0;
    }
    if (st->seen[i]) {
        snprintf(st->why, sizeof st->why, "given twice");
        return 0;
    }
    st->seen[i] = 1;
    st->cfg->origin[i].line = st->in->line;
    if (set_key(st->cfg, st->grid, i, value, st->why, sizeof st->why))
        return 0;
    st->err_line = 0;
    return 1;
}

int ppb_config_key_fail(const ppb_config *cfg, const char *section, const char *key, ppb_err *err,
                        const char *fmt, ...)
{
    char why[1200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    int i = find_key(section, key);
    if (i >= 0 && cfg->origin[i].from_set)
        return ppb_fail(err, "--set %s.%s: %s", section, key, why);
    int line = i >= 0 ? cfg->origin[i].line : 0;
    return ppb_fail(err, "%s:%d: [%s] %s: %s", cfg->path, line, section, key, why);
}

/* Checks that involve more than one key. */
static int validate(const ppb_config *cfg, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    int slab = sc->geometry == PPB_GEOM_SLAB;
    if (slab && sc->step != PPB_STEP_NONE)
        return ppb_config_key_fail(cfg, "medium", "step", err,
                                   "steps are refused in slab mode (SPEC.md 2)");
    if (!slab && sc->step != PPB_STEP_NONE && fabs(sc->step_x) >= 0.5 * sc->width)
        return ppb_config_key_fail(cfg, "medium", "step_x", err,
                                   "the step must lie inside the tube");
    return 0;
}

static void base_name(const char *path, char *out, size_t cap)
{
    const char *b = strrchr(path, '/');
    b = b ? b + 1 : path;
    size_t n = strcspn(b, ".");
    snprintf(out, cap, "%.*s", (int)(n < cap ? n : cap - 1), b);
}

static int apply_defaults(ppb_config *cfg, ppb_err *err)
{
    char why[512];
    for (int i = 0; i < NKEYS; i++)
        if (set_key(cfg, NULL, i, keys[i].def, why, sizeof why))
            return ppb_fail(err, "internal: default of [%s] %s: %s", keys[i].section, keys[i].key,
                            why);
    return 0;
}

int ppb_config_defaults(ppb_config *cfg, ppb_err *err)
{
    memset(cfg, 0, sizeof *cfg);
    snprintf(cfg->path, sizeof cfg->path, "(defaults)");
    snprintf(cfg->name, sizeof cfg->name, "defaults");
    return apply_defaults(cfg, err);
}

int ppb_config_load_grid(ppb_config *cfg, ppb_grid *grid, const char *path, ppb_err *err)
{
    memset(cfg, 0, sizeof *cfg);
    if (grid)
        ppb_grid_clear(grid);
    snprintf(cfg->path, sizeof cfg->path, "%s", path);
    if (apply_defaults(cfg, err))
        return -1;
    FILE *f = fopen(path, "r");
    if (!f)
        return ppb_fail(err, "%s: cannot open config: %s", path, strerror(errno));
    line_reader in = {.f = f};
    parse_state st = {.cfg = cfg, .grid = grid, .in = &in};
    int rc = ini_parse_stream(read_line, &in, on_key, &st);
    fclose(f);
    if (rc > 0 && rc == st.err_line)
        return ppb_fail(err, "%s:%d: %s: %s", path, rc, st.what, st.why);
    if (rc > 0)
        return ppb_fail(err, "%s:%d: syntax error (expected [section] or key = value)", path, rc);
    if (rc < 0)
        return ppb_fail(err, "%s: cannot read config", path);
    if (!cfg->name[0])
        base_name(path, cfg->name, sizeof cfg->name);
    if (!cfg->out_dir[0])
        snprintf(cfg->out_dir, sizeof cfg->out_dir, "results/%s", cfg->name);
    return validate(cfg, err);
}

int ppb_config_load(ppb_config *cfg, const char *path, ppb_err *err)
{
    return ppb_config_load_grid(cfg, NULL, path, err);
}

int ppb_config_set_grid(ppb_config *cfg, ppb_grid *grid, const char *section, const char *key,
                        const char *value, ppb_err *err)
{
    int i = find_key(section, key);
    if (i < 0)
        return ppb_fail(err, "--set %s.%s: %s", section, key,
                        section_known(section) ? "unknown key" : "unknown section");
    char why[1200];
    /* A key set again replaces an earlier list on it. */
    if (grid)
        ppb_grid_remove(grid, i);
    if (set_key(cfg, grid, i, value, why, sizeof why))
        return ppb_fail(err, "--set %s.%s: %s", section, key, why);
    cfg->origin[i].from_set = 1;
    return validate(cfg, err);
}

int ppb_config_set(ppb_config *cfg, const char *section, const char *key, const char *value,
                   ppb_err *err)
{
    return ppb_config_set_grid(cfg, NULL, section, key, value, err);
}

int ppb_config_point(const ppb_config *cfg, const ppb_grid *grid, long long i, ppb_config *out,
                     ppb_err *err)
{
    long long n = ppb_grid_npoints(grid);
    if (i < 0 || i >= n)
        return ppb_fail(err, "grid point %lld out of range [0, %lld)", i, n);
    *out = *cfg;
    for (int a = 0; grid && a < grid->naxes; a++)
        store_number(out, &keys[grid->axes[a].key], ppb_grid_value(grid, a, i));
    return validate(out, err);
}

static void write_value(const ppb_config *cfg, const key_def *k, FILE *out)
{
    const char *p = (const char *)cfg + k->offset;
    switch (k->type) {
    case K_INT:
        fprintf(out, "%d", *(const int *)p);
        break;
    case K_LLONG:
        fprintf(out, "%lld", *(const long long *)p);
        break;
    case K_REAL:
        fprintf(out, "%.17g", *(const double *)p);
        break;
    case K_ENUM:
        fprintf(out, "%s", enum_value_name(k->enums, *(const int *)p));
        break;
    case K_METHODS:
        for (int j = 0; j < cfg->nmethods; j++)
            fprintf(out, "%s%s", j ? ", " : "", cfg->methods[j]);
        break;
    default:
        fprintf(out, "%s", p);
    }
}

void ppb_config_write_resolved(const ppb_config *cfg, FILE *out)
{
    for (int i = 0; i < NKEYS; i++) {
        fprintf(out, "%s.%s = ", keys[i].section, keys[i].key);
        write_value(cfg, &keys[i], out);
        fputc('\n', out);
    }
}

void ppb_config_write_keys(FILE *out)
{
    fprintf(out, "| section | key | type | default | range | meaning |\n");
    fprintf(out, "|---|---|---|---|---|---|\n");
    for (int i = 0; i < NKEYS; i++) {
        const key_def *k = &keys[i];
        char range[256] = "";
        if (k->type == K_ENUM)
            enum_list(k->enums, range, sizeof range);
        else if (k->type == K_INT || k->type == K_LLONG || k->type == K_REAL)
            snprintf(range, sizeof range, "[%g, %g]", k->min, k->max);
        fprintf(out, "| %s | %s | %s | %s | %s | %s |\n", k->section, k->key, type_names[k->type],
                k->def[0] ? k->def : "(see meaning)", range, k->help);
    }
}

void ppb_config_key_name(int key, char *buf, size_t cap)
{
    if (key < 0 || key >= NKEYS)
        snprintf(buf, cap, "?");
    else
        snprintf(buf, cap, "%s.%s", keys[key].section, keys[key].key);
}

double ppb_config_key_value(const ppb_config *cfg, int key)
{
    const key_def *k = &keys[key];
    const char *p = (const char *)cfg + k->offset;
    if (k->type == K_INT || k->type == K_ENUM)
        return *(const int *)p;
    if (k->type == K_LLONG)
        return (double)*(const long long *)p;
    return k->type == K_REAL ? *(const double *)p : 0.0;
}

int ppb_config_has_method(const ppb_config *cfg, const char *id)
{
    for (int i = 0; i < cfg->nmethods; i++)
        if (strcmp(cfg->methods[i], id) == 0)
            return 1;
    return 0;
}
