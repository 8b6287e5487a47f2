#!/usr/bin/python3
"""tools/discrepancy_power.py: the tally of a results file, resuming, its
argument checks, and the committed results of the power study
(examples/discrepancy/power/results.jsonl): consistent records, no case and
seed twice, the null case never naming a cause, and with five seeds of a
mechanism the right cause in at least 4 of 5."""
import contextlib
import io
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOLS = os.path.join(ROOT, "tools")
sys.path.insert(0, TOOLS)
import discrepancy_power as dp  # noqa: E402

RESULTS = os.path.join(ROOT, "examples", "discrepancy", "power", "results.jsonl")


def record(case, seed, named, status="cause named"):
    expect = dp.CASES[case]["expect"]
    correct = named == expect if expect else status == "no significant discrepancy"
    return {"case": case, "seed": seed, "points": 7, "signal": 2.5, "expect": expect, "status": status,
            "named": named, "correct": correct}


def output_of(fn, recs):
    """fn(path) on a results file holding recs: (its return value, what it printed)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "r.jsonl")
        with open(path, "w") as f:
            for r in recs:
                f.write(json.dumps(r) + "\n")
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            value = fn(path)
    return value, out.getvalue()


class Tally(unittest.TestCase):
    def test_rates_per_case(self):
        recs = [record("cohesion", 1, "cohesion sjkr"), record("cohesion", 2, None, "discrepancy not explained"),
                record("cohesion", 3, "viscoelastic damping"), record("null", 1, None, "no significant discrepancy"),
                record("null", 2, "cohesion sjkr")]
        rates, out = output_of(dp.summary, recs)
        self.assertEqual(rates, {"cohesion": (1, 3), "null": (1, 2)})
        self.assertIn("viscoelastic damping", out)
        self.assertIn("discrepancy not explained", out)

    def test_markdown_has_a_row_per_record(self):
        recs = [dict(record("rolling", 1, "rolling friction cdt"), param="mur", true=0.05, baseline_chi2_red=4.0,
                     gain=2.9, fitted=0.048, runs=500, seconds=300.0),
                dict(record("null", 1, None, "no significant discrepancy"), param="e", true=0.8,
                     baseline_chi2_red=0.9, gain=None, runs=900, seconds=400.0)]
        _, out = output_of(dp.markdown, recs)
        lines = out.splitlines()
        self.assertEqual(len(lines), 2 + len(recs))
        self.assertIn("| rolling | 1 | mur = 0.05 | 4.00 | cause named | rolling friction cdt | 2.90 | 0.048 |", lines[2])
        self.assertIn("| null | 1 | e = 0.8 | 0.90 | no significant discrepancy | - | - | - |", lines[3])

    def test_missing_file_is_empty(self):
        self.assertEqual(dp.load(os.path.join(ROOT, "no", "such", "file.jsonl")), [])

    def test_unknown_case_is_refused(self):
        proc = subprocess.run(["/usr/bin/python3", os.path.join(TOOLS, "discrepancy_power.py"), "--out",
                               os.devnull, "--cases", "cohesion,magic"], capture_output=True, text=True)
        self.assertEqual(proc.returncode, 2)
        self.assertIn("unknown case 'magic'", proc.stderr)

    def test_levels(self):
        lv = dp.levels("viscoelastic", 7)
        self.assertEqual(len(lv), 7)
        self.assertAlmostEqual(lv[0], 0.05)
        self.assertAlmostEqual(lv[-1], 5.0)
        self.assertAlmostEqual(lv[1] / lv[0], lv[2] / lv[1])  # geometric
        lt = dp.levels("tangential", 8)
        self.assertAlmostEqual(lt[1] - lt[0], lt[2] - lt[1])  # linear


class CommittedResults(unittest.TestCase):
    def setUp(self):
        self.recs = dp.load(RESULTS)
        if not self.recs:
            self.skipTest("no committed results in " + RESULTS)

    def test_records_are_consistent_and_unique(self):
        keys = [(r["case"], r["seed"], r["points"], r["signal"]) for r in self.recs]
        self.assertEqual(len(keys), len(set(keys)), "a case and seed recorded twice")
        for r in self.recs:
            self.assertIn(r["case"], dp.CASES)
            expect = dp.CASES[r["case"]]["expect"]
            self.assertEqual(r["expect"], expect)
            if expect:
                self.assertEqual(r["correct"], r["named"] == expect, r)
            else:
                self.assertEqual(r["correct"], r["status"] == "no significant discrepancy", r)
            self.assertEqual(r["named"] is not None, r["status"] == "cause named", r)

    def test_null_case_never_names_a_cause(self):
        for r in self.recs:
            if r["case"] == "null":
                self.assertIsNone(r["named"], f"seed {r['seed']}: named {r['named']!r} in data that hide nothing")

    def test_right_cause_in_four_of_five(self):
        # the target at a realistic difficulty: with five or more seeds of a
        # mechanism, the right cause named in at least 4 of 5 data sets
        for case, c in dp.CASES.items():
            rs = [r for r in self.recs if r["case"] == case]
            if c["expect"] is None or len(rs) < 5:
                continue
            right = sum(r["correct"] for r in rs)
            self.assertGreaterEqual(right, 0.8 * len(rs), f"{case}: right cause in {right} of {len(rs)}")

    def test_rates_are_printed(self):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            rates = dp.summary(RESULTS)
        sys.stderr.write("\n" + out.getvalue())
        self.assertEqual(sum(n for _, n in rates.values()), len(self.recs))


if __name__ == "__main__":
    unittest.main()
