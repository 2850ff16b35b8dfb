/* materials.h: measured media by name (reference: Materials): the table of Jensen, Marschner,
 * Levoy & Hanrahan 2001 (Fig. 5: reduced scattering sigma_s', absorption sigma_a in mm^-1 and
 * the index eta) and of Narasimhan, Gupta, Donner, Ramamoorthi, Nayar & Jensen 2006 (Table 1:
 * sigma_s, sigma_a in mm^-1 and g, per colour channel), as carried by the renderers' copies
 * (pbrt-v4 src/pbrt/media.cpp, Mitsuba 0.6 src/medium/materials.h; which copy each number
 * follows, and where they disagree, is in docs/reference.md, Materials).
 *
 * Owns the table and the one mapping from a row and a colour channel to the medium's
 * (sigma_t, albedo, g, n): config.c's `[medium] material` and `channel` use it, `ppbench
 * materials` prints it. */
#ifndef PPB_MATERIALS_H
#define PPB_MATERIALS_H

#include <stdio.h>

typedef enum ppb_material_source {
    PPB_JENSEN2001 = 0,    /* Jensen et al. 2001, Fig. 5: sigma_s' (reduced), sigma_a, eta */
    PPB_NARASIMHAN2006 = 1 /* Narasimhan et al. 2006, Table 1: sigma_s, sigma_a, g */
} ppb_material_source;

typedef enum ppb_channel { PPB_CH_R = 0, PPB_CH_G = 1, PPB_CH_B = 2 } ppb_channel;

typedef struct ppb_material {
    const char *name; /* the config's name: lower case, '_' for blanks ("lowfat_milk") */
    const char *row;  /* the row as the papers' copies name it ("Lowfat Milk") */
    ppb_material_source source;
    double sigma_s[3]; /* mm^-1, R G B: Jensen's reduced sigma_s', Narasimhan's sigma_s */
    double sigma_a[3]; /* mm^-1, R G B */
    double g[3];       /* HG asymmetry: Narasimhan's; 0 for Jensen's rows (see below) */
    double n;          /* Jensen's eta; 1.33 for Narasimhan's rows (Mitsuba's water value) */
} ppb_material;

int ppb_material_count(void);
const ppb_material *ppb_material_at(int i);

/* The row named name (case-insensitive), or NULL. */
const ppb_material *ppb_material_find(const char *name);

/* The medium of one channel: sigma_t = sigma_s + sigma_a (mm^-1), albedo = sigma_s / sigma_t,
 * g and n. A Jensen row has only the reduced sigma_s' = sigma_s (1 - g): it is taken with g = 0
 * and sigma_s = sigma_s' (the similarity relation's choice, as pbrt-v4's presets and Mitsuba
 * 0.6 make it), so its sigma_t is the reduced extinction sigma_t' = sigma_s' + sigma_a. */
void ppb_material_medium(const ppb_material *m, ppb_channel ch, double *sigma_t, double *albedo,
                         double *g, double *n);

/* The table as Markdown, with each row's source (`ppbench materials`). */
void ppb_materials_write(FILE *out);

#endif
