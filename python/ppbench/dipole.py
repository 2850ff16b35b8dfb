"""An external method in Python: the classical dipole (Jensen et al. 2001) for the slab, by
plain quadrature. Run by ppbench as

    [method.dipole_py]
    command = python3 -m ppbench.dipole {scene} {out}

It reads scene.json, writes {out}/radiance.csv and {out}/totals.csv (docs/external.md).

Model (n = 1, so A = 1): reduced coefficients sigma_s' = albedo sigma_t (1 - g), sigma_t' =
sigma_a + sigma_s', alpha' = sigma_s' / sigma_t', D = 1 / (3 sigma_t'), sigma_tr =
sqrt(3 sigma_a sigma_t'); a real source at depth z_r = 1 / sigma_t' and a negative one at
z_v = -(z_r + 4 D). The flux leaving a face at distance r from the entry point (Fick's law) is
    F(r) = alpha' / (4 pi) sum_i q_i h_i (1 + sigma_tr d_i) exp(-sigma_tr d_i) / d_i^3,
d_i = sqrt(r^2 + h_i^2), h_i the source's height below the face (z_i for S1, depth - z_i for
S2), q_i = +-1. The slab's R (T) is 2 pi int_0^inf r F(r) dr, here by composite 8-point
Gauss-Legendre on geometric panels out to 60 / sigma_tr. Stated quadrature error: below 1e-9
relative (doubling the panels changes R and T by less than that; the closed forms
alpha'/2 sum q_i sign(h_i) exp(-sigma_tr |h_i|) agree to 1e-12 at the study's media). The
dipole's exit radiance is Lambertian: cos(theta_L) R / pi on S1 and cos(theta_L) T / pi on S2,
the same in every bin (a negative flux, the first source below a thin slab, is set to 0 as the C
mp method does). Slab scenes only (the tube needs the flux through the sides).

Options (docs/external.md, "Partial coverage"): `--name NAME` writes its rows under NAME (the
config's `{name}`), default dipole_py; `--reflectance-only` writes S1's rows alone (the section
then says `surfaces = S1`) and takes a tube too, as the slab of the tube's height: a reflectance-
only method for the study's every case. `--approx` also takes a stepped medium (the medium at
x < step_x) and n != 1 (A = 1 still): a rough stand-in, for trying the study loop, not a model
of those cases.

    [method.dipole_py]
    command = python3 -m ppbench.dipole --reflectance-only --approx --name {name} {scene} {out}
    surfaces = S1
"""
import math
import os
import sys

# 8-point Gauss-Legendre nodes and weights on [-1, 1]
_GL = [(-0.9602898564975363, 0.1012285362903763), (-0.7966664774136267, 0.2223810344533745),
       (-0.5255324099163290, 0.3137066458778873), (-0.1834346424956498, 0.3626837833783620),
       (0.1834346424956498, 0.3626837833783620), (0.5255324099163290, 0.3137066458778873),
       (0.7966664774136267, 0.2223810344533745), (0.9602898564975363, 0.1012285362903763)]


def plane_integral(f, r_max, panels=60):
    """2 pi int_0^r_max r f(r) dr, composite Gauss-Legendre on geometric panels."""
    edges = [0.0] + [r_max * 1e-6 * (1e6 ** (k / panels)) for k in range(panels + 1)]
    total = 0.0
    for a, b in zip(edges, edges[1:]):
        for x, w in _GL:
            r = 0.5 * (a + b) + 0.5 * (b - a) * x
            total += 0.5 * (b - a) * w * r * f(r)
    return 2.0 * math.pi * total


def dipole_RT(sigma_t, albedo, g, depth, panels=60):
    sigma_s_r = albedo * sigma_t * (1.0 - g)
    sigma_a = (1.0 - albedo) * sigma_t
    sigma_t_r = sigma_a + sigma_s_r
    alpha_r = sigma_s_r / sigma_t_r
    D = 1.0 / (3.0 * sigma_t_r)
    s = math.sqrt(3.0 * sigma_a * sigma_t_r)
    z_r = 1.0 / sigma_t_r
    sources = [(+1.0, z_r), (-1.0, -(z_r + 4.0 * D))]

    def flux(heights):
        def F(r):
            tot = 0.0
            for q, h in heights:
                d = math.sqrt(r * r + h * h)
                tot += q * h * (1.0 + s * d) * math.exp(-s * d) / d ** 3
            return alpha_r / (4.0 * math.pi) * tot
        return F

    r_max = 60.0 / s
    R = plane_integral(flux(sources), r_max, panels)
    T = plane_integral(flux([(q, depth - z) for q, z in sources]), r_max, panels)
    return R, T


def main(argv):
    args, name, only_r, approx = [], "dipole_py", False, False
    it = iter(argv[1:])
    for a in it:
        if a == "--name":
            name = next(it, "")
        elif a == "--reflectance-only":
            only_r = True
        elif a == "--approx":
            approx = True
        else:
            args.append(a)
    if len(args) != 2 or not name:
        sys.exit("usage: python3 -m ppbench.dipole [--name NAME] [--reflectance-only] [--approx] "
                 "SCENE.json OUT_DIR")
    argv = [argv[0]] + args
    from ppbench import read_scene
    sc = read_scene(argv[1])
    if sc["geometry"]["kind"] != "slab" and not only_r:
        sys.exit("ppbench.dipole: slab scenes only (geometry = slab; a tube: --reflectance-only)")
    m, light = sc["medium"], sc["light"]
    if m["step"] != "none" and not approx:
        sys.exit("ppbench.dipole: uniform media only (--approx: the medium at x < step_x)")
    if m.get("n", 1.0) != 1.0 and not approx:
        sys.exit("ppbench.dipole: n = 1 only (the boundary factor A = 1; --approx: A = 1 anyway)")
    R, T = dipole_RT(m["sigma_t"], m["albedo"], m["g"], sc["geometry"]["height"])
    cos_l = light["irradiance_s1"]  # cos(theta_L): the irradiance S1 receives
    # Where the first source lies below a thin slab T comes out negative: 0, as the C mp does.
    L = {"S1": max(0.0, cos_l * R / math.pi), "S2": max(0.0, cos_l * T / math.pi)}
    with open(os.path.join(argv[2], "radiance.csv"), "w") as f:
        f.write("method,surface,segment,s,theta_bin,phi_bin,radiance,stderr\n")
        for p in sc["sample_points"]:
            if only_r and p["surface"] != "S1":
                continue  # not computed: the config's surfaces = S1 says so
            for b in sc["bins"]:
                f.write("%s,%s,%d,%.17g,%d,%d,%.17g,0\n" % (
                    name, p["surface"], p["segment"], p["s"], b["theta_bin"], b["phi_bin"],
                    L[p["surface"]]))
    if only_r:
        return  # no totals.csv: ppbench integrates S1 (R) and marks the rest not computed
    # totals: fractions of the power in; the unscattered beam leaves S2 with exp(-tau / cos)
    ballistic = math.exp(-m["sigma_t"] * sc["geometry"]["height"] / cos_l)
    with open(os.path.join(argv[2], "totals.csv"), "w") as f:
        f.write("method,R,T,sides,absorbed,ballistic\n")
        f.write("%s,%.17g,%.17g,0,%.17g,%.17g\n" % (name, R, T, 1 - R - T - ballistic, ballistic))


if __name__ == "__main__":
    main(sys.argv)
