/* paper.c: Shinya et al. 2009, Table 2 (paper.h). */
#include "model/paper.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

const char *const ppb_paper_columns[] = {"proposed", "MP", "MP+S", "S", NULL};

/* One row of Table 2: a case's cell, the RMS error (%) of each column in ppb_paper_columns'
 * order. */
typedef struct paper_row {
    const char *case_name, *cell;
    double value[4];
} paper_row;

static const paper_row table2[] = {
    {"uniform_g0_normal", "R_x0", {13, 13, 23, 65}},
    {"uniform_g0_normal", "T_x0", {4, 72, 24, 56}},
    {"uniform_g0_oblique", "R_x0", {10, 43, 101, 57}},
    {"uniform_g0_oblique", "T_x0", {8, 210, 302, 89}},
    {"uniform_gm05_normal", "R_x0", {20, 23, 51, 48}},
    {"uniform_gm05_normal", "T_x0", {5, 84, 189, 47}},
    {"uniform_gp05_normal", "R_x0", {24, 19, 6, 81}},
    {"uniform_gp05_normal", "T_x0", {7, 58, 26, 66}},
};

int ppb_paper_column_rank(const char *column)
{
    for (int k = 0; column && ppb_paper_columns[k]; k++)
        if (strcmp(column, ppb_paper_columns[k]) == 0)
            return k;
    return -1;
}

double ppb_paper_table2(const char *case_name, const char *cell, const char *column)
{
    int k = ppb_paper_column_rank(column);
    for (size_t i = 0; k >= 0 && i < sizeof table2 / sizeof table2[0]; i++)
        if (strcmp(table2[i].case_name, case_name) == 0 && strcmp(table2[i].cell, cell) == 0)
            return table2[i].value[k];
    return NAN;
}
