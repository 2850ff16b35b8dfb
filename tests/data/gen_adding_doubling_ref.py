#!/usr/bin/env python3
"""Regenerates tests/data/adding_doubling_ref.csv: slab totals at strongly forward-peaked
Henyey-Greenstein phase functions from an independent solver, iadpython (pip install
iadpython==0.5.3 numpy scipy), Prahl's adding-doubling method, for tests/test_deltam.c (the
plane-parallel solver's delta-M scaling, reference: Methods, `ppslab`).

Cases: g in {0.7, 0.8, 0.9, 0.95} x albedo in {0.9, 0.99, 0.9999} x n in {1, 1.33, 1.5} x
tau0 in {1, 3, 10}, normal incidence, air on both sides (n_above = n_below = 1, no glass
slides; n is the medium's index). iadpython's Sample.rt() returns
- UR1, UT1: total reflection (specular + diffuse + unscattered light leaving through S1) and
  total transmission (diffuse + unscattered through S2) for a normally incident collimated beam
  of unit power; ppbench's R + specular + ballistic through S1 and T + ballistic through S2;
- URU, UTU: the same for diffuse (Lambertian) incidence (written, not compared).
The quadrature (iadpython applies delta-M itself), measured on this table's worst cases:
- n = 1: quad_pts = 24; iadpython 0.5.3 breaks down from 32 on (3, 0.99, 0.95: UT1 0.9295 at
  24, 0.9206 at 32, 0.437 at 36), and 16, 20, 24 agree within 4e-5.
- n > 1: quad_pts = 48. The points are split at the critical angle and the totals oscillate
  with quad_pts (tau0 1, albedo 0.9, g 0.95, n 1.5: UT1 0.80245, 0.79947, 0.80124, 0.80023,
  0.80077, 0.80053, 0.80060, 0.80055 at 16, 20, ..., 40, 48): 24 is off by 7e-4, 40 and 48
  agree within 6e-5; 64 breaks down (0.7984).
The neighbouring order's values (20 at n = 1, 40 at n > 1) are written too (UR1_alt, UT1_alt,
quad_alt), so the reference's own convergence is visible next to the test's 2e-4.
"""
import csv
import itertools
import os

import iadpython


def rt(tau0, albedo, g, n, quad_pts):
    s = iadpython.Sample(a=albedo, b=tau0, g=g, n=n, n_above=1.0, n_below=1.0,
                         quad_pts=quad_pts)
    return [float(v) for v in s.rt()]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "adding_doubling_ref.csv"), "w", newline="") as f:
        out = csv.writer(f, lineterminator="\n")
        out.writerow(["tau0", "albedo", "g", "n", "UR1", "UT1", "URU", "UTU", "quad",
                      "UR1_alt", "UT1_alt", "quad_alt"])
        for g, albedo, n, tau0 in itertools.product((0.7, 0.8, 0.9, 0.95), (0.9, 0.99, 0.9999),
                                                    (1.0, 1.33, 1.5), (1.0, 3.0, 10.0)):
            quad, alt = (24, 20) if n == 1.0 else (48, 40)
            ur1, ut1, uru, utu = rt(tau0, albedo, g, n, quad)
            ra, ta, _, _ = rt(tau0, albedo, g, n, alt)
            out.writerow([tau0, albedo, g, n] + ["%.12f" % v for v in (ur1, ut1, uru, utu)] +
                         [quad] + ["%.12f" % v for v in (ra, ta)] + [alt])


if __name__ == "__main__":
    main()
