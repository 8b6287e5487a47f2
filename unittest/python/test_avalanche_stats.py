#!/usr/bin/python3
"""tools/avalanche_stats.py on synthetic avalanche CSVs whose statistics are known."""
import csv
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

TOOLS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools")
sys.path.insert(0, TOOLS)
import avalanche_stats as st  # noqa: E402

BODY_MASS = 2.0e-5  # kg per body of the synthetic avalanches


def write_csv(path, masses, ntypes=2):
    """An avalanche CSV in the format of fix clog-detect (doc/tools.md)."""
    cols = ["avalanche", "t_start", "t_end", "t_clog", "duration", "bodies", "mass", "flow_rate", "fill_height"]
    for k in range(1, ntypes + 1):
        cols += [f"bodies_t{k}", f"mass_t{k}"]
    with open(path, "w") as f:
        f.write("# fix clog-detect (synthetic test data)\n# units: SI\n")
        f.write(",".join(cols) + "\n")
        t = 0.0
        for i, m in enumerate(masses):
            bodies = int(round(m / BODY_MASS))
            dur = 0.01 * bodies + 0.01
            row = [i + 1, t, t + dur, t + dur + 0.05, dur, bodies, m, m / dur, 0.05]
            row += [bodies, m] + [0, 0.0] * (ntypes - 1)
            f.write(",".join(f"{x:.10g}" for x in row) + "\n")
            t += dur + 0.1


def run(*args):
    return subprocess.run([sys.executable, os.path.join(TOOLS, "avalanche_stats.py"), *args], capture_output=True,
                          text=True)


class AvalancheStats(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        self.rng = np.random.default_rng(20240611)

    def tearDown(self):
        self.tmp.cleanup()

    def test_exponential_sizes_and_ratio(self):
        # base case phi = 0: mean 0.02 kg; phi = 0.1: mean 0.01 kg (true ratio 0.5)
        mu0, mu1, n = 0.02, 0.01, 400
        a0, a1 = self.rng.exponential(mu0, n), self.rng.exponential(mu1, n)
        p0, p1 = os.path.join(self.dir, "phi0.csv"), os.path.join(self.dir, "phi01.csv")
        write_csv(p1, a1)
        write_csv(p0, a0)
        out = os.path.join(self.dir, "out")
        # the base case is the one with phi = 0, here listed second
        r = run(p1, p0, "--phi", "0.1", "0", "--out", out, "--bootstrap", "2000")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("<S>/<S0>", r.stdout)
        for f in ("avalanche_stats.csv", "avalanche_ccdf.png", "avalanche_mean.png"):
            self.assertTrue(os.path.getsize(os.path.join(out, f)) > 0, f)
        with open(os.path.join(out, "avalanche_stats.csv")) as f:
            rows = {row["label"]: row for row in csv.DictReader(f)}
        c0, c1 = rows["phi=0"], rows["phi=0.1"]
        for row, mu, x in ((c0, mu0, a0), (c1, mu1, a1)):
            self.assertEqual(int(row["n"]), n)
            m, se = float(row["mean_mass"]), float(row["se_mass"])
            self.assertAlmostEqual(m, np.mean(x), delta=1e-9)
            # exponential: se = mu/sqrt(n); the sample mean within 4 se of the true mean
            self.assertAlmostEqual(se, mu / np.sqrt(n), delta=0.2 * mu / np.sqrt(n))
            self.assertLess(abs(m - mu), 4 * mu / np.sqrt(n))
            # t and bootstrap intervals contain the sample mean and agree to 20 % in width
            lo, hi = float(row["ci_t_lo_mass"]), float(row["ci_t_hi_mass"])
            blo, bhi = float(row["ci_boot_lo_mass"]), float(row["ci_boot_hi_mass"])
            self.assertTrue(lo < m < hi and blo < m < bhi)
            self.assertAlmostEqual((bhi - blo) / (hi - lo), 1.0, delta=0.2)
            # tail fit: the characteristic size is the mean of an exponential
            lam, lse = float(row["lambda_mass"]), float(row["lambda_se_mass"])
            self.assertLess(abs(lam - mu), 4 * lse)
            self.assertTrue(float(row["lambda_lo_mass"]) < lam < float(row["lambda_hi_mass"]))
            # bodies: mass / body mass (rounded)
            self.assertAlmostEqual(float(row["mean_bodies"]) * BODY_MASS, m, delta=0.5 * BODY_MASS)
        self.assertEqual(float(c0["ratio_mass"]), 1.0)
        self.assertEqual(float(c0["ratio_err_mass"]), 0.0)
        ratio, err = float(c1["ratio_mass"]), float(c1["ratio_err_mass"])
        self.assertAlmostEqual(ratio, np.mean(a1) / np.mean(a0), delta=1e-6)
        # propagated error: R sqrt(1/n + 1/n) for exponentials, about 0.035 here
        self.assertAlmostEqual(err, 0.5 * np.sqrt(2.0 / n), delta=0.3 * 0.5 * np.sqrt(2.0 / n))
        self.assertLess(abs(ratio - 0.5), 4 * err)

    def test_ci_coverage(self):
        # 95 % intervals of the mean of 40 exponential sizes cover the true mean
        # in about 93-95 % of 400 repetitions (binomial sd 1.1 %)
        rng = np.random.default_rng(7)
        cover_t = cover_b = 0
        reps, mu = 400, 3.0
        for _ in range(reps):
            x = rng.exponential(mu, 40)
            _, _, lo, hi = st.mean_ci_t(x)
            blo, bhi = st.mean_ci_bootstrap(x, rng, nboot=500)
            cover_t += lo <= mu <= hi
            cover_b += blo <= mu <= bhi
        self.assertGreater(cover_t / reps, 0.89)
        self.assertLess(cover_t / reps, 0.99)
        self.assertGreater(cover_b / reps, 0.87)
        self.assertLess(cover_b / reps, 0.99)

    def test_tail_fit_of_shifted_tail(self):
        # a mixture whose tail above the threshold is exponential with lambda = 5:
        # small avalanches below 2 do not bias the fit of the tail
        x = np.concatenate([self.rng.uniform(0, 2, 300), 2 + self.rng.exponential(5.0, 700)])
        s_min, lam, se, lo, hi, k = st.exp_tail_fit(x, quantile=0.4)
        self.assertGreater(s_min, 2.0)
        self.assertLess(abs(lam - 5.0), 4 * se)
        self.assertTrue(lo < 5.0 < hi)

    def test_malformed_csv(self):
        bad = os.path.join(self.dir, "bad.csv")
        cases = {
            "avalanche,t_start,bodies\n1,0.0,3\n": "mass",  # missing column
            "avalanche,bodies,mass\n1,3,0.01\n2,x,0.02\n": "line 3",  # not a number
            "# c\navalanche,bodies,mass\n1,3\n": "line 3",  # wrong number of fields
            "avalanche,bodies,mass\n1,3,-0.01\n": "negative",
        }
        for text, what in cases.items():
            with open(bad, "w") as f:
                f.write(text)
            r = run(bad, "--out", self.dir, "--no-plots")
            self.assertNotEqual(r.returncode, 0, text)
            self.assertIn(what, r.stderr, text)
        r = run(os.path.join(self.dir, "missing.csv"), "--no-plots")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("cannot read", r.stderr)


if __name__ == "__main__":
    unittest.main()
