/* config.h: an experiment's settings, read from an INI file (SPEC.md section 9 plus the
 * method settings documented in configs/README.md).
 *
 * Owns the key table (section, key, type, default, range): parsing, validation, defaults and
 * the documentation all come from that one table in config.c. A numeric key may hold a list
 * ("0, 0.5, 0.9" or "0:1:0.25"), which makes the config a sweep; ppb_config_point() resolves
 * one grid point to plain values. Errors read "file:line: key: reason". */
#ifndef PPB_CONFIG_H
#define PPB_CONFIG_H

#include <stdio.h>

#include "base/err.h"
#include "model/scene.h"

#define PPB_MAX_METHODS 16
#define PPB_MAX_AXES    8
#define PPB_MAX_LIST    1024
#define PPB_MAX_KEYS    64

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
} ppb_pp_settings;

typedef struct ppb_mp_settings {
    int pairs;   /* dipole pairs beyond the first (multipole) */
    int samples; /* quadrature nodes per mfp over the lit strip */
} ppb_mp_settings;

/* One swept key: its table index and values. */
typedef struct ppb_axis {
    int key;
    int line;
    int n;
    double values[PPB_MAX_LIST];
} ppb_axis;

typedef struct ppb_config {
    char path[1024];
    char name[128];
    int nmethods;
    char methods[PPB_MAX_METHODS][32];
    ppb_scene scene;
    int samples_dir; /* directions per bin axis for deterministic methods (n x n per bin) */
    int samples_seg; /* points per segment for deterministic methods */
    ppb_mc_settings mc;
    ppb_pp_settings pp;
    ppb_mp_settings mp;
    char out_dir[1024];
    int key_line[PPB_MAX_KEYS]; /* line of each key in the file, 0 = default */
    int naxes;                  /* keys holding lists: a sweep */
    ppb_axis axes[PPB_MAX_AXES];
} ppb_config;

/* Every key at its default (the study's settings); no file involved. */
int ppb_config_defaults(ppb_config *cfg, ppb_err *err);

/* Loads and validates a config; on error nothing in *cfg is meaningful. */
int ppb_config_load(ppb_config *cfg, const char *path, ppb_err *err);

/* Sets one key from a string as if it stood in the file (used by tests and --set). */
int ppb_config_set(ppb_config *cfg, const char *section, const char *key, const char *value,
                   ppb_err *err);

/* Number of grid points (1 when nothing is swept), and the config of point i (row-major over
 * the axes in file order). */
long long ppb_config_npoints(const ppb_config *cfg);
int ppb_config_point(const ppb_config *cfg, long long i, ppb_config *out, ppb_err *err);

/* Writes every resolved key as "section.key = value" lines: the canonical form hashed for
 * resume and recorded in provenance. */
void ppb_config_write_resolved(const ppb_config *cfg, FILE *out);

/* The key table as a Markdown table (configs/README.md is generated from it). */
void ppb_config_write_keys(FILE *out);

/* Name of swept key k ("medium.g") into buf, and its value in cfg. */
void ppb_config_key_name(int key, char *buf, size_t cap);
double ppb_config_key_value(const ppb_config *cfg, int key);

int ppb_config_has_method(const ppb_config *cfg, const char *id);

#endif
