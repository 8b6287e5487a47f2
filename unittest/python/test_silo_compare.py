#!/usr/bin/python3
"""tools/silo_compare.py: the accounting of a log of examples/silo_liggghts/in.silo_both,
the statistics of ensembles, and (when LIGGGHTS is installed) both programs on
a shortened run of the script."""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOLS = os.path.join(ROOT, "tools")
sys.path.insert(0, TOOLS)
import silo_compare as sc  # noqa: E402

NRES = 10
MC, MB, VC, VB = sc.masses(NRES, 3.2)


def synthetic_log(n1_0, n2_0, events, bed=(1e-5, 4000, 200)):
    """Lines of in.silo_both's output: FILLED, BED, then FLOW/CLOG/ARCH events, END."""
    out = [f"FILLED t 0.3 n_type1_spheres {n1_0} n_type2 {n2_0} zmax 10 dc",
           f"BED slab_volume {bed[0]} n_type1_spheres {bed[1]} n_type2 {bed[2]}"]
    last = None
    for e in events:
        if e[0] == "FLOW":
            out.append(f"FLOW {e[1]} {e[2]} {e[3]}")
            last = e
        elif e[0] == "CLOG":
            out.append(f"CLOG {e[1]}")
        else:
            out.append(f"ARCH {e[1]} {e[2]} {e[3]}")
    out.append(f"END t {last[1]} n_type1_spheres {last[2]} n_type2 {last[3]}")
    return "\n".join(out) + "\n"


# 1000 clump spheres (100 clumps) and 50 beads; 10 clumps and 5 beads leave in the
# first avalanche, a clog, the arch (2 clumps, 1 bead) is deleted, then 4 clumps leave
ONE_CLOG = [("FLOW", 0.31, 1000, 50), ("FLOW", 0.32, 950, 48), ("FLOW", 0.33, 900, 45), ("FLOW", 0.34, 900, 45),
            ("CLOG", 0.44), ("ARCH", 0.44, 880, 44), ("FLOW", 0.45, 860, 44), ("FLOW", 0.46, 840, 44),
            ("FLOW", 0.47, 840, 44)]


class Accounting(unittest.TestCase):
    def test_passage_and_deletion_are_told_apart(self):
        ev = ONE_CLOG
        with tempfile.TemporaryDirectory() as tmp:
            log = os.path.join(tmp, "log")
            with open(log, "w") as f:
                f.write("some other output\n" + synthetic_log(1000, 50, ev))
            rec = sc.parse_log(log)
            o = sc.observables(rec, dict(sc.DEFAULTS))
        first = 10 * MC + 5 * MB
        second = 4 * MC
        self.assertAlmostEqual(o["mass_passed"], first + second, places=15)
        self.assertEqual(o["clogs"], 1)
        self.assertEqual(len(o["avalanches"]), 1)  # the one ended by the clog; the running one is not complete
        self.assertAlmostEqual(o["avalanches"][0], first, places=15)
        self.assertAlmostEqual(o["first_clog"], 0.44 - 0.30, places=12)
        self.assertAlmostEqual(o["bed_phi"], (4000 / NRES * VC + 200 * VB) / 1e-5, places=12)
        # flow rate: the mass over the 0.01 s chunks in which something passed, after the first 0.05 s
        self.assertAlmostEqual(o["flow_rate"], (4 * MC) / 0.02, places=9)
        # a window of discharge time: only its chunks (0.01-0.02 and 0.02-0.03 s after the start)
        early = sc.observables(rec, dict(sc.DEFAULTS), sc.parse_window("0,0.03"))
        self.assertAlmostEqual(early["flow_rate"], (10 * MC + 5 * MB) / 0.02, places=9)
        self.assertEqual(sc.parse_window("0.05,end"), sc.DEFAULT_WINDOW)
        for bad in ("0.2,0.1", "0.1", "a,b"):
            with self.assertRaises(SystemExit):
                sc.parse_window(bad)

    def test_until_cuts_every_observable_and_accepts_stopped_runs(self):
        # the same log as above, observed over the first 0.12 s of discharge (started at
        # 0.30 s): the first avalanche only, no clog yet
        ev = ONE_CLOG
        with tempfile.TemporaryDirectory() as tmp:
            log = os.path.join(tmp, "log")
            with open(log, "w") as f:
                f.write(synthetic_log(1000, 50, ev))
            rec = sc.parse_log(log)
            o = sc.observables(rec, dict(sc.DEFAULTS), sc.parse_window("0,0.03"), sc.parse_until("0.12"))
            self.assertAlmostEqual(o["mass_passed"], 10 * MC + 5 * MB, places=15)
            self.assertEqual(o["clogs"], 0)
            self.assertEqual(o["avalanches"], [])
            self.assertAlmostEqual(o["flow_rate"], (10 * MC + 5 * MB) / 0.02, places=9)
            self.assertTrue(sc.reached(rec, 0.17))
            self.assertFalse(sc.reached(rec, 0.18))
            # a run stopped by a time limit (no END line) counts only with --until
            d = sc.run_dir(tmp, "granary", 4.0, 7)
            os.makedirs(d)
            with open(os.path.join(d, "log"), "w") as f:
                f.write("".join(line + "\n" for line in synthetic_log(1000, 50, ev).splitlines()
                                if not line.startswith("END")))
            self.assertEqual(list(sc.finished_runs(tmp, 4.0)), [])
            self.assertEqual([r[:2] for r in sc.finished_runs(tmp, 4.0, 0.15)], [("granary", 7)])
            self.assertEqual(list(sc.finished_runs(tmp, 4.0, 0.2)), [])
        self.assertTrue(math.isinf(sc.parse_until(None)))
        for bad in ("0", "-1", "x"):
            with self.assertRaises(SystemExit):
                sc.parse_until(bad)

    def test_statistics(self):
        m, sd, h = sc.ci95([1.0, 2.0, 3.0, 4.0])
        self.assertAlmostEqual(m, 2.5)
        self.assertAlmostEqual(sd, math.sqrt(5 / 3))
        self.assertAlmostEqual(h, 3.182446305284263 * sd / 2, places=9)
        rng = np.random.default_rng(1)
        same = sc.compare(rng.normal(0, 1, 40), rng.normal(0, 1, 40))
        self.assertGreater(same["welch_p"], 0.01)
        wide = sc.compare(rng.normal(0, 1, 40), rng.normal(0, 3, 40))
        self.assertLess(wide["levene_p"], 0.01)
        shifted = sc.compare(rng.normal(0, 1, 40), rng.normal(1.5, 1, 40))
        self.assertLess(shifted["welch_p"], 1e-4)

    def test_seeds_are_primes(self):
        p = sc.primes_from(32452843, 5)
        self.assertEqual(len(p), 5)
        for q in p:
            self.assertTrue(all(q % d for d in range(2, int(math.isqrt(q)) + 1)))
        self.assertEqual(p[0], 32452867)


class Export(unittest.TestCase):
    def test_report_of_the_export_is_the_report_of_the_logs(self):
        # two configurations, three seeds each, with clogs and arch removals: the compact files
        # that `export` writes give `report` the same statistics, test by test, as the logs
        rng = np.random.default_rng(7)
        with tempfile.TemporaryDirectory() as tmp:
            runs = os.path.join(tmp, "runs")
            for c in ("granary", "liggghts_beads"):
                for seed in sc.primes_from(32452843, 3):
                    d = sc.run_dir(runs, c, 2.0, seed)
                    os.makedirs(d)
                    n1, n2, t, ev = 1000, 50, 0.31, []
                    for _ in range(4):
                        for _ in range(int(rng.integers(2, 6))):
                            n1 -= 10 * int(rng.integers(0, 4))
                            n2 -= int(rng.integers(0, 2))
                            ev.append(("FLOW", round(t, 2), n1, n2))
                            t += 0.01
                        ev += [("CLOG", round(t, 2)), ("ARCH", round(t, 2), n1 - 20, n2)]
                        n1 -= 20
                    ev.append(("FLOW", round(t, 2), n1, n2))
                    with open(os.path.join(d, "log"), "w") as f:
                        f.write(synthetic_log(1000, 50, ev))
            with open(os.path.join(runs, "settings.json"), "w") as f:
                json.dump({"variables": dict(sc.DEFAULTS), "slits": [2.0], "seeds": sc.primes_from(32452843, 3),
                           "configs": ["granary", "liggghts_beads"]}, f)
            compact = os.path.join(tmp, "compact")
            tool = [sys.executable, os.path.join(TOOLS, "silo_compare.py")]
            subprocess.run(tool + ["export", runs, compact], check=True, capture_output=True)
            self.assertEqual(sorted(os.listdir(compact)), ["avalanches.csv", "runs.csv", "settings.json"])
            reports = []
            for src in (runs, compact):
                out = os.path.join(tmp, os.path.basename(src) + ".json")
                subprocess.run(tool + ["report", src, "--json", out], check=True, capture_output=True)
                with open(out) as f:
                    reports.append(json.load(f)["cases"]["2"])
            self.assertEqual(reports[0]["granary"]["avalanches"], reports[1]["granary"]["avalanches"])
            self.assertEqual(len(reports[0]["granary"]["avalanches"]), 12)
            self.assertEqual(reports[0]["tests"], reports[1]["tests"])
            # an export holds the rates of its window: another window needs another export
            r = subprocess.run(tool + ["report", compact, "--window", "0,0.03"], capture_output=True, text=True)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("export the run folder again", r.stderr)
            # and of its duration: --until needs an export made with it
            r = subprocess.run(tool + ["report", compact, "--until", "0.05"], capture_output=True, text=True)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("export the run folder again with --until 0.05", r.stderr)
            short = os.path.join(tmp, "short")
            subprocess.run(tool + ["export", runs, short, "--until", "0.05"], check=True, capture_output=True)
            r = subprocess.run(tool + ["report", short], capture_output=True, text=True, check=True)
            self.assertIn("every observable over the first 0.05 s", r.stdout)
            for k in sc.RUN_KEYS:
                for a, b in zip(reports[0]["liggghts_beads"][k], reports[1]["liggghts_beads"][k]):
                    self.assertAlmostEqual(a, b, places=8, msg=k)

            # merge: the export twice with itself and a folder of two of its runs pools to the
            # same six runs (each once); a run that differs, or other physics, stops it
            sub = os.path.join(tmp, "sub")
            shutil.copytree(compact, sub)
            with open(os.path.join(sub, "runs.csv")) as f:
                lines = f.read().splitlines(keepends=True)
            with open(os.path.join(sub, "runs.csv"), "w") as f:
                f.writelines(lines[:4])  # comment, header, two runs
            pooled = os.path.join(tmp, "pooled")
            r = subprocess.run(tool + ["merge", compact, sub, "--to", pooled], capture_output=True, text=True,
                               check=True)
            self.assertEqual(r.stdout.count("kept once"), 2)
            self.assertIn("6 runs from 2 folders", r.stdout)
            out = os.path.join(tmp, "pooled.json")
            subprocess.run(tool + ["report", pooled, "--json", out], check=True, capture_output=True)
            with open(out) as f:
                merged = json.load(f)["cases"]["2"]
            self.assertEqual(merged["tests"], reports[1]["tests"])
            self.assertEqual(merged["granary"]["avalanches"], reports[1]["granary"]["avalanches"])
            with open(os.path.join(sub, "runs.csv"), "w") as f:
                f.writelines(lines[:3] + [lines[3].replace(",0.", ",0.9", 1)])
            r = subprocess.run(tool + ["merge", compact, sub, "--to", pooled], capture_output=True, text=True)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("different results: not a rerun of one seed", r.stderr)
            with open(os.path.join(short, "settings.json")) as f:
                self.assertEqual(json.load(f)["until"], "0.05")
            r = subprocess.run(tool + ["merge", compact, short, "--to", pooled], capture_output=True, text=True)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("export them alike", r.stderr)
            other = os.path.join(tmp, "other")
            shutil.copytree(compact, other)
            with open(os.path.join(other, "settings.json")) as f:
                st = json.load(f)
            st["variables"]["phi"] = 0.1
            with open(os.path.join(other, "settings.json"), "w") as f:
                json.dump(st, f)
            r = subprocess.run(tool + ["merge", compact, other, "--to", pooled], capture_output=True, text=True)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("differ in phi: not one ensemble", r.stderr)


GRANARY = os.environ.get("GRANARY_BINARY", os.path.join(ROOT, "build", "granary"))


@unittest.skipUnless(shutil.which("liggghts"), "LIGGGHTS is not installed (Debian package liggghts)")
@unittest.skipUnless(os.path.exists(GRANARY), "granary is not built")
class BothPrograms(unittest.TestCase):
    def test_the_script_runs_unchanged_in_both(self):
        # a short fill and discharge; both programs fill the same number of bodies and pass some
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "runs")
            r = subprocess.run([sys.executable, os.path.join(TOOLS, "silo_compare.py"), "run", "--out", out,
                                "--configs", "granary,liggghts", "--seeds", "1", "--slit", "4", "--granary", GRANARY,
                                "-var", "W", "8", "-var", "D", "3", "-var", "H", "16", "-var", "top_ins", "15",
                                "-var", "settle", "0.12", "-var", "tmax", "0.08"],
                               capture_output=True, text=True, timeout=600)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            res = {}
            for c in ("granary", "liggghts"):
                d = os.path.join(out, c, "s4")
                (seed,) = os.listdir(d)
                res[c] = sc.observables(sc.parse_log(os.path.join(d, seed, "log")), dict(sc.DEFAULTS, W=8, D=3))
            # the same insertion: the same number of bodies (insert/pack of both programs)
            self.assertEqual(res["granary"]["bed_bodies"], res["liggghts"]["bed_bodies"])
            for c in res:
                self.assertGreater(res[c]["mass_passed"], 0.0, c)
                self.assertGreater(res[c]["bed_phi"], 0.3, c)
            rep = subprocess.run([sys.executable, os.path.join(TOOLS, "silo_compare.py"), "report", out, "--json",
                                  os.path.join(tmp, "r.json")], capture_output=True, text=True, timeout=120)
            self.assertEqual(rep.returncode, 0, rep.stderr)
            with open(os.path.join(tmp, "r.json")) as f:
                self.assertIn("granary", json.load(f)["cases"]["4"])


if __name__ == "__main__":
    unittest.main(verbosity=2)
