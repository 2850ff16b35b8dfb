/* burley_fit.c: Burley's s refitted to a Monte Carlo line-searchlight profile (reference:
 * Outputs, results/searchlight; scripts/searchlight_study.sh builds and runs it).
 *
 * usage: burley_fit PROFILE.csv A ALBEDO DMIN DMAX [S]
 *   PROFILE.csv: the study's folded profile (distance,seg_lo,seg_hi,mc,mc_se,...): S1's exitance
 *   per unit line strength averaged over a segment [seg_lo, seg_hi] of distances from the line.
 * Prints "s_fit,rms,A_pp": the rate s (per mfp; g = 0, so l = 1 mfp and s = s_fit(A) / l is the
 * paper's dimensionless scaling factor, Christensen & Burley 2015 Eq. 5) minimising the relative
 * least squares sum ((model - mc) / mc)^2 over the segments with DMIN <= distance <= DMAX, the
 * model Burley's line kernel (burley_profile.h, A s (K0(s r) + K0(s r / 3)) / (4 pi), 2 K0 the
 * closed-form z integral) averaged exactly over the segment (ppb_burley_strip: the profile is
 * radial, so a segment's average of the line's exitance is the line kernel integrated over the
 * segment's distances), with A as given (the Monte Carlo's own total reflectance); the RMS of
 * the relative residual at the optimum; and A from ppb_burley_albedo (the plane-parallel
 * solver's total diffuse reflectance, what the `burley` method uses) for comparison.
 * Golden-section search on ln s over [ln 0.05, ln 20] to 1e-10: the objective is unimodal in s
 * there (measured on the five albedos; the bracket's ends are far from every optimum). With S
 * given, no fit: the same line for s = S (Eq. 5's s, to compare its RMS). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/burley/burley_profile.h"
#include "methods/burley/method_burley.h"

#define MAXSEG 8192

typedef struct fit_data {
    int n;
    double lo[MAXSEG], hi[MAXSEG], mc[MAXSEG];
    double A;
} fit_data;

static double objective(const fit_data *d, double s, double *rms)
{
    ppb_burley b = {.A = d->A, .s = s};
    double sum = 0.0;
    for (int i = 0; i < d->n; i++) {
        double model = ppb_burley_strip(&b, d->lo[i], d->hi[i], 0.0, 32) / (d->hi[i] - d->lo[i]);
        double r = (model - d->mc[i]) / d->mc[i];
        sum += r * r;
    }
    if (rms)
        *rms = sqrt(sum / d->n);
    return sum;
}

static int load(const char *path, double dmin, double dmax, fit_data *d)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    char line[1024];
    d->n = 0;
    if (!fgets(line, sizeof line, f)) { /* header */
        fclose(f);
        return -1;
    }
    while (fgets(line, sizeof line, f) && d->n < MAXSEG) {
        double dist, lo, hi, mc;
        if (sscanf(line, "%lf,%lf,%lf,%lf", &dist, &lo, &hi, &mc) != 4)
            continue;
        if (dist < dmin || dist > dmax || !(mc > 0.0))
            continue;
        d->lo[d->n] = lo;
        d->hi[d->n] = hi;
        d->mc[d->n] = mc;
        d->n++;
    }
    fclose(f);
    return d->n > 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    if (argc != 6 && argc != 7) {
        fprintf(stderr, "usage: burley_fit PROFILE.csv A ALBEDO DMIN DMAX [S]\n");
        return 2;
    }
    static fit_data d;
    d.A = atof(argv[2]);
    double albedo = atof(argv[3]);
    if (load(argv[1], atof(argv[4]), atof(argv[5]), &d)) {
        fprintf(stderr, "burley_fit: %s: no segments in range\n", argv[1]);
        return 2;
    }
    const double phi = 0.5 * (sqrt(5.0) - 1.0);
    double a = log(0.05), b = log(20.0);
    double c = b - phi * (b - a), e = a + phi * (b - a);
    double fc = objective(&d, exp(c), NULL), fe = objective(&d, exp(e), NULL);
    while (b - a > 1e-10) {
        if (fc < fe) {
            b = e;
            e = c;
            fe = fc;
            c = b - phi * (b - a);
            fc = objective(&d, exp(c), NULL);
        } else {
            a = c;
            c = e;
            fc = fe;
            e = a + phi * (b - a);
            fe = objective(&d, exp(e), NULL);
        }
    }
    double s = argc == 7 ? atof(argv[6]) : exp(0.5 * (a + b)), rms;
    objective(&d, s, &rms);
    ppb_err err;
    double A_pp = NAN;
    if (ppb_burley_albedo(albedo, 0.0, 1.0, 1.0, 334, &A_pp, &err))
        fprintf(stderr, "burley_fit: %s\n", err.msg);
    printf("%.6f,%.6f,%.6f\n", s, rms, A_pp);
    return 0;
}
