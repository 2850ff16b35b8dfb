/* slab_budget.c: the plane-parallel slab solver's error against adding-doubling, split into
 * single and multiple scattering (docs/methods.md, "Slab solver: error budget against
 * adding-doubling"; `make build/slab_budget`).
 *
 * usage: slab_budget DIRS MODE [G] [--sfi K] [--diffuse [--nodes K]] [--ref FILE] [--collars C]
 *   DIRS cells per hemisphere, MODE the delta-M mode (0 off, 1 on, 2 auto), G only the cases of
 *   that g. Reads tests/data/adding_doubling_ref.csv (iadpython, tests/data/
 *   gen_adding_doubling_ref.py) from the repository root, or --ref FILE with the same first
 *   eight columns (tau0, albedo, g, n, UR1, UT1, and two more; --diffuse needs them to be URU,
 *   UTU). Per case (normal incidence):
 *   dR, dT: UR1 and UT1 of the solver less adding-doubling;
 *   dR_ss, dT_ss: the cells' single scattering less the exact one. The exact single
 *   scattering of the slab (beam D e^-tau down and its reflection U e^-(tau0 - tau) up, each
 *   scattered once, then the faces' reflection series F(mu) in closed form, leaving through 1 -
 *   F) is integrated over mu by Gauss-Legendre on 120 intervals graded geometrically in theta
 *   towards the HG peak, split at the critical angle; the cells' single scattering is the same
 *   closed form per mirror pair of cells (it couples no cells): mu -> k_i, p -> the cell's
 *   exact mean of p (pp_phase_row), F -> the cell's mean reflectance (pp_fresnel_ring_mean);
 *   dR_ms, dT_ms: the rest, the multiply scattered light's error.
 *   --sfi K: the multiply scattered part taken instead from the exit radiance (pp_exit_radiance,
 *   the source function integrated along each direction) less its exact single scattering,
 *   Gauss-Legendre (6 nodes) on K equal theta intervals; dR, dT are then exact single scattering
 *   plus that.
 *   --collars C: the partition with C collars per hemisphere ([pp] collars; 0, the default, the
 *   near-square cells).
 *   --diffuse: URU and UTU (diffuse incidence, 2 int UR1(mu) mu dmu in air) by Gauss-Legendre
 *   in mu (--nodes K, default 12), one solve per node; printed beside adding-doubling's.
 * Last line: the worst |difference| of each column. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/quadrature.h"
#include "kernels/ppb_fresnel.h"
#include "physics/directions.h"
#include "physics/phase.h"
#include "physics/ppsolver.h"

#define GL 20 /* Gauss nodes per interval of the exact single scattering */

typedef struct ad_case {
    double tau0, albedo, g, n, ur1, ut1, uru, utu;
} ad_case;

/* The beam inside at normal incidence: downward D e^-tau, upward U e^-(tau0 - tau). */
static void beam_sums(double tau0, double nr, double *D, double *U)
{
    double F0 = nr > 1 ? ppb_fresnel(1.0, nr) : 0.0, e0 = exp(-tau0);
    *D = (1 - F0) / (1 - F0 * F0 * e0 * e0);
    *U = *D * F0 * e0;
}

/* Singly scattered radiance leaving the faces along inside cosine m (L0 up at the top, L1 down
 * at the bottom, inside, before the exit's 1 - F), for the scattering phase values pb (into the
 * up direction from the downward beam) and pf (into the down direction from it), and the face
 * reflectance F along m. */
static void ss_faces(double tau0, double a, double D, double U, double m, double pb, double pf,
                     double F, double *L0, double *L1)
{
    double e0 = exp(-tau0);
    double H = -expm1(-tau0 * (1 + 1 / m)) / (1 + m);
    double G = fabs(m - 1) < 1e-9 ? tau0 * e0 : (exp(-tau0 / m) - e0) / (m - 1);
    double A = a * (D * pb * H + U * pf * G), B = a * (D * pf * G + U * pb * H);
    double e = exp(-tau0 / m);
    *L0 = (A + e * F * B) / (1 - e * e * F * F);
    *L1 = B + e * F * *L0;
}

static void exact_ss(const ad_case *c, double *R1, double *T1)
{
    double D, U, x[GL], wq[GL], edges[122], r = 0, t = 0;
    beam_sums(c->tau0, c->n, &D, &U);
    ppb_gauss_legendre(GL, x, wq);
    int ne = 0;
    edges[ne++] = 0.0;
    for (int k = 0; k <= 120; k++)
        edges[ne++] = 1e-6 * pow(0.5 * M_PI / 1e-6, k / 120.0);
    double thc = c->n > 1 ? acos(sqrt(1 - 1 / (c->n * c->n))) : -1;
    for (int k = 0; k + 1 < ne; k++) {
        double cuts[3] = {edges[k], edges[k + 1], edges[k + 1]};
        int nc = 2;
        if (thc > edges[k] && thc < edges[k + 1])
            cuts[1] = thc, nc = 3;
        for (int s = 0; s + 1 < nc; s++) {
            double a0 = cuts[s], a1 = cuts[s + 1];
            for (int j = 0; j < GL; j++) {
                double th = 0.5 * (a0 + a1) + 0.5 * (a1 - a0) * x[j], m = cos(th);
                double wt = 0.5 * (a1 - a0) * wq[j] * sin(th), L0, L1;
                double F = c->n > 1 ? ppb_fresnel(m, 1 / c->n) : 0.0;
                ss_faces(c->tau0, c->albedo, D, U, m, pp_hg(c->g, -m), pp_hg(c->g, m), F, &L0, &L1);
                r += 2 * M_PI * wt * m * (1 - F) * L0;
                t += 2 * M_PI * wt * m * (1 - F) * L1;
            }
        }
    }
    *R1 = r, *T1 = t;
}

static int collars; /* --collars: the partition's collars per hemisphere (0: square cells) */

static int cell_ss(const ad_case *c, int N, double *R1, double *T1)
{
    pp_dirs d;
    ppb_err err;
    double mu_snap = c->n > 1 ? sqrt(1 - 1 / (c->n * c->n)) : 0.0;
    if (pp_dirs_make_collars(N, 0, mu_snap, collars, &d, &err) != 0) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    double *F = calloc(2 * (size_t)N, sizeof(double)), wL[3] = {0, -1, 0}, D, U, r = 0, t = 0;
    if (!F || pp_phase_row(&d, c->g, wL, F, &err) != 0) {
        free(F), pp_dirs_free(&d);
        return -1;
    }
    beam_sums(c->tau0, c->n, &D, &U);
    for (int i = 0; i < N; i++) {
        double m = d.k[i], lo, hi, p0, p1, L0, L1;
        pp_dirs_bounds(&d, i, &lo, &hi, &p0, &p1);
        double Rc = c->n > 1 ? pp_fresnel_ring_mean(lo, hi, c->n) : 0.0;
        ss_faces(c->tau0, c->albedo, D, U, m, F[i] / d.area[i], F[N + i] / d.area[i], Rc, &L0, &L1);
        r += d.area[i] * m * (1 - Rc) * L0;
        t += d.area[i] * m * (1 - Rc) * L1;
    }
    free(F);
    pp_dirs_free(&d);
    *R1 = r, *T1 = t;
    return 0;
}

/* Exact single scattering leaving into air along air cosine ma. */
static double ss_exit(const ad_case *c, double ma, int top)
{
    double D, U, L0, L1, nr = c->n;
    beam_sums(c->tau0, nr, &D, &U);
    double m = nr > 1 ? sqrt(1 - (1 - ma * ma) / (nr * nr)) : ma;
    double F = nr > 1 ? ppb_fresnel(m, 1 / nr) : 0.0;
    ss_faces(c->tau0, c->albedo, D, U, m, pp_hg(c->g, -m), pp_hg(c->g, m), F, &L0, &L1);
    return (1 - F) / (nr * nr) * (top ? L0 : L1);
}

/* Multiply scattered flux out of each face by source-function integration (no azimuth at
 * normal incidence). */
static void sfi_ms(const pp_solution *s, const ad_case *c, int nint, double *Rm, double *Tm)
{
    double x[6], wq[6], r = 0, t = 0;
    ppb_gauss_legendre(6, x, wq);
    for (int k = 0; k < nint; k++) {
        double a0 = 0.5 * M_PI * k / nint, a1 = 0.5 * M_PI * (k + 1) / nint;
        for (int j = 0; j < 6; j++) {
            double th = 0.5 * (a0 + a1) + 0.5 * (a1 - a0) * x[j];
            double wt = 0.5 * (a1 - a0) * wq[j] * sin(th), m = cos(th);
            double wu[3] = {sin(th), m, 0}, wd[3] = {sin(th), -m, 0};
            r += 2 * M_PI * wt * m * (pp_exit_radiance(s, wu) - ss_exit(c, m, 1));
            t += 2 * M_PI * wt * m * (pp_exit_radiance(s, wd) - ss_exit(c, m, 0));
        }
    }
    *Rm = r, *Tm = t;
}

/* UR1 and UT1 at air cosine mu (the solver's). */
static int totals_at(const ad_case *c, int N, int mode, double mu, double *ur, double *ut,
                     pp_solution **keep)
{
    pp_params p = {c->tau0, c->albedo, c->g, mu, N};
    pp_solution *s;
    ppb_err err;
    if (pp_solve_collars(&p, c->n, mode, collars, NULL, &s, NULL, &err) != 0) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    double R, T, B, spec, btop;
    pp_totals(s, &R, &T, &B);
    pp_boundary_totals(s, &spec, &btop);
    *ur = spec + R + btop, *ut = T + B - btop;
    if (keep)
        *keep = s;
    else
        pp_free(s);
    return 0;
}

static void worst(double *w, int k, double v)
{
    w[k] = fmax(w[k], fabs(v));
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr,
                "usage: slab_budget DIRS MODE [G] [--sfi K] [--diffuse [--nodes K]] [--ref FILE] "
                "[--collars C]\n");
        return 2;
    }
    int N = atoi(argv[1]), mode = atoi(argv[2]), sfi = 0, diffuse = 0, nodes = 12;
    double gf = -1;
    const char *ref = "tests/data/adding_doubling_ref.csv";
    for (int i = 3; i < argc; i++) {
        if (strcmp(argv[i], "--sfi") == 0 && i + 1 < argc)
            sfi = atoi(argv[++i]);
        else if (strcmp(argv[i], "--collars") == 0 && i + 1 < argc)
            collars = atoi(argv[++i]);
        else if (strcmp(argv[i], "--ref") == 0 && i + 1 < argc)
            ref = argv[++i];
        else if (strcmp(argv[i], "--diffuse") == 0)
            diffuse = 12;
        else if (strcmp(argv[i], "--nodes") == 0 && i + 1 < argc)
            nodes = atoi(argv[++i]);
        else
            gf = atof(argv[i]);
    }
    FILE *f = fopen(ref, "r");
    char line[512];
    if (!f || !fgets(line, sizeof line, f)) {
        fprintf(stderr, "%s: cannot read (run from the repository root)\n", ref);
        return 2;
    }
    double w[8] = {0};
    printf("tau0 albedo g n | dR dT | dR_ss dT_ss | dR_ms dT_ms | R1 T1%s\n",
           diffuse ? " | dURU dUTU" : "");
    ad_case c;
    while (fgets(line, sizeof line, f)) {
        if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &c.tau0, &c.albedo, &c.g, &c.n, &c.ur1,
                   &c.ut1, &c.uru, &c.utu) != 8 ||
            (gf > 0 && fabs(c.g - gf) > 1e-9))
            continue;
        double ur, ut, R1, T1, r1c, t1c;
        pp_solution *s;
        if (totals_at(&c, N, mode, 1.0, &ur, &ut, &s) != 0)
            return 1;
        double dr = ur - c.ur1, dt = ut - c.ut1;
        exact_ss(&c, &R1, &T1);
        if (cell_ss(&c, N, &r1c, &t1c) != 0)
            return 1;
        double drs = r1c - R1, dts = t1c - T1, drm = dr - drs, dtm = dt - dts;
        if (sfi > 0) {
            double R, T, B, spec, btop, Rm, Tm;
            pp_totals(s, &R, &T, &B);
            pp_boundary_totals(s, &spec, &btop);
            sfi_ms(s, &c, sfi, &Rm, &Tm);
            drm = spec + btop + R1 + Rm - c.ur1, dtm = (B - btop) + T1 + Tm - c.ut1;
            dr = drm, dt = dtm, drs = dts = 0.0;
        }
        pp_free(s);
        printf("%4g %6g %4g %4g | %+.2e %+.2e | %+.2e %+.2e | %+.2e %+.2e | %.5f %.5f", c.tau0,
               c.albedo, c.g, c.n, dr, dt, drs, dts, drm, dtm, R1, T1);
        worst(w, 0, dr), worst(w, 1, dt), worst(w, 2, drs), worst(w, 3, dts);
        worst(w, 4, drm), worst(w, 5, dtm);
        if (diffuse) {
            double x[64], wq[64], uru = 0, utu = 0;
            nodes = nodes < 1 ? 1 : (nodes > 64 ? 64 : nodes);
            ppb_gauss_legendre(nodes, x, wq);
            for (int j = 0; j < nodes; j++) {
                double mu = 0.5 + 0.5 * x[j];
                if (totals_at(&c, N, mode, mu, &ur, &ut, NULL) != 0)
                    return 1;
                uru += wq[j] * mu * ur, utu += wq[j] * mu * ut; /* 2 int mu dmu: weights / 2 */
            }
            printf(" | %+.2e %+.2e", uru - c.uru, utu - c.utu);
            worst(w, 6, uru - c.uru), worst(w, 7, utu - c.utu);
        }
        printf("\n");
        fflush(stdout);
    }
    fclose(f);
    printf("worst: R %.2e T %.2e | ss %.2e %.2e | ms %.2e %.2e", w[0], w[1], w[2], w[3], w[4],
           w[5]);
    if (diffuse)
        printf(" | URU %.2e UTU %.2e", w[6], w[7]);
    printf("\n");
    return 0;
}
