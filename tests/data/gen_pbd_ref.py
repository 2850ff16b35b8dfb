#!/usr/bin/env python3
"""Reference values for tests/test_pbd.c (photon beam diffusion as pbrt-v4 ships it), computed
independently of the C code: numpy + scipy.integrate.quad (adaptive Gauss-Kronrod), the exact
Fresnel reflectance written out here, pbrt-v4's formulas (bssrdf.cpp) transcribed from their
description in src/methods/pbd/pbd_table.h.

Rows (pbd_ref.csv):
  ms,rho,g,eta,r,sampled100,unsampled   BeamDiffusionMS at sigma_t = 1: pbrt's 100-quantile mean,
                                        and the integral it estimates, int_0^inf sigma_t'
                                        exp(-sigma_t' z) f(z) dz (quad)
  ss,rho,g,eta,r,sampled100,unsampled   the same for BeamDiffusionSS (density sigma_t exp(-sigma_t
                                        (t - t_c)) on t > t_c)
  rhoeff,row,g,eta,sampled100,unsampled the plane integral int_0^{r_max} 2 pi r (SS + MS) dr of
                                        the table's albedo row `row`, r_max = 2.5e-3 1.2^62 (the
                                        table's last radius), by quad on each table interval: of
                                        pbrt's 100-sample profile (what the spline integral rhoEff
                                        approximates) and of the unsampled profile
Run: python3 tests/data/gen_pbd_ref.py > tests/data/pbd_ref.csv
"""
import math

import numpy as np
from scipy.integrate import quad


def fresnel(mu, n_rel):
    """Unpolarized Fresnel reflectance, incidence cosine mu, relative index n_rel = n_t / n_i."""
    s2t = (1.0 - mu * mu) / (n_rel * n_rel)
    if s2t >= 1.0:
        return 1.0
    ct = math.sqrt(1.0 - s2t)
    rs = (mu - n_rel * ct) / (mu + n_rel * ct)
    rp = (n_rel * mu - ct) / (n_rel * mu + ct)
    return 0.5 * (rs * rs + rp * rp)


def fm1(e):
    e2, e3, e4, e5 = e**2, e**3, e**4, e**5
    if e < 1:
        return 0.45966 - 1.73965 * e + 3.37668 * e2 - 3.904945 * e3 + 2.49277 * e4 - 0.68441 * e5
    return -4.61686 + 11.1136 * e - 10.4646 * e2 + 5.11455 * e3 - 1.27198 * e4 + 0.12746 * e5


def fm2(e):
    e2, e3, e4, e5 = e**2, e**3, e**4, e**5
    if e < 1:
        return 0.27614 - 0.87350 * e + 1.12077 * e2 - 0.65095 * e3 + 0.07883 * e4 + 0.04860 * e5
    r1 = 1 / e
    return (-547.033 + 45.3087 * r1**3 - 218.725 * r1**2 + 458.843 * r1 + 404.557 * e
            - 189.519 * e2 + 54.9327 * e3 - 9.00603 * e4 + 0.63942 * e5)


def ms_integrand(rho, g, eta, r):
    ss, sa = rho, 1.0 - rho
    sps = ss * (1 - g)
    spt = sa + sps
    rhop = sps / spt
    D = (2 * sa + sps) / (3 * spt * spt)
    str_ = math.sqrt(max(0.0, sa / D))
    c1, c2 = fm1(eta), fm2(eta)
    ze = -2 * D * (1 + 3 * c2) / (1 - 2 * c1)
    cphi, ce = 0.25 * (1 - 2 * c1), 0.5 * (1 - 3 * c2)

    def f(zr):
        zv = -zr + 2 * ze
        dr, dv = math.hypot(r, zr), math.hypot(r, zv)
        phi = (math.exp(-str_ * dr) / dr - math.exp(-str_ * dv) / dv) / (4 * math.pi * D)
        en = (zr * (1 + str_ * dr) * math.exp(-str_ * dr) / dr**3
              - zv * (1 + str_ * dv) * math.exp(-str_ * dv) / dv**3) / (4 * math.pi)
        kappa = 1 - math.exp(-2 * spt * (dr + zr))
        return kappa * rhop * rhop * (phi * cphi + en * ce)

    return f, spt


def ms(rho, g, eta, r, n=100):
    f, spt = ms_integrand(rho, g, eta, r)
    if n:
        return sum(f(-math.log(1 - (i + 0.5) / n) / spt) for i in range(n)) / n
    # unsampled: int_0^1 f(z(u)) du with u = 1 - exp(-spt z), split where f varies
    pts = sorted({min(0.999, 1 - math.exp(-spt * x)) for x in (r / 4, r, 4 * r, 1.0)})
    return quad(lambda u: f(-math.log1p(-u) / spt), 0, 1, points=pts, limit=400,
                epsabs=0, epsrel=1e-11)[0]


def hg(mu, g):
    g = min(0.99, max(-0.99, g))
    d = 1 + g * g - 2 * g * mu
    return (1 - g * g) / (4 * math.pi * d * math.sqrt(d))


def ss(rho, g, eta, r, n=100):
    tc = r * math.sqrt(max(0.0, eta * eta - 1))

    def f(t):
        d = math.hypot(r, t)
        co = t / d
        fo = fresnel(co, 1 / eta) if eta > 1 else 0.0
        return rho * math.exp(-(d + tc)) / d**2 * hg(-co, g) * (1 - fo) * co

    if n:
        return sum(f(tc - math.log(1 - (i + 0.5) / n)) for i in range(n)) / n
    # unsampled: t = t_c - ln(1 - u); split where f peaks (t - t_c ~ r)
    pts = sorted({min(0.999, 1 - math.exp(-x)) for x in (r / 4, r, 4 * r, 1.0)})
    return quad(lambda u: f(tc - math.log1p(-u)), 0, 1, points=pts, limit=400, epsabs=0,
                epsrel=1e-11)[0]


def radii():
    r = [0.0, 2.5e-3]
    for _ in range(62):
        r.append(r[-1] * 1.2)
    return r


def rho_row(i):
    return (1 - math.exp(-8 * i / 99.0)) / (1 - math.exp(-8))


def rhoeff(row, g, eta, n):
    rho, rs = rho_row(row), radii()
    f = lambda r: 2 * math.pi * r * (ss(rho, g, eta, r, n) + ms(rho, g, eta, r, n))
    return sum(quad(f, rs[k], rs[k + 1], limit=200, epsabs=1e-14, epsrel=1e-10)[0]
               for k in range(len(rs) - 1))


def main():
    print("kind,a,g,eta,r,sampled100,unsampled")
    for rho, g, eta in ((0.95, 0.0, 1.0), (0.8, 0.5, 1.4), (0.99, -0.5, 1.4)):
        for r in (0.01, 0.1, 1.0, 5.0):
            print(f"ms,{rho},{g},{eta},{r},{ms(rho, g, eta, r):.17g},{ms(rho, g, eta, r, 0):.17g}")
            print(f"ss,{rho},{g},{eta},{r},{ss(rho, g, eta, r):.17g},{ss(rho, g, eta, r, 0):.17g}")
    for row, g, eta in ((70, 0.0, 1.0), (90, 0.5, 1.4), (50, -0.5, 1.4)):
        print(f"rhoeff,{row},{g},{eta},0,{rhoeff(row, g, eta, 100):.17g},"
              f"{rhoeff(row, g, eta, 0):.17g}")


if __name__ == "__main__":
    main()
