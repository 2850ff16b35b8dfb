#!/usr/bin/env python3
"""ring_slab.py: an independent check of the slab solver's polar-ring partition (docs/methods.md,
the slab solver's error budget; src/physics/directions.h, phase_rings.h).

At normal light a slab's field is constant on each ring of directions, and then the direction
cells solve exactly the ring (azimuthal mode m = 0) system, whatever the rings' azimuthal cuts,
provided the cell-pair integrals are exact. This script solves that ring system directly, with
nothing of ppbench's code: discrete ordinates on given ring edges in mu, the pair integrals of
HG over ring pairs from its Legendre series, S_rr' = pi sum_l (2l + 1) g^l I_l(r) I_l(r')
(I_l the integral of P_l over the ring; the series summed until g^l < 1e-15, the diagonal set by
conservation), the same delta-M as the solver (P -> F E + (1 - F) P, F from the cells' diffusion
coefficient at albedo 1 against their isotropic one), the Fresnel ring means of the boundary
condition, the beam's reflection series, and the eigen solution of the 2R ODE system. It prints
UR1 and UT1 less adding-doubling (tests/data/adding_doubling_ref.csv) for the ring edges of the
equal-area collars (the partition the solver had until 2026-12-07) and of equal-width rings.

usage: python3 scripts/ring_slab.py [--collars C ...] [--all]   (pip install numpy scipy)
  default: the six g 0.95, tau0 10, n > 1 cases; --all: the 108 cases (about a minute).
"""
import argparse
import csv
import math
import os

import numpy as np
from numpy.polynomial.legendre import leggauss
from scipy.special import eval_legendre


def fresnel(mu, n):
    """Unpolarised reflectance from inside (index n) to air at inside cosine mu."""
    s2 = n * n * (1 - mu * mu)
    if s2 >= 1:
        return 1.0
    ct = math.sqrt(1 - s2)
    rs = (n * mu - ct) / (n * mu + ct)
    rp = (mu - n * ct) / (mu + n * ct)
    return 0.5 * (rs * rs + rp * rp)


def ring_reflectance(lo, hi, n):
    """int F mu dmu / int mu dmu over [lo, hi]: total reflection exactly, the rest by Gauss."""
    if n == 1.0:
        return 0.0
    mc = math.sqrt(1 - 1 / n ** 2)
    x, w = leggauss(64)
    num = 0.0
    if min(hi, mc) > lo:
        num += 0.5 * (min(hi, mc) ** 2 - lo ** 2)
    a, b = max(lo, mc), hi
    if b > a:
        m = 0.5 * (a + b) + 0.5 * (b - a) * x
        num += 0.5 * (b - a) * sum(wi * fresnel(mi, n) * mi for mi, wi in zip(m, w))
    return num / (0.5 * (hi * hi - lo * lo))


def legendre_integrals(L, lo, hi):
    """int_lo^hi P_l for l = 0 .. L."""
    ph = [eval_legendre(l, hi) for l in range(L + 2)]
    pl = [eval_legendre(l, lo) for l in range(L + 2)]
    out = np.zeros(L + 1)
    out[0] = hi - lo
    for l in range(1, L + 1):
        out[l] = ((ph[l + 1] - ph[l - 1]) - (pl[l + 1] - pl[l - 1])) / (2 * l + 1)
    return out


def solve(edges, tau0, albedo, g, n):
    """UR1, UT1 of the slab at normal light on rings with cosine edges 1 = e0 > ... > eR = 0."""
    e = np.array(edges)
    R = len(e) - 1
    L = int(math.log(1e-15) / math.log(g)) + 10
    lo = np.concatenate([e[1:], -e[:-1]])   # cells 0..R-1 go down (mu > 0 along tau)
    hi = np.concatenate([e[:-1], -e[1:]])
    area = 2 * np.pi * (hi - lo)
    k = 0.5 * (hi + lo)
    I = np.array([legendre_integrals(L, lo[i], hi[i]) for i in range(2 * R)])
    wl = (2 * np.arange(L + 1) + 1) * g ** np.arange(L + 1)
    S = np.pi * (I * wl) @ I.T
    np.fill_diagonal(S, 0)
    np.fill_diagonal(S, area - S.sum(1))
    P = S / area[:, None]
    Sa, Sb = S[:R, :R], S[:R, R:]
    h = np.linalg.solve(np.diag(area[:R]) - (Sa - Sb), area[:R] * k[:R])
    Dc = 2 * np.sum(area[:R] * k[:R] * h) / (4 * np.pi)
    D0 = 2 * np.sum(area[:R] * k[:R] ** 2) / (4 * np.pi)
    F = 1 - (1 - g) * Dc / D0
    P = F * np.eye(2 * R) + (1 - F) * P
    Fb = ((n - 1) / (n + 1)) ** 2
    down = (1 - Fb) / (1 - Fb ** 2 * math.exp(-2 * tau0))
    up = down * Fb * math.exp(-tau0)

    def hg_band(a, b):  # 2 pi int_a^b p(mu) dmu, HG about mu = 1
        return (1 - g * g) / (2 * g) * ((1 + g * g - 2 * g * b) ** -0.5 - (1 + g * g - 2 * g * a) ** -0.5)

    qd = np.array([hg_band(lo[i], hi[i]) for i in range(2 * R)]) / area
    qu = np.concatenate([qd[R:], qd[:R]])
    E = np.eye(2 * R)
    lam, V = np.linalg.eig(-(E - albedo * P) / k[:, None])
    lam, V = lam.real, V.real
    Zd = np.linalg.solve(E - albedo * P - np.diag(k), albedo * qd * down)
    Zu = np.linalg.solve(E - albedo * P + np.diag(k), albedo * qu * up)
    ref = np.where(lam > 0, tau0, 0.0)
    H0, H1 = V * np.exp(lam * (0 - ref)), V * np.exp(lam * (tau0 - ref))
    P0, P1 = Zd + Zu * math.exp(-tau0), Zd * math.exp(-tau0) + Zu
    Rc = np.array([ring_reflectance(e[i + 1], e[i], n) for i in range(R)])
    dn, upc = np.arange(R), np.arange(R, 2 * R)
    A = np.vstack([H0[dn] - Rc[:, None] * H0[upc], H1[upc] - Rc[:, None] * H1[dn]])
    b = -np.concatenate([P0[dn] - Rc * P0[upc], P1[upc] - Rc * P1[dn]])
    c = np.linalg.solve(A, b)
    I0, I1 = H0 @ c + P0, H1 @ c + P1
    ur1 = Fb + np.sum(area[:R] * k[:R] * (1 - Rc) * I0[upc]) + (1 - Fb) * up * math.exp(-tau0)
    ut1 = np.sum(area[:R] * k[:R] * (1 - Rc) * I1[dn]) + (1 - Fb) * down * math.exp(-tau0)
    return ur1, ut1


def split_rings(theta, r_snap, split=4):
    """Cuts the two rings beside the snapped edge theta[r_snap] into `split` each."""
    out = []
    for r in range(len(theta) - 1):
        a, b = theta[r], theta[r + 1]
        m = split if r in (r_snap - 1, r_snap) else 1
        out += [a + (b - a) * j / m for j in range(m)]
    return out + [theta[-1]]


def equal_width(collars, n):
    """The polar rings: collars + 1 rings of equal width, snapped at the critical angle."""
    R = collars + 1
    if n == 1.0:
        return [math.cos(0.5 * math.pi * r / R) for r in range(R + 1)]
    tc = math.acos(math.sqrt(1 - 1 / n ** 2))
    rs = max(1, min(R - 1, round(tc / (0.5 * math.pi) * R)))
    th = [tc * r / rs for r in range(rs + 1)] + \
         [tc + (0.5 * math.pi - tc) * r / (R - rs) for r in range(1, R - rs + 1)]
    return [math.cos(t) for t in split_rings(th, rs)]


def equal_area(N, collars, n):
    """The equal-area collars below a one-cell cap (directions.c as it was): edges at
    mu = 1 - C / N, C the cells above, rounded in steps of two."""
    cap = math.acos(1 - 1 / N)
    tc = math.acos(math.sqrt(1 - 1 / n ** 2)) if n > 1 else 0.0
    coll, r_snap, split = collars, 0, 1
    if tc > cap:
        r_snap = max(1, min(coll - 1, round((tc - cap) / (0.5 * math.pi - cap) * coll)))
        split = 4
    if r_snap:
        th = [cap + (tc - cap) * r / r_snap for r in range(r_snap + 1)] + \
             [tc + (0.5 * math.pi - tc) * r / (coll - r_snap) for r in range(1, coll - r_snap + 1)]
        th = split_rings(th, r_snap, split)
    else:
        th = [cap + (0.5 * math.pi - cap) * r / coll for r in range(coll + 1)]
    rings = len(th) - 1
    done, cums = 1, []
    for r in range(1, rings + 1):
        cum = N if r == rings else 2 * round(0.5 * N * (1 - math.cos(th[r])))
        cum = max(min(cum, N - 2 * (rings - r)), done + (1 if r == 1 else 2))
        cums.append(cum)
        done = cum
    return [1.0, 1 - 1 / N] + [1 - c / N for c in cums[:-1]] + [0.0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--collars", type=int, nargs="*", default=[55, 79])
    ap.add_argument("--all", action="store_true")
    a = ap.parse_args()
    here = os.path.dirname(os.path.abspath(__file__))
    rows = list(csv.DictReader(open(os.path.join(here, "..", "tests", "data",
                                                 "adding_doubling_ref.csv"))))
    cases = [r for r in rows if a.all or (float(r["g"]) == 0.95 and float(r["tau0"]) == 10
                                          and float(r["n"]) > 1)]
    for C in a.collars:
        for name, make in (("equal-area", lambda n: equal_area(334, C, n)),
                           ("equal-width", lambda n: equal_width(C, n))):
            worst = 0.0
            for r in cases:
                t, al, g, n = (float(r[x]) for x in ("tau0", "albedo", "g", "n"))
                ur, ut = solve(make(n), t, al, g, n)
                worst = max(worst, abs(ur - float(r["UR1"])), abs(ut - float(r["UT1"])))
            print(f"{C} collars, {name} rings: worst |UR1|, |UT1| difference {worst:.3g} "
                  f"over {len(cases)} cases")


if __name__ == "__main__":
    main()
