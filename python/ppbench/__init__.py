"""ppbench from Python: read an experiment's outputs, recompute the metrics (docs/reference.md: Metrics), read a
scene.json (docs/external.md). Standard library only; with pandas installed, load() returns
DataFrames, otherwise lists of dicts.

    import ppbench
    run = ppbench.load("results/uniform_g0_normal")
    ppbench.metrics(run["radiance"], "pp", cell="R_x0")   # {'rms_rel': ..., 'noise_rel': ...}
"""
import csv
import json
import math
import os

__all__ = ["load", "metrics", "read_scene", "read_config", "bin_edges", "CELLS"]

try:  # optional
    import pandas as _pd
except ImportError:  # pragma: no cover - depends on the machine
    _pd = None


def _num(v):
    try:
        return int(v)
    except ValueError:
        try:
            return float(v)
        except ValueError:
            return v


def _read_csv(path):
    with open(path, newline="") as f:
        return [{k: _num(v) for k, v in row.items()} for row in csv.DictReader(f)]


def read_config(directory):
    """The resolved config of a finished experiment: {"section.key": value} from
    provenance.txt (the lines from experiment.name on)."""
    cfg, on = {}, False
    with open(os.path.join(directory, "provenance.txt")) as f:
        for line in f:
            line = line.rstrip("\n")
            on = on or line.startswith("experiment.name = ")
            if on and " = " in line:
                k, v = line.split(" = ", 1)
                cfg[k] = _num(v)
    return cfg


def bin_edges(ntheta, nphi):
    """The bins (docs/reference.md: Bins): {bin index: (theta_lo, theta_hi, phi_lo, phi_hi, w_k)}, radians; theta
    edges at sin^2(theta) = k / ntheta, phi folded to [0, pi], w_k = pi / (ntheta nphi)."""
    out = {}
    for it in range(ntheta):
        for ip in range(nphi):
            out[it * nphi + ip] = (math.asin(math.sqrt(it / ntheta)),
                                   math.asin(math.sqrt((it + 1) / ntheta)),
                                   ip * math.pi / nphi, (ip + 1) * math.pi / nphi,
                                   math.pi / (ntheta * nphi))
    return out


# The CSV files of an output set (docs/reference.md: Outputs), by the key load() gives each;
# the first four are always present in the result ([] when the file is absent).
_ALWAYS = ("summary", "rms", "totals", "regions", "angular", "timings")


def load(directory):
    """Every output of an experiment: {"config", "radiance", "summary", "rms", "totals",
    "regions", "angular", "timings"}, plus every other CSV of the set under its name without
    .csv ("summary_mc1", "summary_rte2d", "rte2d_refinements", ...); a file the set lacks
    (regions.csv in slab mode, a run without mc) is []. radiance rows carry their bin's theta/phi
    edges and w_k. DataFrames with pandas, else lists of dicts."""
    cfg = read_config(directory)
    edges = bin_edges(int(cfg["bins.theta"]), int(cfg["bins.phi"]))
    nphi = int(cfg["bins.phi"])
    rad = _read_csv(os.path.join(directory, "radiance.csv"))
    for r in rad:
        e = edges[r["theta_bin"] * nphi + r["phi_bin"]]
        r.update(theta_lo=e[0], theta_hi=e[1], phi_lo=e[2], phi_hi=e[3], w_k=e[4])
    out = {"config": cfg, "radiance": rad}
    names = set(_ALWAYS)
    names.update(f[:-4] for f in os.listdir(directory) if f.endswith(".csv"))
    names.discard("radiance")
    for name in sorted(names):
        path = os.path.join(directory, name + ".csv")
        out[name] = _read_csv(path) if os.path.exists(path) else []
    if _pd is not None:
        for k in out:
            if k != "config":
                out[k] = _pd.DataFrame(out[k])
    return out


def _rows(table):
    return table.to_dict("records") if hasattr(table, "to_dict") else table


CELLS = ("R_x0", "T_x0", "S1_all", "S2_all", "S3_all", "S4_all")


def _cell_points(cell, nseg):
    """The sample points (surface, segment) of a Table 2 / whole-surface cell (docs/reference.md: Metrics): R_x0 and
    T_x0 the two S1 (S2) segments next to x = 0, Sk_all every segment of Sk."""
    if cell in ("R_x0", "T_x0"):
        surf, n = ("S1" if cell == "R_x0" else "S2"), nseg["S1" if cell == "R_x0" else "S2"]
        return {(surf, n // 2 - 1), (surf, n // 2)} if n % 2 == 0 else {(surf, n // 2)}
    surf = cell.split("_")[0]
    return {(surf, k) for k in range(nseg.get(surf, 0))}


def metrics(radiance, method, cell=None, points=None, ref="mc"):
    """The metrics (docs/reference.md: Metrics) of `method` against `ref` over a set of sample points: points = {(surface,
    segment)}, or cell = "R_x0", "T_x0", "S1_all", ...; returns rms_rel, noise_rel, rms_excess:
        rms_rel   = sqrt(sum w_k (L_m - L_r)^2 / sum w_k L_r^2)
        noise_rel = sqrt(sum w_k se_r^2 / sum w_k L_r^2)
        rms_excess = sqrt(max(0, rms_rel^2 - noise_rel^2))
    Raises ValueError, naming what is there, for a method or reference not in the radiance
    rows, a cell that is not one of CELLS (or whose surface the run lacks: S3_all, S4_all in
    slab mode), neither or both of cell and points, and points the reference has no rows at;
    nan where the reference's radiance is 0 at every bin of the points (summary.csv's nan)."""
    rows = _rows(radiance)
    present = []
    for r in rows:
        if r["method"] not in present:
            present.append(r["method"])
    for who, what in ((ref, "reference"), (method, "method")):
        if who not in present:
            raise ValueError("%s %r is not in the radiance rows (methods there: %s)"
                             % (what, who, ", ".join(present) or "none"))
    if (cell is None) == (points is None):
        raise ValueError("give one of cell= (one of %s) or points= {(surface, segment)}"
                         % ", ".join(CELLS))
    nseg = {}
    for r in rows:
        if r["method"] == ref:
            nseg[r["surface"]] = max(nseg.get(r["surface"], 0), r["segment"] + 1)
    if points is None:
        have = [c for c in CELLS if c.split("_")[0] in nseg or c in ("R_x0", "T_x0")]
        if cell not in have:
            raise ValueError("unknown cell %r: the cells of this run are %s"
                             % (cell, ", ".join(have)))
        points = _cell_points(cell, nseg)
    key = lambda r: (r["surface"], r["segment"], r["theta_bin"], r["phi_bin"])
    refs = {key(r): r for r in rows if r["method"] == ref and (r["surface"], r["segment"]) in points}
    num = den = noise = 0.0
    for r in rows:
        k = key(r)
        if r["method"] != method or k not in refs:
            continue
        w, L_r, se = r["w_k"], refs[k]["radiance"], refs[k]["stderr"]
        num += w * (r["radiance"] - L_r) ** 2
        den += w * L_r ** 2
        noise += w * se ** 2
    if not refs:
        raise ValueError("%r has no rows at the points %s (its surfaces: %s)"
                         % (ref, sorted(points)[:4], ", ".join(sorted(nseg)) or "none"))
    if den == 0.0:  # a reference of 0 everywhere there: undefined, nan as in summary.csv
        return {"rms_rel": math.nan, "noise_rel": math.nan, "rms_excess": math.nan}
    rms = math.sqrt(num / den)
    nz = math.sqrt(noise / den)
    return {"rms_rel": rms, "noise_rel": nz, "rms_excess": math.sqrt(max(0.0, rms * rms - nz * nz))}


def read_scene(path):
    """scene.json as a dict (docs/external.md)."""
    with open(path) as f:
        return json.load(f)
