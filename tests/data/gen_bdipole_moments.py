#!/usr/bin/env python3
"""Reference Fresnel moments for tests/test_bdipole.c: C_i(n) = int_0^1 F(mu, 1/n) mu^i dmu,
i = 1, 2, for light inside a medium of index n meeting the boundary with air, F the exact
unpolarized Fresnel reflectance (Born & Wolf 1.5.2), 1 under total internal reflection.

Independent of the code under test: mpmath's tanh-sinh quadrature at 40 digits, directly in the
inside cosine mu (no change of variable), split at the critical cosine mu_c = sqrt(1 - 1/n^2)
where F has its square-root kink. Prints C lines for the test's table."""
import mpmath as mp

mp.mp.dps = 40


def fresnel(ci, nrel):
    s2 = (1 - ci * ci) / nrel**2
    if s2 >= 1:
        return mp.mpf(1)
    ct = mp.sqrt(1 - s2)
    rs = (ci - nrel * ct) / (ci + nrel * ct)
    rp = (nrel * ci - ct) / (nrel * ci + ct)
    return (rs * rs + rp * rp) / 2


def moment(i, n):
    n = mp.mpf(n)
    mu_c = mp.sqrt(1 - 1 / n**2)
    f = lambda mu: fresnel(mu, 1 / n) * mu**i
    return mp.quad(f, [0, mu_c, 1])


for n in ["1.1", "1.2", "1.33", "1.4", "1.5", "2.5"]:
    print("{%s, %s, %s}," % (n, mp.nstr(moment(1, n), 18), mp.nstr(moment(2, n), 18)))
