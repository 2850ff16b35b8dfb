#!/usr/bin/env python3
"""make_blob.py: writes configs/objects/blob.obj, the closed test mesh of `ppbench object`
(docs/reference.md, Objects): an icosphere subdivided three times (1280 triangles) whose radius
is modulated, r = 1 + 0.25 sin(3x) sin(2y) cos(2z) + 0.15 cos(4y), a bumpy, partly concave blob
(a stand-in for a scanned shape). Generated here, so it carries the project's own licence.
Deterministic: the same bytes every run. Usage: python3 scripts/make_blob.py [OUT]"""
import math
import sys


def icosphere(levels):
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
         (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        mid = {}

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = [(v[a][k] + v[b][k]) / 2 for k in range(3)]
                n = math.sqrt(sum(x * x for x in p))
                v.append(tuple(x / n for x in p))
                mid[key] = len(v) - 1
            return mid[key]

        nf = []
        for a, b, c in f:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return v, f


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "configs/objects/blob.obj"
    v, f = icosphere(3)
    with open(out, "w") as fh:
        fh.write("# blob.obj: written by scripts/make_blob.py (ppbench's test mesh, its licence)\n")
        for x, y, z in v:
            r = 1 + 0.25 * math.sin(3 * x) * math.sin(2 * y) * math.cos(2 * z) + 0.15 * math.cos(4 * y)
            fh.write("v %.6f %.6f %.6f\n" % (r * x, r * y, r * z))
        for a, b, c in f:
            fh.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


if __name__ == "__main__":
    main()
