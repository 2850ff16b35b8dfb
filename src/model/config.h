/* config.h: an experiment's settings, read from an INI file (reference: Keys, plus the
 * method settings documented in configs/README.md).
 *
 * Owns the key table (section, key, type, default, range) and the name table of every enum
 * key: parsing, validation, defaults and the documentation all come from those tables in
 * config.c. A numeric key may hold a list ("0, 0.5, 0.9" or "0:1:0.25"), which makes the config
 * a sweep: the lists go into a grid the caller owns (model/grid.h) and ppb_config_point()
 * resolves one grid point to plain values. Errors read "file:line: [section] key: reason".
 *
 * A config is a regular text file of at most 1 MiB, read whole before parsing: anything else
 * (a directory, a device, binary data, a line too long for the INI parser) is refused naming
 * the file and line, and text quoted in a message is escaped (never raw bytes). Integer keys
 * are read as integers: a seed keeps every digit.
 *
 * The config knows no methods: `methods` is a list of id strings, checked against the method
 * registry by the methods layer (ppb_methods_check in methods/registry.h). For such later
 * checks the config records where each key was set (ppb_config_key_fail). */
#ifndef PPB_CONFIG_H
#define PPB_CONFIG_H

#include <stdio.h>

#include "base/err.h"
#include "model/grid.h"
#include "model/scene.h"

/* Whether a key of the table changes the Monte Carlo's result (its tallies, for the same device
 * and kernel): the reference cache's key hashes the resolved value of every PPB_MC_KEY key
 * (methods/mc/mc_cache.h), and no other. Every entry of the table states one of the two; 0 is
 * no decision, which the table's test refuses (tests/test_cache_keys.c). */
typedef enum ppb_mc_key { PPB_MC_KEY = 1, PPB_NOT_MC_KEY = 2 } ppb_mc_key;

/* The length unit of a config (reference: Materials): every length is in it and every
 * coefficient per it. mfp: the study's, the reference medium's mean free path (sigma_t = 1 is
 * that medium); mm: a measured material's, whose coefficients are per mm. The numbers the
 * methods receive are the same either way: the unit says how to read them. */
typedef enum ppb_unit { PPB_UNIT_MFP = 0, PPB_UNIT_MM = 1 } ppb_unit;

#define PPB_MAX_METHODS 16
#define PPB_MAX_KEYS    96

typedef struct ppb_mc_settings {
    long long photons;   /* photon budget */
    int batches;         /* independent batches for standard errors */
    long long seed;      /* Philox key */
    int workgroup;       /* local size; 0 = let the runtime choose */
    long long chunk;     /* photons per kernel launch; 0 = sized to the device */
    long long first;     /* first photon index of this run (a shard of one point) */
    double target_noise; /* stop early when noise_rel at the x = 0 cells falls below; 0 = off */
} ppb_mc_settings;

typedef struct ppb_pp_settings {
    int directions; /* direction cells per hemisphere (M = 2 x directions) */
    int modes;      /* n_e: modes kept in the march, 0 = all */
    int table;      /* 0 = R table (Eq. 15), 1 = S table (Eq. 16-17) */
    double step;    /* ray-march step length, mfp */
    int albedos;    /* albedo nodes of the tables (Sec. 3.3) */
    int map_res;    /* cells per mfp of the D(x) and average-albedo maps */
    int delta_m;    /* PPB_DELTA_M_*: the slab solver's delta-M (ppslab and the march) */
    int collars;    /* the direction cells' collars per hemisphere, 0 = near-square cells */
} ppb_pp_settings;

/* [pp] delta_m; the values of PP_DELTA_M_* (physics/ppsolver.h, which asserts it). */
typedef enum { PPB_DELTA_M_OFF = 0, PPB_DELTA_M_ON = 1, PPB_DELTA_M_AUTO = 2 } ppb_delta_m;

typedef struct ppb_mp_settings {
    int pairs;   /* dipole pairs beyond the first (multipole) */
    int samples; /* quadrature nodes per mfp over the lit strip */
} ppb_mp_settings;

typedef struct ppb_burley_settings {
    int samples;    /* quadrature nodes per profile length d over the lit strip */
    int directions; /* direction cells per hemisphere of the slab solve that gives A */
} ppb_burley_settings;

typedef struct ppb_bdipole_settings {
    int samples; /* quadrature nodes per 1 / sigma_tr over the lit strip */
} ppb_bdipole_settings;
typedef struct ppb_pbd_settings {
    int nodes; /* Gauss-Legendre nodes per panel of the strip's x and z integrals */
} ppb_pbd_settings;
typedef struct ppb_dirpole_settings {
    int samples; /* nodes per diffusion length along the strip and per unit of t along z */
} ppb_dirpole_settings;

/* [rte2d] delta_m: none, the truncated function an HG (on), or the Legendre series (legendre). */
typedef enum {
    PPB_RTE_DELTA_M_OFF = 0,
    PPB_RTE_DELTA_M_HG = 1,
    PPB_RTE_DELTA_M_LEGENDRE = 2
} ppb_rte_delta_m_kind;

/* [rte2d] moment: the cells' first-moment correction off, on, or where g > 0 (auto). */
typedef enum {
    PPB_RTE_MOMENT_OFF = 0,
    PPB_RTE_MOMENT_ON = 1,
    PPB_RTE_MOMENT_AUTO = 2
} ppb_rte_moment;

/* [rte2d] source: the emission in each of the sweep's regions flat, or linear in x and y. */
typedef enum { PPB_RTE_SOURCE_FLAT = 0, PPB_RTE_SOURCE_LINEAR = 1 } ppb_rte_source;

typedef struct ppb_rte2d_settings {
    double spacing;    /* grid node spacing over the cross-section, mfp */
    int directions;    /* direction cells per hemisphere */
    double step;       /* march step in the x-y plane, mfp */
    double tol;        /* relative residual of the converged solve */
    int refinements;   /* K: stop after K steps of Eq. 5 from I_pp; 0 = converge */
    int delta_m;       /* PPB_RTE_DELTA_M_*: delta-M with the single-scattering correction (TMS) */
    int delta_m_order; /* delta-M's truncation order L (f = g^L); 0 = sqrt(2 directions) */
    int moment;        /* PPB_RTE_MOMENT_*: the cells' phase matrix corrected to HG's g */
    int ims;           /* 1: delta-M's intensity correction of the exit (Nakajima-Tanaka IMS) */
    int source;        /* ppb_rte_source: the sweep's emission in each region */
} ppb_rte2d_settings;

/* A three-dimensional object's settings ([object]; docs/reference.md, Objects). Material 1 is
 * [medium]'s sigma_t, albedo, g and n; material 2 the inclusion's (shape = yokan). The light and
 * the camera are given as the direction toward them, theta from +y and phi from +x toward +z;
 * model/object_build.h turns these into a ppb_object. The tube's methods ignore them. */
typedef enum {
    PPB_OBJ_BOX = 0,
    PPB_OBJ_SPHERE = 1,
    PPB_OBJ_YOKAN = 2,
    PPB_OBJ_MESH = 3,
    PPB_OBJ_FILE = 4
} ppb_object_shape;
typedef struct ppb_object_settings {
    int shape;                       /* ppb_object_shape */
    int nx, ny, nz;                  /* grid voxels */
    double voxel;                    /* voxel edge, in the config's unit */
    double inc_radius;               /* inclusion radius, a fraction of the smallest grid edge */
    double inc_x, inc_y, inc_z;      /* inclusion centre, fractions of the grid's edges */
    double inc_sigma_t, inc_albedo;  /* the inclusion's material */
    char mesh[1024];                 /* shape = mesh: a closed triangle mesh (OBJ) */
    char voxels[1024];               /* shape = file: a voxel file (docs/reference.md, Objects) */
    double light_theta, light_phi;   /* toward the light, degrees */
    double camera_theta, camera_phi; /* toward the camera, degrees */
    int image_w, image_h;            /* camera pixels */
    int patch;                       /* patch edge in boundary faces */
} ppb_object_settings;

/* A method defined by the config itself: a section [method.NAME] with `command` (a shell
 * command holding {scene} and {out}) and an optional `timeout` in seconds, or the same keys
 * given as --set method.NAME.command=... (which defines NAME, or overrides the file's key).
 * The config stores them without knowing what they run (methods/method_external.h runs them;
 * the registry finds NAME as a method id through this list). */
#define PPB_MAX_EXTERNAL 8
typedef struct ppb_external_def {
    char name[32];
    char command[2048];
    double timeout;   /* seconds; 0 = the default (3600) */
    int line;         /* line of the section's first key (0: defined by --set) */
    int command_line; /* line of its command (0: not in the file) */
    int timeout_line; /* line of its timeout (0: not in the file) */
    int command_set;  /* 1: the command is --set's */
    int timeout_set;  /* 1: the timeout is --set's */
    /* The surfaces it answers (docs/external.md, "Partial coverage"): bit k for S(k+1); 0: all
     * of them. The others are not computed: absent from its rows, NaN in its result, left out
     * of every metric. */
    unsigned surfaces;
    int surfaces_line, surfaces_set;
} ppb_external_def;

/* Where a key's value came from, so that checks made after loading name the right place. */
typedef struct ppb_key_origin {
    int line;     /* line of the key in the config file, 0 = not in the file */
    int from_set; /* 1: last set by ppb_config_set (--set on the command line) */
} ppb_key_origin;

/* [medium] channel = rgb: a colour experiment (docs/reference.md, Colour): the runner runs
 * every method for the R, G and B channels, each channel's config from ppb_config_channel;
 * the config's own scene holds the green channel's medium. */
enum { PPB_CHANNEL_RGB = 3 };

typedef struct ppb_config {
    char path[1024];
    char name[128];
    int nmethods;
    char methods[PPB_MAX_METHODS][32]; /* ids as written; methods/registry.h checks them */
    ppb_scene scene;
    int unit;          /* ppb_unit */
    char material[32]; /* a row of model/materials.h by name, or "none" */
    int channel;       /* ppb_channel: the material's colour channel, or PPB_CHANNEL_RGB */
    int samples_dir;   /* directions per bin axis for deterministic methods (n x n per bin) */
    int samples_seg;   /* points per segment for deterministic methods */
    ppb_mc_settings mc;
    ppb_pp_settings pp;
    ppb_mp_settings mp;
    ppb_burley_settings burley;
    ppb_bdipole_settings bdipole;
    ppb_pbd_settings pbd;
    ppb_dirpole_settings dirpole;
    ppb_rte2d_settings rte2d;
    ppb_object_settings object;
    char out_dir[1024];
    double memory_limit; /* GB a method may allocate; 0 = half the machine's (base/memory.h) */
    ppb_key_origin origin[PPB_MAX_KEYS]; /* per key of the table */
    int nexternal;
    ppb_external_def external[PPB_MAX_EXTERNAL]; /* the [method.NAME] sections, in file order */
} ppb_config;

/* Every key at its default (the study's settings); no file involved. */
int ppb_config_defaults(ppb_config *cfg, ppb_err *err);

/* Loads and validates a config; on error nothing in *cfg is meaningful. A key holding a list
 * becomes an axis of grid (emptied first; a key keeps its list's first value in *cfg); with grid
 * NULL a list is an error. */
int ppb_config_load_grid(ppb_config *cfg, ppb_grid *grid, const char *path, ppb_err *err);
int ppb_config_load(ppb_config *cfg, const char *path, ppb_err *err); /* grid NULL */

/* Loads a config as ppb_config_load_grid, then applies overrides "section.key=value" (the
 * command line's --set) in order, each as if it stood in the file, and only then checks the
 * keys against each other: the overrides' order does not matter, and a conflict names the
 * --set option or the file line of each side. */
int ppb_config_load_sets(ppb_config *cfg, ppb_grid *grid, const char *path, const char *const *sets,
                         int nsets, ppb_err *err);

/* Sets one key from a string as if it stood in the file, then checks the keys against each
 * other (used by tests); a list replaces the key's axis in grid (NULL: lists refused), a plain
 * value removes it. */
int ppb_config_set_grid(ppb_config *cfg, ppb_grid *grid, const char *section, const char *key,
                        const char *value, ppb_err *err);
int ppb_config_set(ppb_config *cfg, const char *section, const char *key, const char *value,
                   ppb_err *err); /* grid NULL */

/* The config of grid point i (model/grid.h), validated; grid NULL has the one point 0. */
int ppb_config_point(const ppb_config *cfg, const ppb_grid *grid, long long i, ppb_config *out,
                     ppb_err *err);

/* Channel ch (PPB_CH_R, G or B) of a colour config (channel = rgb): *out is cfg with channel
 * = ch and that channel's medium (ppb_material_medium), exactly the config of the same file
 * with channel = r, g or b, and its output directory <out_dir>/<r|g|b>. */
int ppb_config_channel(const ppb_config *cfg, int ch, ppb_config *out, ppb_err *err);

/* The name a config writes for channel value ch ("r", "g", "b", "rgb"). */
const char *ppb_channel_name(int ch);

/* Fails with why (printf format) about a key, named where it was set: "file:line: [section]
 * key: why" (line 0 when the key kept its default), or "--set section.key: why". Returns -1. */
int ppb_config_key_fail(const ppb_config *cfg, const char *section, const char *key, ppb_err *err,
                        const char *fmt, ...) __attribute__((format(printf, 5, 6)));

/* ppb_config_key_fail about the key of grid axis a (where its list was given). */
int ppb_config_axis_fail(const ppb_config *cfg, const ppb_grid *grid, int a, ppb_err *err,
                         const char *why);

/* Writes every resolved key as "section.key = value" lines: the canonical form hashed for
 * resume and recorded in provenance. */
void ppb_config_write_resolved(const ppb_config *cfg, FILE *out);

/* The same lines with every real in the shortest form that reads back as the same double
 * (0.95): provenance.txt's, for people (the hash keeps ppb_config_write_resolved's form). */
void ppb_config_write_readable(const ppb_config *cfg, FILE *out);

/* Every resolved key as an INI file ([section] then key = value, reals as in
 * ppb_config_write_readable): config.ini, which ppb_config_load reads back into the same
 * settings, so `ppbench run config.ini` repeats the run. */
void ppb_config_write_ini(const ppb_config *cfg, FILE *out);

/* The key table as a Markdown table (configs/README.md is generated from it). */
void ppb_config_write_keys(FILE *out);

/* Name of key k of the table ("medium.g", as in ppb_axis.key) into buf, and its value in cfg. */
void ppb_config_key_name(int key, char *buf, size_t cap);
double ppb_config_key_value(const ppb_config *cfg, int key);

/* What the key table says of key k (0 <= k < ppb_config_nkeys()), for code that iterates the
 * table: the reference cache's key, and the tests that change every key in turn. */
typedef struct ppb_key_info {
    const char *section, *key;
    ppb_mc_key mc;
    int number;  /* 1: an integer or real in [min, max] */
    int integer; /* 1: an integer */
    double min, max;
    const char *def;       /* the default as written in the table */
    const char *enums[16]; /* an enum key's value names, NULL-terminated; else enums[0] NULL */
    /* 1: a PPB_MC_KEY key that joins the reference cache's key only when it is not at its
     * default (ppb_config_key_at_default), because at its default it changes nothing: a key
     * added after references were traced and shipped, which keep their keys. */
    int keyed_when_set;
} ppb_key_info;
int ppb_config_nkeys(void);
void ppb_config_key_info(int key, ppb_key_info *info);

/* 1 when key k holds its default value in cfg (its written value is the default's). */
int ppb_config_key_at_default(const ppb_config *cfg, int key);

/* Key k's line of ppb_config_write_resolved ("section.key = value\n", the canonical form). */
void ppb_config_write_key(const ppb_config *cfg, int key, FILE *out);

int ppb_config_has_method(const ppb_config *cfg, const char *id);

/* A [method.NAME] surfaces mask as its config value ("S1, S2") and a newline. */
void ppb_surfaces_write(unsigned mask, FILE *out);

/* The [method.NAME] section of id, or NULL. */
const ppb_external_def *ppb_config_external(const ppb_config *cfg, const char *id);

/* Where d's key (`command`, `timeout`; NULL: the definition) was given, for a message about it:
 * "--set method.NAME.KEY" when --set gave it, else "file:line: [method.NAME] KEY". */
const char *ppb_config_external_where(const ppb_config *cfg, const ppb_external_def *d,
                                      const char *key, char *buf, size_t cap);

/* How close a mistyped name is to a known one (case-folded Levenshtein distance; a typed
 * prefix of 3 or more characters is close): the distance, or -1 when not close enough for a
 * "did you mean" (more than 1 edit for names of up to 4 characters, more than 2 beyond). */
int ppb_name_distance(const char *typed, const char *known);

#endif
