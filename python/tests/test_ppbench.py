"""python/ppbench against a finished output set: PPB_TEST_RUN names a tube run of mc and ss
(tests/test_ux.c, test_python_package, makes one with the built binary and runs this file:
PYTHONPATH=python PPB_TEST_RUN=DIR python3 -m unittest discover -s python/tests).

Expected values: the set's own files. metrics() must give summary.csv's rows (written by the C
metrics, docs/reference.md: Metrics) to their 6 printed digits; load() must give every CSV of
the set row for row (docs/reference.md: Outputs names them); the errors are the documented
ValueErrors (docs/external.md: Python), where the package used to raise ZeroDivisionError (a
cell with no points), AttributeError (no cell) or return zeros (a method not in the run)."""
import csv
import math
import os
import unittest

import ppbench

RUN = os.environ.get("PPB_TEST_RUN")


def _csv(name):
    with open(os.path.join(RUN, name), newline="") as f:
        return list(csv.DictReader(f))


@unittest.skipUnless(RUN, "PPB_TEST_RUN: an output set (tests/test_ux.c makes one)")
class TestPackage(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.out = ppbench.load(RUN)
        cls.rad = cls.out["radiance"]

    def test_load_returns_every_output(self):
        files = sorted(f[:-4] for f in os.listdir(RUN) if f.endswith(".csv"))
        for name in ("regions", "angular", "timings", "summary", "rms", "totals", "summary_mc1"):
            self.assertIn(name, files)
        for name in files:
            self.assertIn(name, self.out)
            self.assertEqual(len(self.out[name]), len(_csv(name + ".csv")), name)
        self.assertEqual(self.out["timings"][0].keys(), _csv("timings.csv")[0].keys())
        self.assertEqual({r["method"] for r in self.out["angular"]}, {"mc", "mc1", "ss"})

    def test_metrics_match_summary(self):
        for row in _csv("summary.csv"):
            got = ppbench.metrics(self.rad, row["method"], cell=row["cell"])
            for k in ("rms_rel", "noise_rel", "rms_excess"):
                want = float(row[k])
                self.assertTrue(math.isclose(got[k], want, rel_tol=1e-5, abs_tol=1e-9),
                                "%s %s %s: %r vs %r" % (row["method"], row["cell"], k, got[k], want))

    def test_method_not_in_run(self):
        with self.assertRaisesRegex(ValueError, r"method 'pp' is not in the radiance rows "
                                                r"\(methods there: mc, mc1, ss\)"):
            ppbench.metrics(self.rad, "pp", cell="R_x0")
        with self.assertRaisesRegex(ValueError, r"reference 'ppslab' is not in"):
            ppbench.metrics(self.rad, "ss", cell="R_x0", ref="ppslab")

    def test_mistyped_cell(self):
        with self.assertRaisesRegex(ValueError, r"unknown cell 'S1': the cells of this run are "
                                                r"R_x0, T_x0, S1_all, S2_all, S3_all, S4_all"):
            ppbench.metrics(self.rad, "ss", cell="S1")

    def test_no_cell(self):
        with self.assertRaisesRegex(ValueError, r"give one of cell="):
            ppbench.metrics(self.rad, "ss")

    def test_points_without_reference_rows(self):
        with self.assertRaisesRegex(ValueError, r"'mc' has no rows at the points"):
            ppbench.metrics(self.rad, "ss", points={("S1", 999)})


if __name__ == "__main__":
    unittest.main()
