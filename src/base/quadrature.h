/* quadrature.h: Gauss-Legendre rules, generated (one generator for every fixed order the
 * project uses: the direction cells' product nodes, the phase matrix, the light maps' beam
 * integral, the multipole's strip integrals, the mp ballistic fraction). */
#ifndef PPB_QUADRATURE_H
#define PPB_QUADRATURE_H

/* Gauss-Legendre nodes x and weights w of order q on [-1, 1], nodes in descending order (x[0]
 * nearest +1, x[q-1] = -x[0]). Nodes are exact to the last bit for the orders checked in
 * tests/test_base.c; weights to a few ulps (the weight formula uses P_q' at the last Newton
 * iterate). Meant for q <= 16 (physics/directions.h's PP_QMAX). */
void ppb_gauss_legendre(int q, double *x, double *w);

#endif
