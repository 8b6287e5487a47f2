#!/usr/bin/python3
"""tools/silo_study.py: the campaign driver, shortened (two tiny cases), killed, stopped and resumed.

A run killed in the middle of a cycle and resumed must give exactly the results
of an uninterrupted run (the chain is deterministic on one rank): no avalanche
lost, none counted twice. Rows of a cycle whose hand-over was interrupted are
dropped before the cycle runs again. Also the analysis tool on these results.
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOLS = os.path.join(ROOT, "tools")
sys.path.insert(0, TOOLS)
import silo_study as st  # noqa: E402

GRANARY = os.environ.get("GRANARY_BINARY", os.path.join(ROOT, "build", "granary"))
# a tiny silo: 7 x 2 dc, a 2.3 dc slit, filled to 7 dc, cycles end below 4.5 dc
TINY = ["-var", "W", "7", "-var", "D", "2", "-var", "H", "11", "-var", "s", "2.3", "-var", "fill", "7",
        "-var", "stop", "4.5", "-var", "column_w", "3", "-var", "box_w", "4", "-var", "box_h", "1.5",
        "-var", "box_z", "1", "-var", "settle", "0.12", "-var", "box_every", "500"]
CASES = ["r0_phi0", "r3.2_phi0.05"]


def driver(data, work, extra=()):
    cmd = [sys.executable, os.path.join(TOOLS, "silo_study.py"), "run", "--granary", GRANARY, "--data", data,
           "--work", work, "--min-avalanches", "4", "--max-cycles", "3"]
    for c in CASES:
        cmd += ["--case", c]
    return cmd + list(extra) + TINY


def read(path):
    with open(path) as f:
        return f.read()


@unittest.skipUnless(os.path.exists(GRANARY), f"granary not built ({GRANARY})")
class SiloStudyDriver(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="silo_study_")
        # the reference: uninterrupted
        cls.ref = os.path.join(cls.tmp, "ref")
        r = subprocess.run(driver(os.path.join(cls.ref, "data"), os.path.join(cls.ref, "work")),
                           capture_output=True, text=True, timeout=900)
        cls.ref_out = r.stdout + r.stderr
        cls.ref_rc = r.returncode

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_reference_run(self):
        self.assertEqual(self.ref_rc, 0, self.ref_out)
        for c in CASES:
            d = os.path.join(self.ref, "data", c)
            for name in ("avalanches.csv", "box.csv", "cycles.csv", "case.json"):
                self.assertTrue(os.path.exists(os.path.join(d, name)), f"{c}/{name}\n{self.ref_out}")
            _, h, cycles = st.read_rows(os.path.join(d, "cycles.csv"))
            _, ah, av = st.read_rows(os.path.join(d, "avalanches.csv"))
            self.assertGreaterEqual(len(cycles), 1)
            # cycles numbered 0, 1, ...; every avalanche row belongs to one of them, numbered 1.. per cycle
            self.assertEqual([int(r[0]) for r in cycles], list(range(len(cycles))))
            for k in range(len(cycles)):
                rows = [r for r in av if int(r[0]) == k]
                self.assertEqual([int(r[1]) for r in rows], list(range(1, len(rows) + 1)))
                # the cycle's line agrees with its avalanches: passed bodies, deleted bodies
                line = cycles[k]
                passed = sum(int(r[ah.index("bodies")]) for r in rows)
                deleted = sum(int(r[ah.index("arch_removed")]) for r in rows)
                self.assertEqual(passed, int(float(line[h.index("passed")])), c)
                self.assertEqual(deleted, int(float(line[h.index("deleted")])), c)
            # the case ends when it has 4 non-empty avalanches or 3 cycles
            self.assertTrue(st.nonempty_avalanches(d) >= 4 or len(cycles) == 3)
            # only the last restart file is kept, from which the chain continues
            restarts = sorted(f for f in os.listdir(os.path.join(self.ref, "work", c)) if f.endswith(".restart"))
            self.assertEqual(restarts, [f"restart_{len(cycles) - 1}.restart"])

    def test_each_run_reads_its_own_copy_of_the_script(self):
        # granary reads its script as it goes: the driver gives every run a copy of in.cycle in its
        # folder, so an in.cycle edited in the source tree meanwhile cannot reach a running cycle
        base = os.path.join(self.tmp, "copy")
        cmd = [sys.executable, os.path.join(TOOLS, "silo_study.py"), "run", "--granary", GRANARY, "--data",
               os.path.join(base, "data"), "--work", os.path.join(base, "work"), "--min-avalanches", "1",
               "--max-cycles", "1", "--keep-work", "--case", "r0_phi0"] + TINY
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        cdir = os.path.join(base, "work", "r0_phi0", "cycle_0")
        self.assertEqual(read(os.path.join(cdir, "in.cycle")), read(st.SCRIPT))
        # and the command runs the copy it is given
        args = type("A", (), {"np": 1, "granary": "g", "work": "w"})
        cmd = st.cycle_command(args, "r0_phi0", 0, True, {}, script=os.path.join(cdir, "in.cycle"))
        self.assertEqual(cmd[cmd.index("-in") + 1], os.path.join(cdir, "in.cycle"))

    def test_killed_and_resumed_gives_the_same_results(self):
        self.assertEqual(self.ref_rc, 0, self.ref_out)
        base = os.path.join(self.tmp, "killed")
        data, work = os.path.join(base, "data"), os.path.join(base, "work")
        first = os.path.join(data, CASES[0], "cycles.csv")
        p = subprocess.Popen(driver(data, work), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                             start_new_session=True)
        # kill the driver and its granary run once the first cycle is handed over and the second runs
        t0 = time.time()
        while time.time() - t0 < 600 and p.poll() is None:
            if os.path.exists(first) and len(st.read_rows(first)[2]) >= 1:
                time.sleep(1.0)
                break
            time.sleep(0.2)
        killed_running = p.poll() is None
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()
        self.assertTrue(killed_running, "the driver finished before it could be killed")
        done = len(st.read_rows(first)[2])
        self.assertGreaterEqual(done, 1)
        # an interrupted hand-over: rows of the next cycle written, its cycles.csv line not
        av = os.path.join(data, CASES[0], "avalanches.csv")
        comments, header, rows = st.read_rows(av)
        st.write_rows(av, comments, header, rows + [[str(done)] + rows[0][1:]])
        r = subprocess.run(driver(data, work), capture_output=True, text=True, timeout=900)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        for c in CASES:
            for name in ("avalanches.csv", "box.csv"):
                self.assertEqual(read(os.path.join(data, c, name)), read(os.path.join(self.ref, "data", c, name)),
                                 f"{c}/{name}")
            _, h, rows = st.read_rows(os.path.join(data, c, "cycles.csv"))
            _, _, ref_rows = st.read_rows(os.path.join(self.ref, "data", c, "cycles.csv"))
            keys = [h.index(k) for k in ("cycle", "steps", "passed", "deleted", "avalanches", "particle_steps")]
            self.assertEqual([[r[k] for k in keys] for r in rows], [[r[k] for k in keys] for r in ref_rows], c)

    def test_stopped_at_deadlines_and_continued_gives_the_same_results(self):
        # runs cut by --deadline: a cycle stopped in its discharge continues from its stop.restart
        # (fix clog-detect's state and log travel in it); one stopped while filling runs again.
        # The results must equal the uninterrupted run's, bit for bit (one rank).
        self.assertEqual(self.ref_rc, 0, self.ref_out)
        base = os.path.join(self.tmp, "deadlines")
        data, work = os.path.join(base, "data"), os.path.join(base, "work")
        out, deadline = "", 1.5
        for _ in range(20):
            r = subprocess.run(driver(data, work, ["--deadline", f"{deadline:.2f}"]), capture_output=True, text=True,
                               timeout=900)
            out += r.stdout + r.stderr
            self.assertIn(r.returncode, (0, 75), out)
            if r.returncode == 0:
                break
            deadline *= 1.3
        self.assertEqual(r.returncode, 0, out)
        self.assertIn("STOPPED at the deadline in its discharge", out)
        self.assertRegex(out, r"cycle \d+: .* in [2-9] runs")
        for c in CASES:
            self.assertEqual(read(os.path.join(data, c, "avalanches.csv")),
                             read(os.path.join(self.ref, "data", c, "avalanches.csv")), f"{c}\n{out}")
            # the box averages: the window that a stop cuts is not written (fix ave/time starts its
            # windows anew in the continuation); every other row is the uninterrupted run's
            stops = len(re.findall(rf"^  {re.escape(c)} cycle \d+: STOPPED at the deadline in its discharge", out,
                                   re.M))
            _, _, box = st.read_rows(os.path.join(data, c, "box.csv"))
            _, _, ref_box = st.read_rows(os.path.join(self.ref, "data", c, "box.csv"))
            self.assertTrue(all(row in ref_box for row in box), c)
            self.assertGreaterEqual(len(box), len(ref_box) - stops, c)
            _, h, rows = st.read_rows(os.path.join(data, c, "cycles.csv"))
            _, _, ref_rows = st.read_rows(os.path.join(self.ref, "data", c, "cycles.csv"))
            keys = [h.index(k) for k in ("cycle", "steps", "passed", "deleted", "avalanches")]
            self.assertEqual([[r[k] for k in keys] for r in rows], [[r[k] for k in keys] for r in ref_rows], c)
            # nothing of a stopped run is left once its cycle is complete
            self.assertFalse(any(f.startswith("cycle_") for f in os.listdir(os.path.join(work, c))), c)

    def test_chains_of_other_seeds_are_merged_once(self):
        self.assertEqual(self.ref_rc, 0, self.ref_out)
        base = os.path.join(self.tmp, "chains")
        main = os.path.join(base, "main")
        shutil.copytree(os.path.join(self.ref, "data"), main)
        chain = os.path.join(base, "chain")
        cmd = driver(chain, os.path.join(base, "work"), ["-var", "seed", "16485866"])
        cmd = cmd[:cmd.index("--case")] + ["--case", CASES[0]] + cmd[cmd.index("--case") + 4:]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        merge = [sys.executable, os.path.join(TOOLS, "silo_study.py"), "merge", "--from", chain, "--data", main]
        case = os.path.join(main, CASES[0])
        n_main = len(st.read_rows(os.path.join(case, "cycles.csv"))[2])
        _, _, ch_cycles = st.read_rows(os.path.join(chain, CASES[0], "cycles.csv"))
        _, _, ch_av = st.read_rows(os.path.join(chain, CASES[0], "avalanches.csv"))
        _, _, main_av = st.read_rows(os.path.join(case, "avalanches.csv"))
        r = subprocess.run(merge, capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        comments, h, rows = st.read_rows(os.path.join(case, "cycles.csv"))
        self.assertEqual([int(x[0]) for x in rows], list(range(n_main + len(ch_cycles))))
        self.assertEqual(rows[n_main][h.index("new_fill")], "1")  # the chain began with a fill
        self.assertTrue(any(c.startswith("# merged: chain seed 16485866") for c in comments))
        _, _, av = st.read_rows(os.path.join(case, "avalanches.csv"))
        self.assertEqual(len(av), len(main_av) + len(ch_av))
        self.assertEqual([x[1:] for x in av[len(main_av):]], [x[1:] for x in ch_av])
        # merged again: nothing added; the case's own chain (same seed) is refused
        before = read(os.path.join(case, "avalanches.csv"))
        r = subprocess.run(merge, capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("merged already", r.stdout)
        self.assertEqual(read(os.path.join(case, "avalanches.csv")), before)
        r = subprocess.run(merge[:4] + [os.path.join(self.ref, "data"), "--case", CASES[0], "--data", main],
                           capture_output=True, text=True, timeout=60)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("REFUSED", r.stdout)
        self.assertEqual(read(os.path.join(case, "avalanches.csv")), before)

    def test_a_chain_without_its_restart_file_goes_on_with_a_new_fill(self):
        self.assertEqual(self.ref_rc, 0, self.ref_out)
        data = os.path.join(self.tmp, "moved", "data")
        shutil.copytree(os.path.join(self.ref, "data"), data)
        case = os.path.join(data, CASES[0])
        n = len(st.read_rows(os.path.join(case, "cycles.csv"))[2])
        cmd = driver(data, os.path.join(self.tmp, "moved", "work"))
        cmd[cmd.index("--max-cycles") + 1] = str(n + 1)
        cmd[cmd.index("--min-avalanches") + 1] = "1000"
        cmd = cmd[:cmd.index("--case")] + ["--case", CASES[0]] + cmd[cmd.index("--case") + 4:]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("fills a new silo", r.stdout)
        _, h, rows = st.read_rows(os.path.join(case, "cycles.csv"))
        self.assertEqual(len(rows), n + 1)
        self.assertEqual(rows[-1][h.index("new_fill")], "1")
        self.assertTrue(all(r[h.index("new_fill")] == "0" for r in rows[1:-1]))
        _, _, av = st.read_rows(os.path.join(case, "avalanches.csv"))
        self.assertTrue(any(int(r[0]) == n for r in av))

    def test_the_chain_goes_on_after_a_merge_numbered_cycles_after_it(self):
        # another chain's cycles merged after this chain's last one: this chain's next cycle
        # continues from its own restart file (renumbered), it does not fill a new silo
        self.assertEqual(self.ref_rc, 0, self.ref_out)
        base = os.path.join(self.tmp, "goes_on")
        data, work = os.path.join(base, "data"), os.path.join(base, "work")
        shutil.copytree(os.path.join(self.ref, "data", CASES[0]), os.path.join(data, CASES[0]))
        shutil.copytree(os.path.join(self.ref, "work", CASES[0]), os.path.join(work, CASES[0]))
        case = os.path.join(data, CASES[0])
        n = len(st.read_rows(os.path.join(case, "cycles.csv"))[2])
        self.assertTrue(os.path.exists(os.path.join(work, CASES[0], f"restart_{n - 1}.restart")))
        other = os.path.join(base, "other", CASES[0])  # "another chain": the same rows under another seed
        shutil.copytree(case, other)
        info = st.json.load(open(os.path.join(other, "case.json")))
        info["variables"] = dict(info.get("variables", {}), seed="17485869")
        st.write_atomic(os.path.join(other, "case.json"), st.json.dumps(info))
        self.assertIn("merged as", st.merge_case(other, case))
        m = len(st.read_rows(os.path.join(case, "cycles.csv"))[2])
        self.assertEqual(m, 2 * n)
        cmd = driver(data, work)
        cmd[cmd.index("--max-cycles") + 1] = str(m + 1)
        cmd[cmd.index("--min-avalanches") + 1] = "1000"
        cmd = cmd[:cmd.index("--case")] + ["--case", CASES[0]] + cmd[cmd.index("--case") + 4:]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn(f"cycle {m}: the chain's last cycle is {n - 1}", r.stdout)
        self.assertNotIn("fills a new silo", r.stdout)
        # the run rewrote case.json and kept the record of the merge
        info = st.json.load(open(os.path.join(case, "case.json")))
        self.assertEqual(info["merged_chains"]["17485869"]["cycles"], n)
        _, h, rows = st.read_rows(os.path.join(case, "cycles.csv"))
        self.assertEqual(len(rows), m + 1)
        self.assertEqual(rows[-1][h.index("new_fill")], "0")

    def test_a_stopped_cycle_numbered_over_by_a_merge_continues_as_the_next(self):
        work = os.path.join(self.tmp, "renumber")
        os.makedirs(os.path.join(work, "cycle_22"))
        for name, text in (("cycle_22/stop.restart", "state"), ("restart_21.restart", "start of 22"),
                           ("cycle_22/partial.json", st.json.dumps({"cycle": 22, "fresh": False, "n0": 9000,
                                                                    "parts": [], "restart": "stop.restart"}))):
            with open(os.path.join(work, name), "w") as f:
                f.write(text)
        data = os.path.join(self.tmp, "renumber_data")
        os.makedirs(data)
        rows = [[str(c), "0"] for c in range(25)]
        st.write_rows(os.path.join(data, "cycles.csv"), ["# cycles"], ["cycle", "new_fill"], rows)
        self.assertIsNone(st.renumber_own_state(work, data, 22))  # its own number: nothing to do
        # cycles 22-24 are not merged ones (a hand-over cut after the cycles.csv line): left alone,
        # the chain fills a new silo rather than run completed cycles again
        self.assertIsNone(st.renumber_own_state(work, data, 25))
        self.assertEqual(sorted(os.listdir(work)), ["cycle_22", "restart_21.restart"])
        st.write_rows(os.path.join(data, "cycles.csv"),
                      ["# cycles", "# merged: chain seed 16485866, its cycles 3-5 as cycles 22-24 (new_fill 0)"],
                      ["cycle", "new_fill"], rows)
        msg = st.renumber_own_state(work, data, 25)
        self.assertIn("cycle 22, stopped in its discharge", msg)
        self.assertEqual(sorted(os.listdir(work)), ["cycle_25", "restart_24.restart"])
        state = st.load_partial(os.path.join(work, "cycle_25"), 25)
        self.assertEqual((state["n0"], state["renumbered_from"], state["fresh"]), (9000, 22, False))
        self.assertEqual(read(os.path.join(work, "cycle_25", "stop.restart")), "state")
        self.assertIsNone(st.renumber_own_state(work, data, 25))  # done once

    def test_other_variables_are_refused(self):
        self.assertEqual(self.ref_rc, 0, self.ref_out)
        data = os.path.join(self.ref, "data")
        r = subprocess.run(driver(data, os.path.join(self.ref, "work"), ["-var", "timeout", "0.05"]),
                           capture_output=True, text=True, timeout=300)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("REFUSED", r.stdout)

    def test_analysis_of_the_results(self):
        self.assertEqual(self.ref_rc, 0, self.ref_out)
        out = os.path.join(self.tmp, "figures")
        r = subprocess.run([sys.executable, os.path.join(TOOLS, "silo_study_analysis.py"), "--data",
                            os.path.join(self.ref, "data"), "--out", out, "--bootstrap", "200"],
                           capture_output=True, text=True, timeout=300)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        for name in ("summary.json", "summary.md", "mean_avalanche.png", "distributions.png", "box.png"):
            self.assertGreater(os.path.getsize(os.path.join(out, name)), 100, name)
        import json
        with open(os.path.join(out, "summary.json")) as f:
            s = json.load(f)
        self.assertEqual(sorted(s["cases"]), sorted(CASES))
        self.assertEqual(s["cases"]["r0_phi0"]["ratio"], 1.0)

    def test_picture_with_relative_paths(self):
        # as tools/demo.sh calls it: --data and --work relative to the current folder
        self.assertEqual(self.ref_rc, 0, self.ref_out)
        r = subprocess.run([sys.executable, os.path.join(TOOLS, "silo_study.py"), "picture", "--case", CASES[0],
                            "--granary", GRANARY, "--data", os.path.join("ref", "data"), "--work",
                            os.path.join("ref", "work"), "--out", "clog.png"],
                           cwd=self.tmp, capture_output=True, text=True, timeout=600)
        log = read(os.path.join(self.ref, "work", CASES[0], "picture", "log"))
        self.assertNotIn("ERROR", log)  # the run found its restart file and meshes
        self.assertIn("Read restart file", log)
        if r.returncode == 0:
            self.assertTrue(os.path.exists(os.path.join(self.ref, "work", CASES[0], "picture", "clog_particles.vtp")))


class CaseNames(unittest.TestCase):
    def test_names(self):
        self.assertEqual(st.parse_case("r3.2_phi0.05"), {"phi": 0.05, "r": 3.2, "nres": 10})
        self.assertEqual(st.parse_case("r0_phi0_n50")["nres"], 50)
        self.assertEqual(st.case_name(0, 0, 50), "r0_phi0_n50")
        self.assertIn("r4.6_phi0.1", st.study_cases())
        self.assertEqual(len(st.study_cases()), 20)  # 1 + 3 x 6 + the 50-sphere case
        with self.assertRaises(ValueError):
            st.parse_case("phi0.05")
        with self.assertRaises(ValueError):
            st.parse_case("r0_phi0.05")

    def test_candidate_cases(self):
        # the candidate causes of the r = 4.6 discrepancy: 50-sphere clumps, cohesion of the spheres
        self.assertEqual(st.candidate_cases(), ["r4.6_phi0.075_n50", "r4.6_phi0.075_coh10000"])
        self.assertEqual(st.parse_case("r4.6_phi0.075_coh2e4"), {"phi": 0.075, "r": 4.6, "nres": 10, "kcoh": 2e4})
        self.assertEqual(st.parse_case("r4.6_phi0.075_n50_coh500")["nres"], 50)
        self.assertEqual(st.case_name(0.075, 4.6, 10, 2e4), "r4.6_phi0.075_coh20000")
        self.assertNotIn("kcoh", st.parse_case("r4.6_phi0.075"))
        with self.assertRaises(ValueError):
            st.parse_case("r0_phi0_coh100")  # no spheres to be cohesive

        class A:
            np, granary, work = 1, "granary", "/w"

        cmd = st.cycle_command(A, "r4.6_phi0.075_coh10000", 0, True, {})
        self.assertEqual(cmd[cmd.index("kcoh") + 1], "10000")
        self.assertNotIn("kcoh", st.cycle_command(A, "r4.6_phi0.075", 0, True, {}))

    @unittest.skipUnless(os.path.exists(GRANARY), f"granary not built ({GRANARY})")
    def test_cohesion_switched_on_by_kcoh_only(self):
        # in.cycle: kcoh > 0 gives cohesion sjkr on the contacts of a sphere (not cylinder-cylinder);
        # without kcoh the pair style is the study's
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run([sys.executable, os.path.join(TOOLS, "make_silo_stl.py"), "--W", "7", "--D", "2",
                            "--H", "11", "--slit", "2.3", "--out", tmp], check=True, capture_output=True)
            logs = {}
            for k in ("0", "2e4"):
                r = subprocess.run([GRANARY, "-in", st.SCRIPT, "-log", f"log{k}", "-screen", "none",
                                    "-var", "restart_out", "c.restart", "-var", "phi", "0.1",
                                    "-var", "potdir", os.path.join(ROOT, "potentials"), "-var", "meshdir", tmp,
                                    "-var", "kcoh", k, "-var", "discharge_max", "200"] + TINY,
                                   cwd=tmp, capture_output=True, text=True, timeout=300)
                self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
                logs[k] = read(os.path.join(tmp, f"log{k}")).splitlines()
            style = "pair_style gran model hertz tangential history rolling_friction cdt"
            self.assertIn(style, logs["0"])
            self.assertIn(style + " cohesion sjkr", logs["2e4"])
            self.assertIn("fix m4 all property/global cohesionEnergyDensity peratomtypepair 2 0 2e4 2e4 2e4",
                          logs["2e4"])
            self.assertFalse(any("cohesionEnergyDensity" in ln and not ln.lstrip().startswith(("#", "if"))
                                 for ln in logs["0"]))


if __name__ == "__main__":
    unittest.main(verbosity=2)
