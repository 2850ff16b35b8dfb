/* legendre_rings.h: the addition theorem's pieces for the phase tests' expected values
 * (test_phase_series.c, test_phase_rings.c): Legendre polynomials by their recurrence and
 * their closed-form integrals over a ring's mu range. Over whole rings only the m = 0
 * harmonics of a phase function survive, so ring sums of cell integrals follow from these. */
#ifndef PPB_TEST_LEGENDRE_RINGS_H
#define PPB_TEST_LEGENDRE_RINGS_H

#include <stdlib.h>

/* P_0 .. P_{lmax}(x) by the upward three-term recurrence (stable on [-1, 1]). */
static inline void lr_legendre(double x, int lmax, double *P)
{
    P[0] = 1.0;
    if (lmax > 0)
        P[1] = x;
    for (int l = 1; l < lmax; l++)
        P[l + 1] = ((2.0 * l + 1.0) * x * P[l] - l * P[l - 1]) / (l + 1.0);
}

/* I_l = integral of P_l over [a, b], l < L, in closed form: (P_{l+1} - P_{l-1}) / (2l + 1)
 * between the ends. 0 on success, -1 out of memory. */
static inline int lr_ring_integrals(double a, double b, int L, double *I)
{
    double *Pa = malloc(sizeof(double) * ((size_t)L + 2)),
           *Pb = malloc(sizeof(double) * ((size_t)L + 2));
    if (!Pa || !Pb) {
        free(Pa), free(Pb);
        return -1;
    }
    lr_legendre(a, L, Pa);
    lr_legendre(b, L, Pb);
    I[0] = b - a;
    for (int l = 1; l < L; l++)
        I[l] = ((Pb[l + 1] - Pb[l - 1]) - (Pa[l + 1] - Pa[l - 1])) / (2.0 * l + 1.0);
    free(Pa), free(Pb);
    return 0;
}

#endif
