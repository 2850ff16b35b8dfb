/* paper.h: what Shinya et al. (2009) published that ppbench compares against: Table 2, the RMS
 * error against Monte Carlo in percent at the cells next to x = 0 (R_x0, T_x0) of the four
 * uniform cases, per method column of the paper. A method says which column is its own
 * (methods/method.h: paper_column); this module names no method of ppbench. */
#ifndef PPB_PAPER_H
#define PPB_PAPER_H

/* The paper's method columns in its order ("proposed", "MP", "MP+S", "S"), NULL-ended. */
extern const char *const ppb_paper_columns[];

/* Table 2's value for (case, cell, column) in percent, or NAN where the paper has none. */
double ppb_paper_table2(const char *case_name, const char *cell, const char *column);

/* The column's place in the paper's order, or -1 when it is not one of the paper's. */
int ppb_paper_column_rank(const char *column);

#endif
