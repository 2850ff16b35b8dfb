#include "model/config.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <ini.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <strings.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "kernels/march_params.h"
#include "model/materials.h"

typedef enum { K_INT, K_LLONG, K_REAL, K_ENUM, K_NAME, K_PATH, K_METHODS, K_MATERIAL } key_type;

/* What `ppbench keys` calls each type. */
static const char *const type_names[] = {
    [K_INT] = "integer",
    [K_LLONG] = "integer",
    [K_REAL] = "real",
    [K_ENUM] = "one of",
    [K_NAME] = "name",
    [K_PATH] = "path",
    [K_METHODS] = "list of method ids",
    [K_MATERIAL] = "material name",
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
static const enum_name lit_names[] = {{0, "face"}, {1, "strip"}, {0, NULL}};
static const enum_name table_names[] = {{PPB_TABLE_R, "R"}, {PPB_TABLE_S, "S"}, {0, NULL}};
static const enum_name unit_names[] = {{PPB_UNIT_MFP, "mfp"}, {PPB_UNIT_MM, "mm"}, {0, NULL}};
/* The first name of a value is the one written; the others are accepted too. */
static const enum_name channel_names[] = {
    {PPB_CH_R, "r"},   {PPB_CH_G, "g"},     {PPB_CH_B, "b"},    {PPB_CHANNEL_RGB, "rgb"},
    {PPB_CH_R, "red"}, {PPB_CH_G, "green"}, {PPB_CH_B, "blue"}, {0, NULL}};
static const enum_name delta_m_names[] = {
    {PPB_DELTA_M_OFF, "off"}, {PPB_DELTA_M_ON, "on"}, {PPB_DELTA_M_AUTO, "auto"}, {0, NULL}};
static const enum_name on_off_names[] = {{0, "off"}, {1, "on"}, {0, NULL}};
static const enum_name rte_source_names[] = {
    {PPB_RTE_SOURCE_FLAT, "flat"}, {PPB_RTE_SOURCE_LINEAR, "linear"}, {0, NULL}};
static const enum_name rte_moment_names[] = {{PPB_RTE_MOMENT_OFF, "off"},
                                             {PPB_RTE_MOMENT_ON, "on"},
                                             {PPB_RTE_MOMENT_AUTO, "auto"},
                                             {0, NULL}};
static const enum_name rte_delta_m_names[] = {{PPB_RTE_DELTA_M_OFF, "off"},
                                              {PPB_RTE_DELTA_M_HG, "on"},
                                              {PPB_RTE_DELTA_M_LEGENDRE, "legendre"},
                                              {0, NULL}};
static const enum_name shape_names[] = {{PPB_OBJ_BOX, "box"},     {PPB_OBJ_SPHERE, "sphere"},
                                        {PPB_OBJ_YOKAN, "yokan"}, {PPB_OBJ_MESH, "mesh"},
                                        {PPB_OBJ_FILE, "file"},   {0, NULL}};

/* An enum key is stored as an int (ppb_scene.geometry is a ppb_geometry). */
_Static_assert(sizeof(ppb_geometry) == sizeof(int), "enum keys are stored as int");

typedef struct key_def {
    const char *section, *key;
    key_type type;
    /* Whether the key changes the Monte Carlo's result (config.h, ppb_mc_key): the reference
     * cache's key hashes exactly the PPB_MC_KEY keys (methods/mc/mc_cache.h). Required: it
     * stands before the offset, so an entry that leaves it out does not compile, and 0 is
     * refused by the key table's test (tests/test_cache_keys.c). */
    ppb_mc_key mc;
    size_t offset;
    double min, max;
    const char *def;
    const enum_name *enums; /* K_ENUM: the value names */
    const char *help;
} key_def;

#define F(field) offsetof(ppb_config, field)
/* The one table: parsing, defaults, ranges, sweeps and configs/README.md all come from it. */
static const key_def keys[] = {
    {"experiment", "name", K_NAME, PPB_NOT_MC_KEY, F(name), 0, 0, "", NULL,
     "experiment name; default: the config file's base name"},
    {"experiment", "geometry", K_ENUM, PPB_MC_KEY, F(scene.geometry), 0, 0, "tube", geometry_names,
     "the tube (docs/reference.md: Geometry), or the infinite slab of thickness `height`"},
    {"experiment", "unit", K_ENUM, PPB_NOT_MC_KEY, F(unit), 0, 0, "mfp", unit_names,
     "the length unit (docs/reference.md: Materials): mfp, or mm (a material's); the numbers "
     "are the same either way"},
    {"experiment", "methods", K_METHODS, PPB_NOT_MC_KEY, F(methods), 0, 0, "mc, pp, ss, mp, mp+ss",
     NULL, "method ids, comma-separated (`ppbench --help` lists them)"},
    {"tube", "width", K_REAL, PPB_MC_KEY, F(scene.width), 0.01, 1000, "10", NULL,
     "W, mfp (ignored by slab)"},
    {"tube", "height", K_REAL, PPB_MC_KEY, F(scene.height), 1e-3, 1000, "3", NULL,
     "H, mfp; the slab thickness in slab mode"},
    {"tube", "segments_top", K_INT, PPB_MC_KEY, F(scene.segments_top), 1, 4096, "128", NULL,
     "segments of S1 and S2"},
    {"tube", "segments_side", K_INT, PPB_MC_KEY, F(scene.segments_side), 1, 4096, "36", NULL,
     "segments of S3 and S4"},
    {"medium", "material", K_MATERIAL, PPB_MC_KEY, F(material), 0, 0, "none", NULL,
     "a measured medium (`ppbench materials`) that sets sigma_t, albedo, g and n, or none"},
    {"medium", "channel", K_ENUM, PPB_MC_KEY, F(channel), 0, 0, "g", channel_names,
     "the material's colour channel, or rgb: every method for each of the three (a colour run, "
     "docs/reference.md: Colour)"},
    {"medium", "sigma_t", K_REAL, PPB_MC_KEY, F(scene.sigma_t), 1e-3, 1000, "1", NULL,
     "extinction, 1/mfp (left of the step)"},
    {"medium", "albedo", K_REAL, PPB_MC_KEY, F(scene.albedo), 0, 1, "0.95", NULL,
     "single-scattering albedo (left of the step)"},
    {"medium", "g", K_REAL, PPB_MC_KEY, F(scene.g), -0.95, 0.95, "0", NULL,
     "Henyey-Greenstein asymmetry"},
    {"medium", "n", K_REAL, PPB_MC_KEY, F(scene.n), 1, 2.5, "1", NULL,
     "refractive index inside (outside is 1): smooth Fresnel boundaries"},
    {"medium", "step", K_ENUM, PPB_MC_KEY, F(scene.step), 0, 0, "none", step_names,
     "what changes at x = step_x (tube only)"},
    {"medium", "step_x", K_REAL, PPB_MC_KEY, F(scene.step_x), -500, 500, "0", NULL,
     "position of the step, mfp; inside the tube"},
    {"medium", "sigma_t_right", K_REAL, PPB_MC_KEY, F(scene.sigma_t_right), 1e-3, 1000, "0.5", NULL,
     "extinction for x >= step_x (step = density)"},
    {"medium", "albedo_right", K_REAL, PPB_MC_KEY, F(scene.albedo_right), 0, 1, "0.475", NULL,
     "albedo for x >= step_x (step = albedo)"},
    {"light", "theta_deg", K_REAL, PPB_MC_KEY, F(scene.theta_deg), 0, 89, "0", NULL,
     "incidence angle from the S1 normal, degrees"},
    {"light", "lit", K_ENUM, PPB_MC_KEY, F(scene.searchlight), 0, 0, "face", lit_names,
     "the lit part of S1: the whole face (x < step_x with step = shadow), or a searchlight's "
     "strip (x0, width; tube only; docs/reference.md: Light)"},
    {"light", "x0", K_REAL, PPB_MC_KEY, F(scene.light_x0), -500, 500, "0", NULL,
     "centre of the strip (lit = strip), mfp"},
    {"light", "width", K_REAL, PPB_MC_KEY, F(scene.light_width), 0, 1000, "1", NULL,
     "width of the strip (lit = strip), mfp; 0 = a line along z at x0"},
    {"bins", "theta", K_INT, PPB_MC_KEY, F(scene.ntheta), 1, 64, "8", NULL,
     "theta bins (equal projected solid angle)"},
    {"bins", "phi", K_INT, PPB_MC_KEY, F(scene.nphi), 1, 64, "8", NULL,
     "phi bins over [0, 180] deg"},
    {"bins", "samples_dir", K_INT, PPB_NOT_MC_KEY, F(samples_dir), 1, 64, "4", NULL,
     "deterministic methods: n x n directions averaged per bin"},
    {"bins", "samples_seg", K_INT, PPB_NOT_MC_KEY, F(samples_seg), 1, 64, "4", NULL,
     "deterministic methods: points averaged per segment"},
    {"mc", "photons", K_LLONG, PPB_MC_KEY, F(mc.photons), 1, 1e13, "1e7", NULL, "photon budget"},
    {"mc", "batches", K_INT, PPB_MC_KEY, F(mc.batches), 2, 1024, "16", NULL,
     "independent batches for standard errors"},
    {"mc", "seed", K_LLONG, PPB_MC_KEY, F(mc.seed), 0, 9.2e18, "1", NULL,
     "random seed (Philox key)"},
    {"mc", "workgroup", K_INT, PPB_NOT_MC_KEY, F(mc.workgroup), 0, 4096, "0", NULL,
     "work-group size, 0 = ppbench picks (1 on a CPU, 64 on a GPU); results do not depend on it"},
    {"mc", "chunk", K_LLONG, PPB_NOT_MC_KEY, F(mc.chunk), 0, 1e12, "0", NULL,
     "photons per kernel launch, 0 = sized to the device (results do not depend on it, "
     "except where target_noise stops the run after a launch)"},
    {"mc", "first", K_LLONG, PPB_MC_KEY, F(mc.first), 0, 1e13, "0", NULL,
     "index of the first photon (a shard of one run)"},
    {"mc", "target_noise", K_REAL, PPB_MC_KEY, F(mc.target_noise), 0, 1, "0", NULL,
     "stop when noise_rel at the x = 0 cells falls below this; 0 = run the whole budget"},
    {"pp", "directions", K_INT, PPB_NOT_MC_KEY, F(pp.directions), 2, 4000, "334", NULL,
     "direction cells per hemisphere (M = 2 x directions)"},
    {"pp", "modes", K_INT, PPB_NOT_MC_KEY, F(pp.modes), 0, 8000, "0", NULL,
     "n_e: modes kept by the march, 0 = all"},
    {"pp", "table", K_ENUM, PPB_NOT_MC_KEY, F(pp.table), 0, 0, "S", table_names,
     "integral table of the march: R (Eq. 15) or S (Eq. 16-17)"},
    {"pp", "step", K_REAL, PPB_NOT_MC_KEY, F(pp.step), 1e-4, 1, "0.05", NULL,
     "ray-march step, mfp"},
    {"pp", "albedos", K_INT, PPB_NOT_MC_KEY, F(pp.albedos), 2, 64, "9", NULL,
     "albedo nodes of the tables (Sec. 3.3)"},
    {"pp", "map_res", K_INT, PPB_NOT_MC_KEY, F(pp.map_res), 1, 4096, "64", NULL,
     "cells per mfp of the optical-depth and albedo maps"},
    {"pp", "delta_m", K_ENUM, PPB_NOT_MC_KEY, F(pp.delta_m), 0, 0, "auto", delta_m_names,
     "slab solver's delta-M for forward-peaked HG: off, on, auto = on where g >= 0.6"},
    {"pp", "collars", K_INT, PPB_NOT_MC_KEY, F(pp.collars), 0, 4000, "0", NULL,
     "slab solver's polar-ring partition: collars + 1 rings of equal polar width per "
     "hemisphere, 0 = near-square cells; at most (directions - 4) / 2"},
    {"mp", "pairs", K_INT, PPB_NOT_MC_KEY, F(mp.pairs), 0, 200, "10", NULL,
     "dipole pairs beyond the first (0 = dipole)"},
    {"mp", "samples", K_INT, PPB_NOT_MC_KEY, F(mp.samples), 1, 256, "16", NULL,
     "quadrature nodes per mfp over the lit strip"},
    {"burley", "samples", K_INT, PPB_NOT_MC_KEY, F(burley.samples), 1, 256, "16", NULL,
     "burley: quadrature nodes per profile length d = mfp / s over the lit strip"},
    {"burley", "directions", K_INT, PPB_NOT_MC_KEY, F(burley.directions), 2, 2000, "334", NULL,
     "burley: direction cells per hemisphere of the slab solve that gives A (and twice as many)"},
    {"bdipole", "samples", K_INT, PPB_NOT_MC_KEY, F(bdipole.samples), 1, 256, "16", NULL,
     "bdipole: quadrature nodes per 1 / sigma_tr over the lit strip"},
    {"pbd", "nodes", K_INT, PPB_NOT_MC_KEY, F(pbd.nodes), 2, 16, "6", NULL,
     "pbd: Gauss-Legendre nodes per panel of the strip's x and z integrals"},
    {"dirpole", "samples", K_INT, PPB_NOT_MC_KEY, F(dirpole.samples), 1, 256, "16", NULL,
     "dirpole: quadrature nodes per diffusion length 1/sigma_tr along the strip and per unit of "
     "t along z = q sinh t"},
    {"rte2d", "spacing", K_REAL, PPB_NOT_MC_KEY, F(rte2d.spacing), 0.005, 10, "0.1", NULL,
     "rte2d: grid node spacing over the cross-section, mfp"},
    {"rte2d", "directions", K_INT, PPB_NOT_MC_KEY, F(rte2d.directions), 2, 2000, "128", NULL,
     "rte2d: direction cells per hemisphere"},
    {"rte2d", "step", K_REAL, PPB_NOT_MC_KEY, F(rte2d.step), 1e-3, 1, "0.05", NULL,
     "rte2d: largest track spacing of the sweep and march step of the exit, in the plane, mfp"},
    {"rte2d", "tolerance", K_REAL, PPB_NOT_MC_KEY, F(rte2d.tol), 1e-12, 0.1, "1e-7", NULL,
     "rte2d: relative residual at which the solve stops"},
    {"rte2d", "refinements", K_INT, PPB_NOT_MC_KEY, F(rte2d.refinements), 0, 10000, "0", NULL,
     "rte2d: K steps of Eq. 5 from I_pp (1 = the paper's method on the grid); 0 = converge"},
    {"rte2d", "delta_m", K_ENUM, PPB_NOT_MC_KEY, F(rte2d.delta_m), 0, 0, "on", rte_delta_m_names,
     "rte2d: delta-M scaling of the forward peak the direction cells cannot resolve, with the "
     "single-scattering correction of the exit radiance: on = the truncated function an HG, "
     "legendre = the Legendre series truncated at delta_m_order"},
    {"rte2d", "delta_m_order", K_INT, PPB_NOT_MC_KEY, F(rte2d.delta_m_order), 0, 64, "0", NULL,
     "rte2d: delta-M's truncation order L (f = g^L; legendre: the series' length); 0 = "
     "sqrt(2 directions)"},
    {"rte2d", "moment", K_ENUM, PPB_NOT_MC_KEY, F(rte2d.moment), 0, 0, "auto", rte_moment_names,
     "rte2d: the direction cells' phase matrix corrected to the mean cosine of the function "
     "they carry; auto = in the tube where g > 0 on the near-square cells"},
    {"rte2d", "ims", K_ENUM, PPB_NOT_MC_KEY, F(rte2d.ims), 0, 0, "on", on_off_names,
     "rte2d: under delta-M, the exit radiance corrected for the light scattered only within the "
     "truncated peak (Nakajima and Tanaka's IMS, every order in the small-angle limit)"},
    {"rte2d", "source", K_ENUM, PPB_NOT_MC_KEY, F(rte2d.source), 0, 0, "flat", rte_source_names,
     "rte2d: the scattered light's emission in each region of the sweep, flat or linear in x and "
     "y (the tube; the slab stays flat, ppslab's system)"},
    /* [object]: `ppbench object` only (docs/reference.md, Objects); the tube's Monte Carlo
     * never reads them, so none is part of its reference cache's key. */
    {"object", "shape", K_ENUM, PPB_NOT_MC_KEY, F(object.shape), 0, 0, "box", shape_names,
     "the object: box (the whole grid), sphere (the grid's inscribed ball), yokan (a box with a "
     "ball inclusion of another material), mesh (a closed OBJ mesh), file (a voxel file)"},
    {"object", "grid_x", K_INT, PPB_NOT_MC_KEY, F(object.nx), 1, 512, "32", NULL,
     "grid voxels along x (mesh: the mesh's bounding box spans the grid)"},
    {"object", "grid_y", K_INT, PPB_NOT_MC_KEY, F(object.ny), 1, 512, "32", NULL,
     "grid voxels along y"},
    {"object", "grid_z", K_INT, PPB_NOT_MC_KEY, F(object.nz), 1, 512, "32", NULL,
     "grid voxels along z"},
    {"object", "voxel", K_REAL, PPB_NOT_MC_KEY, F(object.voxel), 1e-4, 100, "0.25", NULL,
     "voxel edge h, in the config's unit (mfp or mm)"},
    {"object", "inclusion_radius", K_REAL, PPB_NOT_MC_KEY, F(object.inc_radius), 0, 0.5, "0.25",
     NULL, "yokan: the inclusion ball's radius, a fraction of the grid's smallest edge"},
    {"object", "inclusion_x", K_REAL, PPB_NOT_MC_KEY, F(object.inc_x), 0, 1, "0.5", NULL,
     "yokan: the inclusion's centre along x, a fraction of the grid's x edge"},
    {"object", "inclusion_y", K_REAL, PPB_NOT_MC_KEY, F(object.inc_y), 0, 1, "0.5", NULL,
     "yokan: the inclusion's centre along y, a fraction of the grid's y edge"},
    {"object", "inclusion_z", K_REAL, PPB_NOT_MC_KEY, F(object.inc_z), 0, 1, "0.5", NULL,
     "yokan: the inclusion's centre along z, a fraction of the grid's z edge"},
    {"object", "inclusion_sigma_t", K_REAL, PPB_NOT_MC_KEY, F(object.inc_sigma_t), 1e-3, 1000, "4",
     NULL, "yokan: the inclusion's extinction, per unit length"},
    {"object", "inclusion_albedo", K_REAL, PPB_NOT_MC_KEY, F(object.inc_albedo), 0, 1, "0.7", NULL,
     "yokan: the inclusion's single-scattering albedo"},
    {"object", "mesh", K_PATH, PPB_NOT_MC_KEY, F(object.mesh), 0, 0, "", NULL,
     "shape = mesh: a closed triangle mesh (Wavefront OBJ), relative to the config's folder"},
    {"object", "voxels", K_PATH, PPB_NOT_MC_KEY, F(object.voxels), 0, 0, "", NULL,
     "shape = file: a voxel file (JSON header + raw bytes), relative to the config's folder"},
    {"object", "light_theta", K_REAL, PPB_NOT_MC_KEY, F(object.light_theta), 0, 180, "0", NULL,
     "direction toward the light: degrees from +y"},
    {"object", "light_phi", K_REAL, PPB_NOT_MC_KEY, F(object.light_phi), -360, 360, "0", NULL,
     "direction toward the light: degrees from +x toward +z"},
    {"object", "camera_theta", K_REAL, PPB_NOT_MC_KEY, F(object.camera_theta), 0, 180, "45", NULL,
     "direction toward the orthographic camera: degrees from +y"},
    {"object", "camera_phi", K_REAL, PPB_NOT_MC_KEY, F(object.camera_phi), -360, 360, "30", NULL,
     "direction toward the camera: degrees from +x toward +z"},
    {"object", "image_width", K_INT, PPB_NOT_MC_KEY, F(object.image_w), 1, 4096, "64", NULL,
     "camera pixels across"},
    {"object", "image_height", K_INT, PPB_NOT_MC_KEY, F(object.image_h), 1, 4096, "64", NULL,
     "camera pixels down"},
    {"object", "patch", K_INT, PPB_NOT_MC_KEY, F(object.patch), 1, 512, "4", NULL,
     "patch edge in boundary faces: a patch is patch x patch faces of one plane and orientation"},
    {"output", "dir", K_PATH, PPB_NOT_MC_KEY, F(out_dir), 0, 0, "", NULL,
     "output directory; default results/<name>"},
    {"run", "memory_limit", K_REAL, PPB_NOT_MC_KEY, F(memory_limit), 0, 1e6, "0", NULL,
     "GB a method may allocate, estimated before it allocates (over it: refused); 0 = half "
     "the machine's memory"},
};
#undef F

/* The PPB_MC_KEY keys that join the cache's key only away from their defaults (config.h,
 * ppb_key_info.keyed_when_set): added after references were traced and shipped, and at their
 * defaults changing nothing, so those references keep their keys. */
static const char *const keyed_when_set[] = {"medium.material", "medium.channel", "light.lit",
                                             "light.x0", "light.width"};

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

/* "Did you mean": how close a mistyped name is to a known one, for the suggestion after
 * "unknown key", "unknown section" and (methods/registry.c) "unknown method". The
 * Levenshtein distance over case-folded characters (one insertion, deletion or substitution
 * each); a typed name that is a prefix of the known one ("theta" for "theta_deg") counts as
 * close whatever its length. Returns the distance, or -1 when the names are not close: more
 * than 1 edit for names of up to 4 characters, more than 2 beyond. */
int ppb_name_distance(const char *typed, const char *known)
{
    size_t a = strlen(typed), b = strlen(known);
    if (a >= 3 && a < b && strncasecmp(typed, known, a) == 0)
        return (int)(b - a) < 2 ? (int)(b - a) : 2;
    if (a > 63 || b > 63)
        return -1;
    int row[64];
    for (size_t j = 0; j <= b; j++)
        row[j] = (int)j;
    for (size_t i = 1; i <= a; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= b; j++) {
            int up = row[j];
            int sub = diag + (tolower((unsigned char)typed[i - 1]) !=
                              tolower((unsigned char)known[j - 1]));
            int best = up + 1 < row[j - 1] + 1 ? up + 1 : row[j - 1] + 1;
            row[j] = sub < best ? sub : best;
            diag = up;
        }
    }
    int d = row[b], limit = (a < b ? a : b) <= 4 ? 1 : 2;
    return d <= limit ? d : -1;
}

/* Why section.key is refused, with the nearest known key when one is close (ppb_name_distance):
 * first a key of the same section ("unknown key (did you mean theta_deg?)"), else the same key
 * in a close section or a close key anywhere ("(did you mean [light] theta_deg?)"; dotted, as
 * --set writes it: "light.theta_deg"). */
static void unknown_why(const char *section, const char *key, int dotted, char *why, size_t n)
{
    /* Retired keys: what replaced them (docs/reference.md, Keys). */
    static const char *const retired[][3] = {
        {"rte2d", "graded_bins",
         "retired key: every deterministic method grades the last theta row of bins toward the "
         "tangent plane now (docs/reference.md, Bins); delete the line"},
    };
    for (size_t i = 0; i < sizeof retired / sizeof retired[0]; i++)
        if (strcmp(section, retired[i][0]) == 0 && strcmp(key, retired[i][1]) == 0) {
            snprintf(why, n, "%s", retired[i][2]);
            return;
        }
    int known = section_known(section), best = -1, bestd = 99, same = 0;
    for (int i = 0; i < NKEYS; i++) {
        int in = strcmp(keys[i].section, section) == 0;
        int ds = in ? 0 : ppb_name_distance(section, keys[i].section);
        int dk = ppb_name_distance(key, keys[i].key);
        if (ds < 0 || dk < 0 || (known && !in && ds > 0))
            continue;
        int d = ds + dk;
        if (d < bestd || (d == bestd && in && !same)) {
            best = i;
            bestd = d;
            same = in;
        }
    }
    /* A known section with no close key: a close key of another section ("[tube] photons"). */
    if (best < 0 && known)
        for (int i = 0; i < NKEYS; i++) {
            int dk = ppb_name_distance(key, keys[i].key);
            if (dk >= 0 && dk < bestd) {
                best = i;
                bestd = dk;
            }
        }
    const char *what = known ? "unknown key" : "unknown section";
    if (best < 0)
        snprintf(why, n, "%s", what);
    else if (dotted)
        snprintf(why, n, "%s (did you mean %s.%s?)", what, keys[best].section, keys[best].key);
    else if (strcmp(keys[best].section, section) == 0)
        snprintf(why, n, "%s (did you mean %s?)", what, keys[best].key);
    else
        snprintf(why, n, "%s (did you mean [%s] %s?)", what, keys[best].section, keys[best].key);
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

/* Text from a config or the command line as a message may quote it: printable ASCII kept,
 * every other byte as \xNN (so a message never sends raw bytes to a terminal), and cut to about
 * 60 characters with "..." (a 100 KB value is not echoed). Returns buf. */
static const char *shown(const char *s, char *buf, size_t cap)
{
    size_t len = 0;
    for (; *s && len + 8 < cap; s++) {
        unsigned char c = (unsigned char)*s;
        if (len >= 60) {
            memcpy(buf + len, "...", 3);
            len += 3;
            break;
        }
        if (c >= 0x20 && c < 0x7f)
            buf[len++] = (char)c;
        else
            len += (size_t)snprintf(buf + len, cap - len, "\\x%02x", c);
    }
    buf[len] = '\0';
    return buf;
}

/* Integers are exact in a double below 2^53 (IEEE 754 binary64's 53-bit significand): an
 * integer written in floating-point form ("1e7") is taken below it, and so is a swept integer
 * (the grid holds doubles). */
#define EXACT_INT_MAX 9007199254740992.0 /* 2^53 */

static int is_digits(const char *s)
{
    s += *s == '+' || *s == '-';
    if (!isdigit((unsigned char)*s))
        return 0;
    while (isdigit((unsigned char)*s))
        s++;
    return *s == '\0';
}

/* A value is within the key's range (and an integer for an integer key). */
static int check_value(const key_def *k, double x, const char *text, char *why, size_t n)
{
    char q[96];
    if ((k->type == K_INT || k->type == K_LLONG) && x != floor(x)) {
        snprintf(why, n, "'%s' is not an integer", shown(text, q, sizeof q));
        return -1;
    }
    if (x < k->min || x > k->max) {
        snprintf(why, n, "%s is out of range [%g, %g]", shown(text, q, sizeof q), k->min, k->max);
        return -1;
    }
    return 0;
}

/* A number, with the key's type and range. Integer keys read digits as integers (strtoll, so a
 * seed above 2^53 keeps every digit, *exact holds it) and accept "1e7" when that double is an
 * integer below 2^53, which it then holds exactly. */
static int parse_number(const key_def *k, const char *text, double *v, long long *exact, char *why,
                        size_t n)
{
    char q[96];
    int integer = k->type == K_INT || k->type == K_LLONG;
    char *end;
    errno = 0;
    if (integer && is_digits(text)) {
        long long x = strtoll(text, &end, 10);
        if (errno == ERANGE || (isfinite(k->min) && x < (long long)k->min) ||
            (isfinite(k->max) && x > (long long)k->max)) {
            snprintf(why, n, "%s is out of range [%g, %g]", shown(text, q, sizeof q), k->min,
                     k->max);
            return -1;
        }
        *v = (double)x;
        if (exact)
            *exact = x;
        return 0;
    }
    double x = strtod(text, &end);
    if (end == text || *trim(end) != '\0' || errno == ERANGE || !isfinite(x)) {
        snprintf(why, n, "'%s' is not a number", shown(text, q, sizeof q));
        return -1;
    }
    if (check_value(k, x, text, why, n))
        return -1;
    if (integer && fabs(x) >= EXACT_INT_MAX) {
        snprintf(why, n,
                 "'%s' is above 2^53, where a floating-point number is not exact: "
                 "write the integer in digits",
                 shown(text, q, sizeof q));
        return -1;
    }
    *v = x;
    if (exact)
        *exact = integer ? (long long)x : 0;
    return 0;
}

/* Value i of the m values of start:stop:step (a:b:st). The values are start + i * step
 * up to the last one that exceeds stop by at most RANGE_TOL steps, and a last value within
 * RANGE_TOL steps of stop is stop itself: "0:1:0.1" ends at 1 whatever the rounding of 0.1
 * (configs/README.md states this rule). */
#define RANGE_TOL 1e-9

static double range_value(double a, double b, double st, long long m, long long i)
{
    double v = a + (double)i * st;
    return i == m - 1 && fabs(v - b) <= RANGE_TOL * st ? b : v;
}

/* "a, b, c" or "start:stop:step" (inclusive, step > 0), or a mix. Every value, given or
 * generated, is checked against the key's range here. *first_exact: the first value exactly,
 * for an integer key (parse_number). */
static int parse_list(const key_def *k, const char *text, double *vals, int *count,
                      long long *first_exact, char *why, size_t n)
{
    char q[96];
    char *buf = strdup(text);
    if (!buf) {
        snprintf(why, n, "out of memory");
        return -1;
    }
    int rc = -1, big = 0; /* big: an integer of 2^53 or more */
    *count = 0;
    char *rest = buf;
    for (char *tok = strsep(&rest, ","); tok; tok = strsep(&rest, ",")) {
        tok = trim(tok);
        if (!*tok) {
            snprintf(why, n, "empty value in list '%s'", shown(text, q, sizeof q));
            goto out;
        }
        if (*count >= PPB_MAX_LIST) {
            snprintf(why, n, "a list holds at most %d values", PPB_MAX_LIST);
            goto out;
        }
        char *c1 = strchr(tok, ':');
        if (!c1) {
            long long exact = 0;
            if (parse_number(k, tok, &vals[*count], &exact, why, n))
                goto out;
            big |= llabs(exact) >= (long long)EXACT_INT_MAX;
            if (*count == 0)
                *first_exact = exact;
            (*count)++;
            continue;
        }
        char *c2 = strchr(c1 + 1, ':');
        if (!c2) {
            snprintf(why, n, "range '%s' must read start:stop:step", shown(tok, q, sizeof q));
            goto out;
        }
        char range[96];
        shown(tok, range, sizeof range);
        *c1 = *c2 = '\0';
        double a, b, st;
        key_def wide = *k;
        wide.min = -INFINITY;
        wide.max = INFINITY;
        long long exact = 0, exact_b = 0;
        if (parse_number(k, trim(tok), &a, &exact, why, n) ||
            parse_number(k, trim(c1 + 1), &b, &exact_b, why, n) ||
            parse_number(&wide, trim(c2 + 1), &st, NULL, why, n))
            goto out;
        if (!(st > 0) || b < a) {
            snprintf(why, n, "range %s needs step > 0 and stop >= start", range);
            goto out;
        }
        /* The count as a double first: a tiny step (0:1:1e-19) makes it too large for any
         * integer type. */
        double steps = floor((b - a) / st + RANGE_TOL);
        if (!(steps < PPB_MAX_LIST - *count)) {
            snprintf(why, n, "range %s has more than %d values", range, PPB_MAX_LIST);
            goto out;
        }
        long long m = (long long)steps + 1;
        big |=
            llabs(exact) >= (long long)EXACT_INT_MAX || llabs(exact_b) >= (long long)EXACT_INT_MAX;
        if (*count == 0)
            *first_exact = exact;
        for (long long i = 0; i < m; i++) {
            double v = range_value(a, b, st, m, i);
            if (v < k->min || v > k->max) {
                snprintf(why, n, "range %s yields %.17g, out of range [%g, %g]", range, v, k->min,
                         k->max);
                goto out;
            }
            vals[(*count)++] = v;
        }
    }
    if (*count == 0) {
        snprintf(why, n, "empty value");
        goto out;
    }
    /* A swept integer goes through the grid's doubles: exact only below 2^53. */
    if (*count > 1 && big) {
        snprintf(why, n, "a swept integer must be below 2^53 (a grid holds doubles)");
        goto out;
    }
    rc = 0;
out:
    free(buf);
    return rc;
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
    const char *best = NULL;
    int bestd = 99;
    for (int j = 0; k->enums[j].name; j++) {
        if (strcasecmp(k->enums[j].name, text) == 0) {
            *out = k->enums[j].value;
            return 0;
        }
        int d = ppb_name_distance(text, k->enums[j].name);
        if (d >= 0 && d < bestd) {
            best = k->enums[j].name;
            bestd = d;
        }
    }
    char names[256], q[96];
    enum_list(k->enums, names, sizeof names);
    snprintf(why, n, "'%s' is not one of %s%s%s%s", shown(text, q, sizeof q), names,
             best ? " (did you mean " : "", best ? best : "", best ? "?)" : "");
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
            char q[96];
            snprintf(why, n, "method id '%s' is longer than %zu characters",
                     shown(tok, q, sizeof q), sizeof cfg->methods[0] - 1);
            return -1;
        }
        /* Ids are names (built-in or [method.NAME]): any other byte is refused here, shown
         * escaped, so no later message echoes a control or bidirectional character. */
        for (const char *c = tok; *c; c++)
            if (!isalnum((unsigned char)*c) && !strchr("_-.+", *c)) {
                char q[96];
                snprintf(why, n, "method id '%s' may hold only letters, digits and _-.+",
                         shown(tok, q, sizeof q));
                return -1;
            }
        for (int i = 0; i < cfg->nmethods; i++)
            if (strcmp(cfg->methods[i], tok) == 0) {
                char q[96];
                snprintf(why, n, "method '%s' listed twice", shown(tok, q, sizeof q));
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
            char q[96]; /* a control or bidirectional character is shown escaped */
            snprintf(why, n, "'%s' may hold only letters, digits and _-.+",
                     shown(text, q, sizeof q));
            return -1;
        }
    snprintf(dst, cap, "%s", text);
    return 0;
}

/* A material's name (model/materials.h) or "none", stored as the table spells it; an unknown
 * name is refused with the nearest one when close (ppb_name_distance). */
static int parse_material(char *dst, size_t cap, const char *text, char *why, size_t n)
{
    const ppb_material *m = ppb_material_find(text);
    if (m || strcasecmp(text, "none") == 0) {
        snprintf(dst, cap, "%s", m ? m->name : "none");
        return 0;
    }
    const char *best = NULL;
    int bestd = 99;
    for (int i = 0; i < ppb_material_count(); i++) {
        int d = ppb_name_distance(text, ppb_material_at(i)->name);
        if (d >= 0 && d < bestd) {
            best = ppb_material_at(i)->name;
            bestd = d;
        }
    }
    char q[96];
    snprintf(why, n, "unknown material '%s' (%s%s%s`ppbench materials` lists them)",
             shown(text, q, sizeof q), best ? "did you mean " : "", best ? best : "",
             best ? "? " : "");
    return -1;
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
    case K_MATERIAL:
        return parse_material(p, sizeof cfg->material, text, why, n);
    default:
        break;
    }
    double vals[PPB_MAX_LIST];
    int count;
    long long exact = 0;
    if (parse_list(k, text, vals, &count, &exact, why, n))
        return -1;
    store_number(cfg, k, vals[0]);
    if (count == 1) {
        if (k->type == K_LLONG)
            *(long long *)p = exact; /* every digit of a seed, also above 2^53 */
        return 0;
    }
    if (!grid) {
        snprintf(why, n, "a list (a sweep) is not accepted here");
        return -1;
    }
    if (grid->naxes == PPB_MAX_AXES) {
        snprintf(why, n, "more than %d swept keys", PPB_MAX_AXES);
        return -1;
    }
    /* The hard limit holds with --yes too: checking, hashing and tracking a grid costs time
     * and memory per point before any point runs. */
    long long points = ppb_grid_npoints(grid);
    if (points > PPB_GRID_MAX_POINTS / count) {
        snprintf(why, n,
                 "%d values make a grid of %lld points, over the hard limit of %lld (--yes does "
                 "not lift it)",
                 count, points * count, (long long)PPB_GRID_MAX_POINTS);
        return -1;
    }
    if (ppb_grid_add(grid, i, vals, count)) {
        snprintf(why, n, "out of memory");
        return -1;
    }
    return 0;
}

/* The file as inih reads it. The system's inih reads lines into a fixed buffer (INI_MAX_LINE,
 * 200 bytes in Debian's build: the rest of a longer line was read as the next line, shifting
 * every line number after it) and reads on after an error. So the config is read into memory
 * first (a regular file of at most PPB_CONFIG_MAX_BYTES: a directory, a device such as
 * /dev/zero or a FIFO is refused before anything is read) and handed to inih one line per call
 * by next_line(), which
 *  - hands a comment line as a blank line and a line without its inline comment (a ';' after a
 *    blank), what inih skips anyway, so comments of any length are fine;
 *  - refuses a NUL or control byte, and a line that still does not fit inih's buffer, as an
 *    error of that line;
 *  - returns end of file after the first error (the handler's, or inih's syntax error, found
 *    by inih's own test), so the first error is reported and nothing after it is read.
 * inih passes no line to the handler (INI_HANDLER_LINENO is off): it counts one line per call,
 * and so does next_line. */
#define PPB_CONFIG_MAX_BYTES (1 << 20)

typedef struct parse_state {
    ppb_config *cfg;
    ppb_grid *grid;
    const char *next, *end; /* the text not yet handed to inih */
    int line;               /* lines handed to inih: the line it is on */
    int in_key;             /* a key since the last section: an indented line continues it */
    int cont;               /* the line handed last continues the key before it */
    int stop;               /* the line handed last holds a syntax error */
    char seen[PPB_MAX_KEYS];
    int err_line; /* line of the first error (handler or text), 0 = none */
    int text_err; /* that error is the text's: why says it all */
    int from_set; /* a --set method.NAME.KEY: may replace the file's key (on_method_key) */
    char why[1200];
    char what[160];
} parse_state;

static int text_fail(parse_state *st, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int text_fail(parse_state *st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(st->why, sizeof st->why, fmt, ap);
    va_end(ap);
    st->err_line = st->line;
    st->text_err = 1;
    return -1;
}

static char *next_line(char *str, int num, void *stream)
{
    parse_state *st = stream;
    if (st->stop || st->err_line || st->next >= st->end)
        return NULL;
    const char *s = st->next;
    const char *nl = memchr(s, '\n', (size_t)(st->end - s));
    size_t len = nl ? (size_t)(nl - s) : (size_t)(st->end - s);
    st->next = nl ? nl + 1 : st->end;
    st->line++;
    for (size_t j = 0; j < len; j++) {
        unsigned char c = (unsigned char)s[j];
        if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f) {
            if (c == 0)
                text_fail(st, "a NUL byte: not a text file");
            else
                text_fail(st, "control character \\x%02x: not a text file", c);
            return NULL;
        }
    }
    size_t b = 0; /* the first non-blank */
    while (b < len && isspace((unsigned char)s[b]))
        b++;
    if (b == len || s[b] == ';' || s[b] == '#')
        len = b = 0; /* a blank or comment line */
    for (size_t j = b + 1; j < len; j++)
        if (s[j] == ';' && isspace((unsigned char)s[j - 1])) {
            len = j;
            break;
        }
    while (len > b && isspace((unsigned char)s[len - 1]))
        len--;
    if (len + 2 > (size_t)num) {
        text_fail(st, "a line of %zu characters (without comments); a line holds at most %d", len,
                  num - 2);
        return NULL;
    }
    st->cont = len > 0 && st->in_key && b > 0;
    /* inih's syntax test, in its order: a line indented under a key continues that key's value
     * (inih's multi-line values; the handler sees the key again), a section needs its ']', a
     * key line a '=' or ':'. */
    if (len > 0 && !(st->in_key && b > 0)) {
        if (s[b] == '[') {
            st->stop = !memchr(s + b, ']', len - b);
            st->in_key = 0;
        } else {
            st->stop = !memchr(s + b, '=', len - b) && !memchr(s + b, ':', len - b);
            st->in_key = 1;
        }
    }
    memcpy(str, s, len);
    str[len] = '\n';
    str[len + 1] = '\0';
    return str;
}

/* A key of a [method.NAME] section: stored as given, checked for form only (what NAME runs is
 * the methods layer's business). Returns 1, or 0 with st->why set. */
static int on_method_key(parse_state *st, const char *section, const char *name, const char *value)
{
    const char *id = section + strlen("method.");
    ppb_config *cfg = st->cfg;
    ppb_external_def *d = NULL;
    for (int i = 0; i < cfg->nexternal; i++)
        if (strcmp(cfg->external[i].name, id) == 0)
            d = &cfg->external[i];
    if (!d) {
        if (!*id || strlen(id) >= sizeof d->name) {
            snprintf(st->why, sizeof st->why, "a method name of 1 to %zu characters",
                     sizeof d->name - 1);
            return 0;
        }
        for (const char *c = id; *c; c++)
            if (!isalnum((unsigned char)*c) && !strchr("_-.+", *c)) {
                snprintf(st->why, sizeof st->why,
                         "a method name may hold only letters, digits and _-.+");
                return 0;
            }
        if (cfg->nexternal == PPB_MAX_EXTERNAL) {
            snprintf(st->why, sizeof st->why, "more than %d [method.NAME] sections",
                     PPB_MAX_EXTERNAL);
            return 0;
        }
        d = &cfg->external[cfg->nexternal++];
        snprintf(d->name, sizeof d->name, "%s", id);
        d->line = st->line;
    }
    if (st->from_set) {
        /* --set defines the key or replaces the file's (or an earlier --set's): the last wins,
         * as for every other key. */
        if (strcmp(name, "command") == 0)
            d->command[0] = '\0', d->command_line = 0, d->command_set = 0;
        if (strcmp(name, "timeout") == 0)
            d->timeout = 0, d->timeout_line = 0, d->timeout_set = 0;
        if (strcmp(name, "surfaces") == 0)
            d->surfaces = 0, d->surfaces_line = 0, d->surfaces_set = 0;
    }
    if (strcmp(name, "surfaces") == 0) {
        /* A list of S1..S4 (docs/external.md, "Partial coverage"). */
        if (d->surfaces_line) {
            snprintf(st->why, sizeof st->why, "given twice");
            return 0;
        }
        unsigned mask = 0;
        char list[256];
        snprintf(list, sizeof list, "%s", value);
        for (char *save = NULL, *tok = strtok_r(list, ", \t", &save); tok;
             tok = strtok_r(NULL, ", \t", &save)) {
            if ((tok[0] != 'S' && tok[0] != 's') || tok[1] < '1' || tok[1] > '4' || tok[2]) {
                snprintf(st->why, sizeof st->why,
                         "'%.40s' is not a surface: a list of S1, S2, S3, S4", tok);
                return 0;
            }
            mask |= 1u << (tok[1] - '1');
        }
        if (!mask) {
            snprintf(st->why, sizeof st->why, "a list of S1, S2, S3, S4 (at least one)");
            return 0;
        }
        d->surfaces = mask;
        d->surfaces_line = st->line ? st->line : 1;
        d->surfaces_set = st->from_set;
        return 1;
    }
    if (strcmp(name, "command") == 0) {
        size_t have = strlen(d->command);
        if (d->command_line && st->cont && !st->from_set) {
            /* An indented line continues the command (inih's multi-line value): joined by a
             * space, so a command longer than one config line can be written. */
            if (have + 1 + strlen(value) >= sizeof d->command) {
                snprintf(st->why, sizeof st->why, "a command of at most %zu characters",
                         sizeof d->command - 1);
                return 0;
            }
            snprintf(d->command + have, sizeof d->command - have, " %s", value);
            return 1;
        }
        if (d->command_line) {
            snprintf(st->why, sizeof st->why, "given twice");
            return 0;
        }
        if (!*value || strlen(value) >= sizeof d->command) {
            snprintf(st->why, sizeof st->why, "a command of 1 to %zu characters",
                     sizeof d->command - 1);
            return 0;
        }
        snprintf(d->command, sizeof d->command, "%s", value);
        d->command_line = st->line;
        d->command_set = st->from_set;
        return 1;
    }
    if (strcmp(name, "timeout") == 0) {
        char *end;
        double t = strtod(value, &end);
        if (d->timeout_line) {
            snprintf(st->why, sizeof st->why, "given twice");
            return 0;
        }
        if (end == value || *end || !(t > 0 && t <= 1e6)) {
            snprintf(st->why, sizeof st->why, "seconds, a number in (0, 1e6]");
            return 0;
        }
        d->timeout = t;
        d->timeout_line = st->line;
        d->timeout_set = st->from_set;
        return 1;
    }
    snprintf(st->why, sizeof st->why,
             "unknown key (a [method.NAME] holds command, timeout and surfaces)");
    return 0;
}

static int on_key(void *user, const char *section, const char *name, const char *value)
{
    parse_state *st = user;
    if (st->err_line)
        return 0; /* not reached: next_line ends the text after an error */
    int i = find_key(section, name);
    char qs[96], qn[96];
    snprintf(st->what, sizeof st->what, "[%s] %s", shown(section, qs, sizeof qs),
             shown(name, qn, sizeof qn));
    st->err_line = st->line;
    if (i < 0) {
        if (strncmp(section, "method.", 7) == 0) {
            if (!on_method_key(st, section, name, value))
                return 0;
            st->err_line = 0;
            return 1;
        }
        unknown_why(section, name, 0, st->why, sizeof st->why);
        return 0;
    }
    if (st->seen[i]) {
        snprintf(st->why, sizeof st->why, "given twice");
        return 0;
    }
    st->seen[i] = 1;
    st->cfg->origin[i].line = st->line;
    if (set_key(st->cfg, st->grid, i, value, st->why, sizeof st->why))
        return 0;
    st->err_line = 0;
    return 1;
}

/* The whole of a config file, NUL-terminated, into *text (the caller frees it). */
static int read_text(const char *path, char **text, size_t *len, ppb_err *err)
{
    /* O_NONBLOCK: opening a FIFO does not wait for a writer; it is refused below. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return ppb_fail(err, "%s: cannot open config: %s", path, strerror(errno));
    struct stat sb;
    char *buf = NULL;
    size_t n = 0;
    int rc = -1;
    if (fstat(fd, &sb) != 0)
        ppb_fail(err, "%s: cannot read config: %s", path, strerror(errno));
    else if (S_ISDIR(sb.st_mode))
        ppb_fail(err, "%s: is a directory, not a config file", path);
    else if (!S_ISREG(sb.st_mode))
        ppb_fail(err, "%s: not a regular file (a config is a text file)", path);
    else if (sb.st_size > PPB_CONFIG_MAX_BYTES)
        ppb_fail(err, "%s: %lld bytes: a config holds at most %d", path, (long long)sb.st_size,
                 PPB_CONFIG_MAX_BYTES);
    else if (!(buf = malloc(PPB_CONFIG_MAX_BYTES + 1)))
        ppb_fail(err, "%s: out of memory", path);
    else
        for (;;) {
            /* Bounded even should the file grow while it is read. */
            ssize_t r = read(fd, buf + n, PPB_CONFIG_MAX_BYTES + 1 - n);
            if (r < 0 && errno == EINTR)
                continue;
            if (r < 0) {
                ppb_fail(err, "%s: cannot read config: %s", path, strerror(errno));
                break;
            }
            n += (size_t)r;
            if (n > PPB_CONFIG_MAX_BYTES) {
                ppb_fail(err, "%s: a config holds at most %d bytes", path, PPB_CONFIG_MAX_BYTES);
                break;
            }
            if (r == 0) {
                rc = 0;
                break;
            }
        }
    close(fd);
    if (rc) {
        free(buf);
        return -1;
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return 0;
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

int ppb_config_axis_fail(const ppb_config *cfg, const ppb_grid *grid, int a, ppb_err *err,
                         const char *why)
{
    const key_def *k = &keys[grid->axes[a].key];
    return ppb_config_key_fail(cfg, k->section, k->key, err, "%s", why);
}

/* Where key (section, key) got its value, for a message about two keys: "--set tube.width",
 * "line 3" or "the default". */
static const char *origin_of(const ppb_config *cfg, const char *section, const char *key, char *buf,
                             size_t cap)
{
    int i = find_key(section, key);
    if (cfg->origin[i].from_set)
        snprintf(buf, cap, "--set %s.%s", section, key);
    else if (cfg->origin[i].line > 0)
        snprintf(buf, cap, "line %d", cfg->origin[i].line);
    else
        snprintf(buf, cap, "the default");
    return buf;
}

/* The searchlight's strip (reference: Light): in the tube, on S1, not with a shadow step (the
 * strip would be cut by it: refused rather than intersected, so the lit part is always one
 * strip). x0 and width are read with lit = strip only. */
static int validate_strip(const ppb_config *cfg, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    char where[600], where2[600];
    double w = sc->light_width, x0 = sc->light_x0, half = 0.5 * sc->width;
    if (!sc->searchlight)
        return 0; /* x0 and width unused, as step_x without a step */
    if (sc->geometry == PPB_GEOM_SLAB)
        return ppb_config_key_fail(
            cfg, "light", "lit", err,
            "a searchlight needs the tube (docs/reference.md, Light; geometry = slab from %s)",
            origin_of(cfg, "experiment", "geometry", where, sizeof where));
    if (sc->step == PPB_STEP_SHADOW)
        return ppb_config_key_fail(
            cfg, "light", "lit", err,
            "a searchlight and a shadow step do not combine (docs/reference.md, Light; step from "
            "%s): light the strip you want with x0 and width",
            origin_of(cfg, "medium", "step", where, sizeof where));
    int on_s1 = w > 0.0 ? x0 - 0.5 * w >= -half && x0 + 0.5 * w <= half : fabs(x0) < half;
    if (!on_s1)
        return ppb_config_key_fail(
            cfg, "light", w > 0.0 ? "width" : "x0", err,
            "the lit %s [x0 - width/2, x0 + width/2] = [%g, %g] must lie on S1 [%g, %g]%s "
            "(x0 from %s, tube width from %s)",
            w > 0.0 ? "strip" : "line", x0 - 0.5 * w, x0 + 0.5 * w, -half, half,
            w > 0.0 ? "" : ", inside it", origin_of(cfg, "light", "x0", where, sizeof where),
            origin_of(cfg, "tube", "width", where2, sizeof where2));
    return 0;
}

/* Whether a key was given (in the file, a grid axis's list included, or by --set). */
static int key_given(const ppb_config *cfg, const char *section, const char *key)
{
    int i = find_key(section, key);
    return cfg->origin[i].line > 0 || cfg->origin[i].from_set;
}

/* The keys a material sets (reference: Materials). */
static const char *const material_keys[] = {"sigma_t", "albedo", "g", "n"};
static int set_by_material(const ppb_config *cfg, int k);

/* [medium] material and channel: the medium's sigma_t, albedo, g and n from the table
 * (model/materials.h), each checked against its own key's range; refused with a key that sets
 * any of them to another value, without unit = mm, and a channel without a material. */
static int apply_material(ppb_config *cfg, ppb_err *err)
{
    char where[256];
    const ppb_material *m = ppb_material_find(cfg->material);
    if (!m) {
        /* Written configs (config.ini, provenance.txt) hold every key, the default channel
         * too: only another channel is refused. */
        if (cfg->channel != PPB_CH_G)
            return ppb_config_key_fail(cfg, "medium", "channel", err,
                                       "%s selects a colour channel of a [medium] material, and "
                                       "none is given",
                                       enum_value_name(channel_names, cfg->channel));
        return 0;
    }
    if (cfg->unit != PPB_UNIT_MM)
        return ppb_config_key_fail(cfg, "medium", "material", err,
                                   "a material's coefficients are per mm: set [experiment] unit = "
                                   "mm, and give the tube's sizes in mm (unit = mfp from %s)",
                                   origin_of(cfg, "experiment", "unit", where, sizeof where));
    ppb_scene *sc = &cfg->scene;
    double v[4], *dst[4] = {&sc->sigma_t, &sc->albedo, &sc->g, &sc->n};
    /* A colour run (channel = rgb) checks every channel's medium here, before any work, and
     * keeps the green one's in the config (PPB_CHANNEL_RGB); each channel's own config is
     * ppb_config_channel's. */
    int rgb = cfg->channel == PPB_CHANNEL_RGB;
    for (int c = rgb ? PPB_CH_R : PPB_CH_B; rgb && c <= PPB_CH_B; c++) {
        ppb_material_medium(m, (ppb_channel)c, &v[0], &v[1], &v[2], &v[3]);
        for (int j = 0; j < 4; j++) {
            const key_def *k = &keys[find_key("medium", material_keys[j])];
            if (v[j] < k->min || v[j] > k->max)
                return ppb_config_key_fail(
                    cfg, "medium", "channel", err,
                    "rgb runs every channel, and %s's %s channel has %s = %g, outside the range "
                    "[%g, %g] the methods take",
                    m->name, enum_value_name(channel_names, c), k->key, v[j], k->min, k->max);
        }
    }
    ppb_material_medium(m, rgb ? PPB_CH_G : (ppb_channel)cfg->channel, &v[0], &v[1], &v[2], &v[3]);
    for (int j = 0; j < 4; j++) {
        const key_def *k = &keys[find_key("medium", material_keys[j])];
        /* A key given beside the material is refused unless it states the material's own value
         * (provenance.txt, which `ppbench score` reads back, holds every resolved key). */
        if (key_given(cfg, "medium", k->key) && *dst[j] != v[j])
            return ppb_config_key_fail(
                cfg, "medium", k->key, err,
                "given together with material = %s (%s), which sets it to %.17g: remove one of "
                "the two",
                m->name, origin_of(cfg, "medium", "material", where, sizeof where), v[j]);
        if (v[j] < k->min || v[j] > k->max)
            return ppb_config_key_fail(
                cfg, "medium", "material", err,
                "%s's %s channel has %s = %g, outside the range [%g, %g] the methods take", m->name,
                enum_value_name(channel_names, cfg->channel), k->key, v[j], k->min, k->max);
    }
    for (int j = 0; j < 4; j++)
        *dst[j] = v[j];
    return 0;
}

/* apply_material, and a sweep over a key the material sets refused whatever its first value. */
static int apply_material_grid(ppb_config *cfg, const ppb_grid *grid, ppb_err *err)
{
    char where[256];
    for (int a = 0; grid && ppb_material_find(cfg->material) && a < grid->naxes; a++)
        if (set_by_material(cfg, grid->axes[a].key))
            return ppb_config_key_fail(
                cfg, keys[grid->axes[a].key].section, keys[grid->axes[a].key].key, err,
                "swept together with material = %s (%s), which sets it: remove one of the two",
                cfg->material, origin_of(cfg, "medium", "material", where, sizeof where));
    return apply_material(cfg, err);
}

/* Checks that involve more than one key; each names the key it fails and where the other
 * one was set. */
static int validate(const ppb_config *cfg, ppb_err *err)
{
    const ppb_scene *sc = &cfg->scene;
    int slab = sc->geometry == PPB_GEOM_SLAB;
    char where[1200];
    /* After every --set: a --set may give the command of a section the file opened. */
    for (int i = 0; i < cfg->nexternal; i++) {
        const ppb_external_def *d = &cfg->external[i];
        if (!d->command_line && !d->command_set)
            return ppb_fail(err, "%s: no command given%s%s%s",
                            ppb_config_external_where(cfg, d, NULL, where, sizeof where),
                            d->line ? "" : " (add --set method.", d->line ? "" : d->name,
                            d->line ? "" : ".command=...)");
    }
    if (slab && sc->step != PPB_STEP_NONE)
        return ppb_config_key_fail(
            cfg, "medium", "step", err,
            "steps are refused in slab mode (docs/reference.md, Geometry; geometry = slab from %s)",
            origin_of(cfg, "experiment", "geometry", where, sizeof where));
    if (!slab && sc->step != PPB_STEP_NONE && fabs(sc->step_x) >= 0.5 * sc->width)
        return ppb_config_key_fail(
            cfg, "medium", "step_x", err,
            "the step must lie inside the tube (|step_x| < width / 2 = %g, width from %s)",
            0.5 * sc->width, origin_of(cfg, "tube", "width", where, sizeof where));
    return validate_strip(cfg, err);
}

static void base_name(const char *path, char *out, size_t cap)
{
    const char *b = strrchr(path, '/');
    b = b ? b + 1 : path;
    size_t n = strcspn(b, ".");
    snprintf(out, cap, "%.*s", (int)(n < cap ? n : cap - 1), b);
}

/* experiment.name from the config file's base name when it has no `name =`: under the same rule
 * as `name =` (parse_string), as the name reaches figure titles and the output path. */
static int derive_name(ppb_config *cfg, const char *path, ppb_err *err)
{
    char base[sizeof cfg->name], why[512];
    base_name(path, base, sizeof base);
    for (int i = 0; i < NKEYS; i++)
        if (keys[i].type == K_NAME &&
            parse_string(&keys[i], cfg->name, sizeof cfg->name, base, why, sizeof why))
            return ppb_fail(err,
                            "%s: the experiment's name, from the file name when the file has no "
                            "[experiment] name: %s; give a name = line",
                            path, why);
    return 0;
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

/* The file's keys, each checked alone; the checks across keys are left to the caller. */
static int read_file(ppb_config *cfg, ppb_grid *grid, const char *path, ppb_err *err)
{
    memset(cfg, 0, sizeof *cfg);
    if (grid)
        ppb_grid_clear(grid);
    snprintf(cfg->path, sizeof cfg->path, "%s", path);
    if (apply_defaults(cfg, err))
        return -1;
    char *text = NULL;
    size_t len = 0;
    if (read_text(path, &text, &len, err))
        return -1;
    parse_state st = {.cfg = cfg, .grid = grid, .next = text, .end = text + len};
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        st.next += 3; /* a UTF-8 byte order mark, which inih skips as well */
    int rc = ini_parse_stream(next_line, &st, on_key, &st);
    free(text);
    if (st.text_err)
        return ppb_fail(err, "%s:%d: %s", path, st.err_line, st.why);
    if (rc > 0 && rc == st.err_line)
        return ppb_fail(err, "%s:%d: %s: %s", path, rc, st.what, st.why);
    if (rc > 0)
        return ppb_fail(err, "%s:%d: syntax error (expected [section] or key = value)", path, rc);
    if (rc < 0)
        return ppb_fail(err, "%s: cannot read config", path);
    if (!cfg->name[0] && derive_name(cfg, path, err))
        return -1;
    if (!cfg->out_dir[0])
        snprintf(cfg->out_dir, sizeof cfg->out_dir, "results/%s", cfg->name);
    return 0;
}

int ppb_config_load_grid(ppb_config *cfg, ppb_grid *grid, const char *path, ppb_err *err)
{
    if (read_file(cfg, grid, path, err))
        return -1;
    return apply_material_grid(cfg, grid, err) ? -1 : validate(cfg, err);
}

int ppb_config_load(ppb_config *cfg, const char *path, ppb_err *err)
{
    return ppb_config_load_grid(cfg, NULL, path, err);
}

/* One key set from text, checked alone, as by --set. */
static int override(ppb_config *cfg, ppb_grid *grid, const char *section, const char *key,
                    const char *value, ppb_err *err)
{
    char qs[96], qk[96];
    int i = find_key(section, key);
    char why[1200];
    if (i < 0) {
        unknown_why(section, key, 1, why, sizeof why);
        return ppb_fail(err, "--set %s.%s: %s", shown(section, qs, sizeof qs),
                        shown(key, qk, sizeof qk), why);
    }
    /* A key set again replaces an earlier list on it. */
    if (grid)
        ppb_grid_remove(grid, i);
    if (set_key(cfg, grid, i, value, why, sizeof why))
        return ppb_fail(err, "--set %s.%s: %s", section, key, why);
    cfg->origin[i].from_set = 1;
    return 0;
}

int ppb_config_set_grid(ppb_config *cfg, ppb_grid *grid, const char *section, const char *key,
                        const char *value, ppb_err *err)
{
    if (override(cfg, grid, section, key, value, err))
        return -1;
    return apply_material_grid(cfg, grid, err) ? -1 : validate(cfg, err);
}

int ppb_config_set(ppb_config *cfg, const char *section, const char *key, const char *value,
                   ppb_err *err)
{
    return ppb_config_set_grid(cfg, NULL, section, key, value, err);
}

/* --set method.NAME.KEY=VALUE (eq: its '='): KEY is what follows the last dot before the '='
 * (a NAME may hold dots), checked as the file's [method.NAME] KEY is (on_method_key). */
static int set_method_key(ppb_config *cfg, const char *set, const char *eq, ppb_err *err)
{
    char q[96], section[128], key[64];
    const char *name = set + 7, *dot = NULL;
    for (const char *p = name; p < eq; p++)
        if (*p == '.')
            dot = p;
    if (!dot || dot == name || dot + 1 == eq || (size_t)(dot - set) >= sizeof section ||
        (size_t)(eq - dot - 1) >= sizeof key)
        return ppb_fail(err,
                        "--set %s: expected method.NAME.KEY=VALUE (KEY: command, timeout or "
                        "surfaces)",
                        shown(set, q, sizeof q));
    snprintf(section, sizeof section, "%.*s", (int)(dot - set), set);
    snprintf(key, sizeof key, "%.*s", (int)(eq - dot - 1), dot + 1);
    parse_state st = {.cfg = cfg, .from_set = 1};
    if (!on_method_key(&st, section, key, eq + 1)) {
        char qs[160];
        return ppb_fail(err, "--set %s.%s: %s", shown(section, qs, sizeof qs),
                        shown(key, q, sizeof q), st.why);
    }
    return 0;
}

int ppb_config_load_sets(ppb_config *cfg, ppb_grid *grid, const char *path, const char *const *sets,
                         int nsets, ppb_err *err)
{
    if (read_file(cfg, grid, path, err))
        return -1;
    for (int j = 0; j < nsets; j++) {
        char q[96];
        const char *eq = strchr(sets[j], '=');
        const char *dot = strchr(sets[j], '.');
        if (!eq || !dot || dot > eq || dot == sets[j] || dot + 1 == eq)
            return ppb_fail(err, "--set %s: expected SECTION.KEY=VALUE",
                            shown(sets[j], q, sizeof q));
        if (strncmp(sets[j], "method.", 7) == 0) {
            if (set_method_key(cfg, sets[j], eq, err))
                return -1;
            continue;
        }
        char section[64], key[64];
        size_t ns = (size_t)(dot - sets[j]), nk = (size_t)(eq - dot - 1);
        if (ns >= sizeof section || nk >= sizeof key)
            return ppb_fail(err, "--set %s: no such key", shown(sets[j], q, sizeof q));
        memcpy(section, sets[j], ns);
        section[ns] = '\0';
        memcpy(key, dot + 1, nk);
        key[nk] = '\0';
        if (override(cfg, grid, section, key, eq + 1, err))
            return -1;
    }
    return apply_material_grid(cfg, grid, err) ? -1 : validate(cfg, err);
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
    return apply_material(out, err) ? -1 : validate(out, err);
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

void ppb_surfaces_write(unsigned mask, FILE *out)
{
    const char *sep = "";
    for (int k = 0; k < 4; k++)
        if (mask & (1u << k)) {
            fprintf(out, "%sS%d", sep, k + 1);
            sep = ", ";
        }
    fputc('\n', out);
}

void ppb_config_write_resolved(const ppb_config *cfg, FILE *out)
{
    for (int i = 0; i < NKEYS; i++) {
        fprintf(out, "%s.%s = ", keys[i].section, keys[i].key);
        write_value(cfg, &keys[i], out);
        fputc('\n', out);
    }
    for (int i = 0; i < cfg->nexternal; i++) {
        fprintf(out, "method.%s.command = %s\n", cfg->external[i].name, cfg->external[i].command);
        if (cfg->external[i].timeout > 0) /* given: in the file or by --set */
            fprintf(out, "method.%s.timeout = %.17g\n", cfg->external[i].name,
                    cfg->external[i].timeout);
        if (cfg->external[i].surfaces) {
            fprintf(out, "method.%s.surfaces = ", cfg->external[i].name);
            ppb_surfaces_write(cfg->external[i].surfaces, out);
        }
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
        else if (k->type == K_MATERIAL)
            snprintf(range, sizeof range, "none or a name of `ppbench materials`");
        fprintf(out, "| %s | %s | %s | %s | %s | %s |\n", k->section, k->key, type_names[k->type],
                k->def[0] ? k->def : "(see meaning)", range, k->help);
    }
}

/* A real in the shortest of %.15g, %.16g, %.17g that strtod reads back as the same double
 * (0.95, not 0.94999999999999996; %.17g always round-trips an IEEE 754 binary64). */
static void write_real_short(double v, FILE *out)
{
    char buf[40];
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    fputs(buf, out);
}

static void write_value_short(const ppb_config *cfg, const key_def *k, FILE *out)
{
    if (k->type == K_REAL)
        write_real_short(*(const double *)((const char *)cfg + k->offset), out);
    else
        write_value(cfg, k, out);
}

/* The [method.NAME] definitions: as "method.NAME.key = value" lines (ini 0) or as sections
 * (ini 1), a long command cut at single spaces into indented continuation lines, which the
 * parser joins back with one space. */
static void write_externals(const ppb_config *cfg, int ini, FILE *out)
{
    for (int i = 0; i < cfg->nexternal; i++) {
        const ppb_external_def *d = &cfg->external[i];
        if (!ini) {
            fprintf(out, "method.%s.command = %s\n", d->name, d->command);
        } else {
            fprintf(out, "\n[method.%s]\ncommand =", d->name);
            const char *s = d->command;
            for (int first = 1; *s; first = 0) {
                size_t n = strlen(s), cut = n;
                for (size_t j = 1; n > 150 && j < n - 1 && j < 150; j++)
                    if (s[j] == ' ' && s[j - 1] != ' ' && s[j + 1] != ' ')
                        cut = j;
                fprintf(out, "%s%.*s\n", first ? " " : "  ", (int)cut, s);
                s += cut < n ? cut + 1 : cut;
            }
        }
        if (d->timeout > 0 && ini)
            fprintf(out, "timeout = %.17g\n", d->timeout);
        else if (d->timeout > 0)
            fprintf(out, "method.%s.timeout = %.17g\n", d->name, d->timeout);
        if (d->surfaces) {
            if (ini)
                fprintf(out, "surfaces = ");
            else
                fprintf(out, "method.%s.surfaces = ", d->name);
            ppb_surfaces_write(d->surfaces, out);
        }
    }
}

void ppb_config_write_readable(const ppb_config *cfg, FILE *out)
{
    for (int i = 0; i < NKEYS; i++) {
        fprintf(out, "%s.%s = ", keys[i].section, keys[i].key);
        write_value_short(cfg, &keys[i], out);
        fputc('\n', out);
    }
    write_externals(cfg, 0, out);
}

/* Key k holds a value the config's material set (apply_material). */
static int set_by_material(const ppb_config *cfg, int k)
{
    if (strcmp(keys[k].section, "medium") != 0 || !ppb_material_find(cfg->material))
        return 0;
    for (size_t j = 0; j < sizeof material_keys / sizeof material_keys[0]; j++)
        if (strcmp(keys[k].key, material_keys[j]) == 0)
            return 1;
    return 0;
}

void ppb_config_write_ini(const ppb_config *cfg, FILE *out)
{
    fprintf(out, "; the resolved config of the run beside it (ppbench run THIS_FILE repeats it)\n");
    for (int i = 0; i < NKEYS; i++) {
        int seen = 0;
        for (int j = 0; j < i && !seen; j++)
            seen = strcmp(keys[j].section, keys[i].section) == 0;
        if (seen)
            continue;
        fprintf(out, "\n[%s]\n", keys[i].section);
        for (int j = i; j < NKEYS; j++)
            if (strcmp(keys[j].section, keys[i].section) == 0) {
                /* A key the material sets is not given beside it (apply_material refuses
                 * that): its value stays as a comment. */
                fprintf(out, "%s%s = ", set_by_material(cfg, j) ? "; " : "", keys[j].key);
                write_value_short(cfg, &keys[j], out);
                fputc('\n', out);
            }
    }
    write_externals(cfg, 1, out);
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

int ppb_config_nkeys(void)
{
    return NKEYS;
}

void ppb_config_key_info(int key, ppb_key_info *info)
{
    const key_def *k = &keys[key];
    memset(info, 0, sizeof *info);
    info->section = k->section;
    info->key = k->key;
    info->mc = k->mc;
    info->integer = k->type == K_INT || k->type == K_LLONG;
    info->number = info->integer || k->type == K_REAL;
    info->min = k->min;
    info->max = k->max;
    info->def = k->def;
    for (int i = 0; k->enums && k->enums[i].name && i < 15; i++)
        info->enums[i] = k->enums[i].name;
    char name[128];
    snprintf(name, sizeof name, "%s.%s", k->section, k->key);
    for (size_t i = 0; i < sizeof keyed_when_set / sizeof keyed_when_set[0]; i++)
        info->keyed_when_set |= strcmp(name, keyed_when_set[i]) == 0;
}

int ppb_config_key_at_default(const ppb_config *cfg, int key)
{
    /* A copy of cfg with the key set to its default, both written as the cache's key writes
     * them (on the heap: a config is tens of KB). */
    ppb_config *def = malloc(sizeof *def);
    char why[512], a[2048] = "", b[2048] = "";
    int same = 0;
    if (def) {
        *def = *cfg;
        FILE *fa = fmemopen(a, sizeof a - 1, "w"), *fb = fmemopen(b, sizeof b - 1, "w");
        if (fa && fb && set_key(def, NULL, key, keys[key].def, why, sizeof why) == 0) {
            write_value(cfg, &keys[key], fa);
            write_value(def, &keys[key], fb);
            fflush(fa);
            fflush(fb);
            same = strcmp(a, b) == 0;
        }
        if (fa)
            fclose(fa);
        if (fb)
            fclose(fb);
    }
    free(def);
    return same;
}

void ppb_config_write_key(const ppb_config *cfg, int key, FILE *out)
{
    fprintf(out, "%s.%s = ", keys[key].section, keys[key].key);
    write_value(cfg, &keys[key], out);
    fputc('\n', out);
}

int ppb_config_has_method(const ppb_config *cfg, const char *id)
{
    for (int i = 0; i < cfg->nmethods; i++)
        if (strcmp(cfg->methods[i], id) == 0)
            return 1;
    return 0;
}

const ppb_external_def *ppb_config_external(const ppb_config *cfg, const char *id)
{
    for (int i = 0; i < cfg->nexternal; i++)
        if (strcmp(cfg->external[i].name, id) == 0)
            return &cfg->external[i];
    return NULL;
}

const char *ppb_config_external_where(const ppb_config *cfg, const ppb_external_def *d,
                                      const char *key, char *buf, size_t cap)
{
    int set = key ? (strcmp(key, "command") == 0 ? d->command_set : d->timeout_set) : !d->line;
    int line = key ? (strcmp(key, "command") == 0 ? d->command_line : d->timeout_line) : d->line;
    if (set)
        snprintf(buf, cap, "--set method.%s%s%s", d->name, key ? "." : "", key ? key : "");
    else
        snprintf(buf, cap, "%s:%d: [method.%s]%s%s", cfg->path, line ? line : d->line, d->name,
                 key ? " " : "", key ? key : "");
    return buf;
}

const char *ppb_channel_name(int ch)
{
    return enum_value_name(channel_names, ch);
}

int ppb_config_channel(const ppb_config *cfg, int ch, ppb_config *out, ppb_err *err)
{
    const ppb_material *m = ppb_material_find(cfg->material);
    if (cfg->channel != PPB_CHANNEL_RGB || !m || ch < PPB_CH_R || ch > PPB_CH_B)
        return ppb_fail(err, "%s: not a colour config (channel = rgb) or no channel %d", cfg->path,
                        ch);
    *out = *cfg;
    out->channel = ch;
    /* The keys the material sets are given by it alone (apply_material refused any other
     * value), so the channel's medium is the table's, as a config with channel = ch has it. */
    ppb_scene *sc = &out->scene;
    ppb_material_medium(m, (ppb_channel)ch, &sc->sigma_t, &sc->albedo, &sc->g, &sc->n);
    if ((size_t)snprintf(out->out_dir, sizeof out->out_dir, "%s/%s", cfg->out_dir,
                         ppb_channel_name(ch)) >= sizeof out->out_dir)
        return ppb_fail(err, "%s: [output] dir too long for its channel subsets", cfg->path);
    return validate(out, err);
}
