#!/usr/bin/python3
"""tools/silo_box_analysis.py: averages over the flowing periods of synthetic box files."""
import csv
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TOOLS = os.path.join(HERE, "..", "..", "tools")
sys.path.insert(0, HERE)
from test_avalanche_stats import write_csv  # noqa: E402


def write_box(path, t, cols):
    names = ["step", "time"] + list(cols)
    with open(path, "w") as f:
        f.write("# Time-averaged data for fix box\n# " + " ".join(names) + "\n")
        for k, tk in enumerate(t):
            f.write(" ".join(f"{x:.10g}" for x in [k * 100, tk] + [cols[c][k] for c in cols]) + "\n")


def run(*args):
    return subprocess.run([sys.executable, os.path.join(TOOLS, "silo_box_analysis.py"), *args], capture_output=True,
                          text=True)


class BoxAnalysis(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def make_case(self, name, phi_flow, theta_flow, ke_body, seed):
        """Avalanches of the synthetic CSV (write_csv) and a box file whose rows inside them hold
        the 'flowing' values, with clogged rows (state 1) in between holding other values."""
        rng = np.random.default_rng(seed)
        masses = rng.exponential(0.002, 6) + 2e-4
        aval = os.path.join(self.dir, name + ".csv")
        write_csv(aval, masses)
        with open(aval) as f:
            rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
        t = np.arange(0.0, float(rows[-1]["t_clog"]) + 0.2, 0.005)
        flowing = np.zeros(len(t), dtype=bool)
        for r in rows:
            flowing |= (t >= float(r["t_start"])) & (t <= float(r["t_end"]))
        n = len(t)
        nc, ns = np.full(n, 20.0), np.full(n, 5.0)
        cols = {
            "phi": np.where(flowing, phi_flow, 0.3) + rng.normal(0, 0.01, n),
            "phi_c": np.where(flowing, phi_flow - 0.1, 0.2),
            "phi_s": np.full(n, 0.1),
            "ke_c": np.where(flowing, ke_body * nc, 0.0),
            "erot_c": np.where(flowing, 0.1 * ke_body * nc, 0.0),
            "n_c": nc,
            "ke_s": np.where(flowing, ke_body * ns, 0.0),
            "erot_s": np.zeros(n),
            "n_s": ns,
            "theta": np.where(flowing, np.radians(theta_flow), 1.2),
            "state": np.where(flowing, 0.0, 1.0),
        }
        box = os.path.join(self.dir, name + ".dat")
        write_box(box, t, cols)
        return box, aval, flowing.sum()

    def test_flowing_averages(self):
        b0, a0, n0 = self.make_case("c0", 0.62, 40.0, 1e-6, 1)
        b1, a1, n1 = self.make_case("c1", 0.58, 30.0, 3e-6, 2)
        out = os.path.join(self.dir, "out")
        r = run("--box", b0, b1, "--avalanches", a0, a1, "--phi", "0", "0.1", "--out", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out, "box_stats.csv")) as f:
            rows = list(csv.DictReader(f))
        for row, phi, theta, ke, nrows in ((rows[0], 0.62, 40.0, 1e-6, n0), (rows[1], 0.58, 30.0, 3e-6, n1)):
            self.assertEqual(int(row["rows"]), nrows)
            self.assertEqual(int(row["avalanches"]), 6)
            # noise of sd 0.01 over > 50 rows: the mean within 0.005
            self.assertAlmostEqual(float(row["phi"]), phi, delta=0.005)
            self.assertAlmostEqual(float(row["phi_c"]), phi - 0.1, places=9)
            self.assertAlmostEqual(float(row["theta_deg"]), theta, places=6)
            self.assertAlmostEqual(float(row["k_te"]), ke, delta=1e-9 * ke)
            self.assertAlmostEqual(float(row["k_re"]), 0.1 * ke * 20 / 25, delta=1e-9 * ke)
        for f in ("box_vs_phi.png", "box_timeseries.png"):
            self.assertTrue(os.path.getsize(os.path.join(out, f)) > 0)

    def test_bad_files(self):
        bad = os.path.join(self.dir, "bad.dat")
        with open(bad, "w") as f:
            f.write("# step time phi\n0 0.0 0.5\n")
        r = run("--box", bad, "--no-plots", "--out", self.dir)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("missing", r.stderr)
        with open(bad, "w") as f:
            f.write("# step time phi ke_c erot_c n_c theta\n0 0.0 0.5 1 1\n")
        r = run("--box", bad, "--no-plots", "--out", self.dir)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("line 2", r.stderr)


if __name__ == "__main__":
    unittest.main()
