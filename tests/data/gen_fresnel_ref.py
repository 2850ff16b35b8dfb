#!/usr/bin/env python3
"""Regenerates tests/data/fresnel_ref.csv: slab totals with Fresnel boundaries from an
independent solver, iadpython (pip install iadpython==0.5.3 scipy), Prahl's adding-doubling
method, for tests/test_fresnel.c.

Cases: tau0 in {1, 3}, albedo in {0.95, 0.475}, g in {-0.5, 0, 0.5}, n in {1.33, 1.4, 1.5},
normal incidence, air on both sides (n_above = n_below = 1, no glass slides). iadpython's
Sample.rt() returns UR1 and UT1: the total reflection (specular + diffuse + unscattered light
leaving through S1) and total transmission (diffuse + unscattered through S2) for a collimated
beam of unit power. quad_pts = 24 (iadpython 0.5.3 is wrong above 32, and 16 -> 24 still moves
values by ~1e-4 at n = 1.4: both are written so the convergence is visible).
"""
import csv
import itertools
import os

import iadpython


def rt(tau0, albedo, g, n, quad_pts):
    s = iadpython.Sample(a=albedo, b=tau0, g=g, n=n, n_above=1.0, n_below=1.0,
                         quad_pts=quad_pts)
    ur1, ut1, _, _ = s.rt()
    return float(ur1), float(ut1)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "fresnel_ref.csv"), "w", newline="") as f:
        out = csv.writer(f, lineterminator="\n")
        out.writerow(["tau0", "albedo", "g", "n", "UR1", "UT1", "UR1_q16", "UT1_q16"])
        for tau0, albedo, g, n in itertools.product((1.0, 3.0), (0.95, 0.475),
                                                    (-0.5, 0.0, 0.5), (1.33, 1.4, 1.5)):
            r24, t24 = rt(tau0, albedo, g, n, 24)
            r16, t16 = rt(tau0, albedo, g, n, 16)
            out.writerow([tau0, albedo, g, n] + ["%.12f" % v for v in (r24, t24, r16, t16)])


if __name__ == "__main__":
    main()
