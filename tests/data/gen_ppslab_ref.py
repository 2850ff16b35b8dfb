#!/usr/bin/env python3
"""Regenerates tests/data/ppslab_ref.csv and ppslab_ref_totals.csv: slab exit radiance and
totals from an independent solver, PythonicDISORT (pip install PythonicDISORT==1.8), a
discrete-ordinates code (Stamnes' DISORT in Python), for tests/test_ppsolver.c.

Cases: tau0 = 3, albedo in {0.95, 0.475}, g in {0, 0.5, -0.5}, theta_L in {0, 45} deg.
HG Legendre coefficients g^l, NQuad = 32 streams, no delta-M, no corrections (g <= 0.5 is
resolved without them). DISORT's frame matches ppsolver's: mu > 0 up, tau down, and the beam
and the outgoing direction are both directions of travel, so the beam at phi0 = 0 travels
toward +x. Radiance is per unit E_perp (I0 = 1). Rows: the S1 (tau = 0, mu > 0) and S2
(tau = tau0, mu < 0) quadrature directions times phi = 0..180 deg every 30 deg; mu_out is the
cosine to the face's outward normal and weight the projected solid angle the row stands for
(mu w_mu dphi, trapezoid in phi), used by the RMS (docs/reference.md, Metrics).
"""
import csv
import os

import numpy as np
import PythonicDISORT

NQUAD = 32
PHIS = np.arange(0, 181, 30)


def solve(tau0, albedo, g, theta):
    mu0 = np.cos(np.radians(theta))
    leg = g ** np.arange(NQUAD)
    mu_arr, Fp, Fm, u0, u = PythonicDISORT.pydisort(
        tau0, albedo, NQUAD, leg, mu0, 1.0, 0.0, NFourier=NQUAD)
    w_half = np.polynomial.legendre.leggauss(NQUAD // 2)[1] / 2  # double-Gauss on [0, 1]
    phi = np.radians(PHIS)
    dphi = np.full(len(phi), np.radians(30.0))
    dphi[0] = dphi[-1] = np.radians(15.0)
    rows = []
    half = NQUAD // 2
    top = u(0.0, phi)[:half, :]           # mu > 0 at tau = 0
    bottom = u(tau0, phi)[half:, :]       # mu < 0 at tau0
    for surf, field in (("S1", top), ("S2", bottom)):
        for i in range(half):
            mu = abs(mu_arr[i] if surf == "S1" else mu_arr[half + i])
            for j, p in enumerate(PHIS):
                # both halves of the folded azimuth: factor 2
                rows.append((surf, mu, p, 2 * mu * w_half[i] * dphi[j], field[i, j]))
    R = Fp(0.0) / mu0
    Tdiff, Tdir = Fm(tau0)
    return rows, R, Tdiff / mu0, Tdir / mu0


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "ppslab_ref.csv"), "w", newline="") as f, \
            open(os.path.join(here, "ppslab_ref_totals.csv"), "w", newline="") as ft:
        out, tot = csv.writer(f), csv.writer(ft)
        out.writerow(["tau0", "albedo", "g", "theta_deg", "surface", "mu_out", "phi_deg",
                      "weight", "radiance"])
        tot.writerow(["tau0", "albedo", "g", "theta_deg", "R", "T", "ballistic"])
        for albedo in (0.95, 0.475):
            for g in (0.0, 0.5, -0.5):
                for theta in (0.0, 45.0):
                    rows, R, T, B = solve(3.0, albedo, g, theta)
                    for r in rows:
                        out.writerow([3.0, albedo, g, theta, r[0], "%.15g" % r[1], r[2],
                                      "%.12g" % r[3], "%.10g" % r[4]])
                    tot.writerow([3.0, albedo, g, theta, "%.12g" % R, "%.12g" % T,
                                  "%.12g" % B])


if __name__ == "__main__":
    main()
