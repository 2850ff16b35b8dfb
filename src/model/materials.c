#include "model/materials.h"

#include <strings.h>

/* Which copy each number follows (reference: Materials has the comparison):
 *  - Jensen's rows: sigma_s' and sigma_a as pbrt-v4 (src/pbrt/media.cpp,
 *    SubsurfaceParameterTable) and Mitsuba 0.6 (src/medium/materials.h) both carry them, except
 *    chicken1 and chicken2's red sigma_a, 0.015 and 0.018 in pbrt-v4, a tenth of that (0.0015,
 *    0.0018) in Mitsuba: pbrt-v4's are kept. eta as Mitsuba carries it (pbrt-v4 has none).
 *    Spectralon (sigma_a = 0, albedo exactly 1) is left out.
 *  - Narasimhan's rows: sigma_s and g as Mitsuba 0.6 carries them (pbrt-v4 stores the reduced
 *    sigma_s (1 - g) instead, tests/test_materials.c checks the two agree); sigma_a as pbrt-v4
 *    carries it (to 5 significant digits; Mitsuba's are the same rounded to 5 decimals). Names
 *    as pbrt-v4's ("Budweiser Beer", "Orange Powder"; Mitsuba: "Budweiser Beder", "Orange Juice
 *    Powder").
 * Jensen's rows have g = 0, the paper giving only the reduced scattering (ppb_material_medium);
 * Narasimhan's n = 1.33, water's, Mitsuba 0.6's value (the paper measures no index). */
/* clang-format off */
static const ppb_material table[] = {
    /* Jensen, Marschner, Levoy, Hanrahan 2001, "A Practical Model for Subsurface Light
     * Transport", SIGGRAPH, Fig. 5. */
    {"apple", "Apple", PPB_JENSEN2001, {2.29, 2.39, 1.97}, {0.0030, 0.0034, 0.046}, {0, 0, 0}, 1.3},
    {"chicken1", "Chicken1", PPB_JENSEN2001, {0.15, 0.21, 0.38}, {0.015, 0.077, 0.19}, {0, 0, 0}, 1.3},
    {"chicken2", "Chicken2", PPB_JENSEN2001, {0.19, 0.25, 0.32}, {0.018, 0.088, 0.20}, {0, 0, 0}, 1.3},
    {"cream", "Cream", PPB_JENSEN2001, {7.38, 5.47, 3.15}, {0.0002, 0.0028, 0.0163}, {0, 0, 0}, 1.3},
    {"ketchup", "Ketchup", PPB_JENSEN2001, {0.18, 0.07, 0.03}, {0.061, 0.97, 1.45}, {0, 0, 0}, 1.3},
    {"marble", "Marble", PPB_JENSEN2001, {2.19, 2.62, 3.00}, {0.0021, 0.0041, 0.0071}, {0, 0, 0}, 1.5},
    {"potato", "Potato", PPB_JENSEN2001, {0.68, 0.70, 0.55}, {0.0024, 0.0090, 0.12}, {0, 0, 0}, 1.3},
    {"skimmilk", "Skimmilk", PPB_JENSEN2001, {0.70, 1.22, 1.90}, {0.0014, 0.0025, 0.0142}, {0, 0, 0}, 1.3},
    {"skin1", "Skin1", PPB_JENSEN2001, {0.74, 0.88, 1.01}, {0.032, 0.17, 0.48}, {0, 0, 0}, 1.3},
    {"skin2", "Skin2", PPB_JENSEN2001, {1.09, 1.59, 1.79}, {0.013, 0.070, 0.145}, {0, 0, 0}, 1.3},
    {"wholemilk", "Wholemilk", PPB_JENSEN2001, {2.55, 3.21, 3.77}, {0.0011, 0.0024, 0.014}, {0, 0, 0}, 1.3},
    /* Narasimhan, Gupta, Donner, Ramamoorthi, Nayar, Jensen 2006, "Acquiring Scattering
     * Properties of Participating Media by Dilution", SIGGRAPH, Table 1. */
    {"lowfat_milk", "Lowfat Milk", PPB_NARASIMHAN2006, {13.1157, 15.4445, 17.9572}, {0.002875, 0.00575, 0.0115}, {0.93200, 0.90200, 0.85900}, 1.33},
    {"reduced_milk", "Reduced Milk", PPB_NARASIMHAN2006, {13.7335, 15.6003, 17.8007}, {0.0025556, 0.0051111, 0.012778}, {0.81900, 0.79700, 0.74600}, 1.33},
    {"regular_milk", "Regular Milk", PPB_NARASIMHAN2006, {18.2052, 20.3826, 22.3698}, {0.0015333, 0.0046, 0.019933}, {0.75000, 0.71400, 0.68100}, 1.33},
    {"espresso", "Espresso", PPB_NARASIMHAN2006, {7.78262, 8.13050, 8.53875}, {4.7984, 6.5751, 8.8493}, {0.90700, 0.89600, 0.88000}, 1.33},
    {"mint_mocha_coffee", "Mint Mocha Coffee", PPB_NARASIMHAN2006, {3.51133, 4.14383, 5.59667}, {3.772, 5.8228, 7.82}, {0.91000, 0.90700, 0.91400}, 1.33},
    {"lowfat_soy_milk", "Lowfat Soy Milk", PPB_NARASIMHAN2006, {2.03838, 2.32875, 3.90281}, {0.0014375, 0.0071875, 0.035937}, {0.85000, 0.85300, 0.84200}, 1.33},
    {"regular_soy_milk", "Regular Soy Milk", PPB_NARASIMHAN2006, {4.66325, 5.20183, 8.74575}, {0.0019167, 0.0095833, 0.065167}, {0.87300, 0.85800, 0.83200}, 1.33},
    {"lowfat_chocolate_milk", "Lowfat Chocolate Milk", PPB_NARASIMHAN2006, {9.83710, 11.4954, 13.1629}, {0.0115, 0.0368, 0.1564}, {0.93400, 0.92700, 0.91600}, 1.33},
    {"regular_chocolate_milk", "Regular Chocolate Milk", PPB_NARASIMHAN2006, {10.5685, 13.1416, 15.2202}, {0.010063, 0.043125, 0.14375}, {0.86200, 0.83800, 0.80600}, 1.33},
    {"coke", "Coke", PPB_NARASIMHAN2006, {0.00254, 0.00299, 0.00000}, {0.10014, 0.16503, 0.2468}, {0.96500, 0.97200, 0.00000}, 1.33},
    {"pepsi", "Pepsi", PPB_NARASIMHAN2006, {0.00083, 0.00203, 0.00000}, {0.091641, 0.14158, 0.20729}, {0.92600, 0.97900, 0.00000}, 1.33},
    {"sprite", "Sprite", PPB_NARASIMHAN2006, {0.00011, 0.00014, 0.00014}, {0.001886, 0.0018308, 0.0020025}, {0.94300, 0.95300, 0.95200}, 1.33},
    {"gatorade", "Gatorade", PPB_NARASIMHAN2006, {0.03668, 0.04488, 0.05742}, {0.024794, 0.019289, 0.008878}, {0.93300, 0.93300, 0.93500}, 1.33},
    {"chardonnay", "Chardonnay", PPB_NARASIMHAN2006, {0.00021, 0.00033, 0.00048}, {0.010782, 0.011855, 0.023997}, {0.91400, 0.95800, 0.97500}, 1.33},
    {"white_zinfandel", "White Zinfandel", PPB_NARASIMHAN2006, {0.00022, 0.00033, 0.00046}, {0.012072, 0.016184, 0.019843}, {0.91900, 0.94300, 0.97200}, 1.33},
    {"merlot", "Merlot", PPB_NARASIMHAN2006, {0.00081, 0.00000, 0.00000}, {0.11632, 0.25191, 0.29434}, {0.97400, 0.00000, 0.00000}, 1.33},
    {"budweiser_beer", "Budweiser Beer", PPB_NARASIMHAN2006, {0.00029, 0.00055, 0.00059}, {0.011492, 0.024911, 0.057786}, {0.91700, 0.95600, 0.98200}, 1.33},
    {"coors_light_beer", "Coors Light Beer", PPB_NARASIMHAN2006, {0.00062, 0.00127, 0.00000}, {0.006164, 0.013984, 0.034983}, {0.91800, 0.96600, 0.00000}, 1.33},
    {"clorox", "Clorox", PPB_NARASIMHAN2006, {0.02731, 0.03302, 0.03695}, {0.0033542, 0.014892, 0.026297}, {0.91200, 0.90500, 0.89200}, 1.33},
    {"apple_juice", "Apple Juice", PPB_NARASIMHAN2006, {0.00257, 0.00311, 0.00413}, {0.012957, 0.023741, 0.052184}, {0.94700, 0.94900, 0.94500}, 1.33},
    {"cranberry_juice", "Cranberry Juice", PPB_NARASIMHAN2006, {0.00196, 0.00238, 0.00301}, {0.039437, 0.094223, 0.12426}, {0.94700, 0.95100, 0.97400}, 1.33},
    {"grape_juice", "Grape Juice", PPB_NARASIMHAN2006, {0.00138, 0.00000, 0.00000}, {0.10404, 0.23958, 0.29325}, {0.96100, 0.00000, 0.00000}, 1.33},
    {"ruby_grapefruit_juice", "Ruby Grapefruit Juice", PPB_NARASIMHAN2006, {0.15496, 0.15391, 0.15995}, {0.085867, 0.18314, 0.25262}, {0.92900, 0.92900, 0.93100}, 1.33},
    {"white_grapefruit_juice", "White Grapefruit Juice", PPB_NARASIMHAN2006, {0.50499, 0.52742, 0.75282}, {0.0138, 0.018831, 0.056781}, {0.54800, 0.54500, 0.56500}, 1.33},
    {"shampoo", "Shampoo", PPB_NARASIMHAN2006, {0.00797, 0.00874, 0.01127}, {0.014107, 0.045693, 0.061717}, {0.91000, 0.90500, 0.92000}, 1.33},
    {"strawberry_shampoo", "Strawberry Shampoo", PPB_NARASIMHAN2006, {0.00215, 0.00245, 0.00253}, {0.01449, 0.05796, 0.075823}, {0.92700, 0.93500, 0.99400}, 1.33},
    {"head_and_shoulders_shampoo", "Head & Shoulders Shampoo", PPB_NARASIMHAN2006, {0.26747, 0.27696, 0.29574}, {0.084621, 0.15688, 0.20365}, {0.91100, 0.89600, 0.88400}, 1.33},
    {"lemon_tea_powder", "Lemon Tea Powder", PPB_NARASIMHAN2006, {0.74489, 0.83823, 1.00158}, {2.4288, 4.5757, 7.2127}, {0.94600, 0.94600, 0.94900}, 1.33},
    {"orange_powder", "Orange Powder", PPB_NARASIMHAN2006, {0.00193, 0.00213, 0.00226}, {0.001449, 0.003441, 0.007863}, {0.91900, 0.91800, 0.92200}, 1.33},
    {"pink_lemonade_powder", "Pink Lemonade Powder", PPB_NARASIMHAN2006, {0.00123, 0.00133, 0.00131}, {0.001165, 0.002366, 0.003195}, {0.90200, 0.90200, 0.90400}, 1.33},
    {"cappuccino_powder", "Cappuccino Powder", PPB_NARASIMHAN2006, {12.2094, 16.4659, 29.2727}, {35.844, 49.547, 61.084}, {0.84900, 0.84300, 0.92600}, 1.33},
    {"salt_powder", "Salt Powder", PPB_NARASIMHAN2006, {0.13805, 0.15677, 0.17865}, {0.28415, 0.3257, 0.34148}, {0.80200, 0.79300, 0.82100}, 1.33},
    {"sugar_powder", "Sugar Powder", PPB_NARASIMHAN2006, {0.00282, 0.00315, 0.00393}, {0.012638, 0.031051, 0.050124}, {0.92100, 0.91900, 0.93100}, 1.33},
    {"suisse_mocha_powder", "Suisse Mocha Powder", PPB_NARASIMHAN2006, {30.0848, 33.4452, 38.7191}, {17.502, 27.004, 35.433}, {0.90700, 0.89400, 0.88800}, 1.33},
    {"pacific_ocean_surface_water", "Pacific Ocean Surface Water", PPB_NARASIMHAN2006, {0.00180, 0.00183, 0.00228}, {0.031845, 0.031324, 0.030147}, {0.90200, 0.82500, 0.91400}, 1.33},
};
/* clang-format on */

int ppb_material_count(void)
{
    return (int)(sizeof table / sizeof table[0]);
}

const ppb_material *ppb_material_at(int i)
{
    return i >= 0 && i < ppb_material_count() ? &table[i] : NULL;
}

const ppb_material *ppb_material_find(const char *name)
{
    for (int i = 0; i < ppb_material_count(); i++)
        if (strcasecmp(table[i].name, name) == 0)
            return &table[i];
    return NULL;
}

void ppb_material_medium(const ppb_material *m, ppb_channel ch, double *sigma_t, double *albedo,
                         double *g, double *n)
{
    double s = m->sigma_s[ch], a = m->sigma_a[ch];
    *sigma_t = s + a;
    *albedo = s / (s + a); /* every row has sigma_a > 0 */
    *g = m->g[ch];
    *n = m->n;
}

static const char *source_name(ppb_material_source s)
{
    return s == PPB_JENSEN2001 ? "Jensen et al. 2001, Fig. 5" : "Narasimhan et al. 2006, Table 1";
}

void ppb_materials_write(FILE *out)
{
    fprintf(out,
            "| material | source (row) | sigma_s R G B, 1/mm | sigma_a R G B, 1/mm | g R G B | n "
            "|\n|---|---|---|---|---|---|\n");
    for (int i = 0; i < ppb_material_count(); i++) {
        const ppb_material *m = &table[i];
        fprintf(out, "| %s | %s (%s) | %g %g %g%s | %g %g %g | %g %g %g | %g |\n", m->name,
                source_name(m->source), m->row, m->sigma_s[0], m->sigma_s[1], m->sigma_s[2],
                m->source == PPB_JENSEN2001 ? " (reduced)" : "", m->sigma_a[0], m->sigma_a[1],
                m->sigma_a[2], m->g[0], m->g[1], m->g[2], m->n);
    }
    fprintf(out, "\nA config takes one channel: `[medium] material = NAME`, `channel = r|g|b`, "
                 "`[experiment] unit = mm`\n(docs/reference.md, Materials). Jensen's rows give "
                 "only the reduced sigma_s':\nthey are taken with g = 0 and sigma_s = sigma_s' "
                 "(the similarity relation).\n");
}
