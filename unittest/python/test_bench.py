#!/usr/bin/python3
"""tools/bench.py: reading both programs' end-of-run reports, and one real run."""
import io
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
TOOLS = os.path.join(ROOT, "tools")
sys.path.insert(0, TOOLS)
import bench  # noqa: E402

# Granary (LAMMPS-style table with min/avg/max), two runs in one script
GRANARY = """Granary 0.1.0
Step Atoms KinEng c_rke
         0        100  1.0  0
Loop time of 2.5 on 2 procs for 1000 steps with 100 atoms

Performance: 4e+04 particle-steps/s, 400 steps/s
Section |  min time  |  avg time  |  max time  |%varavg| %total
---------------------------------------------------------------
Pair    |        0.9 |          1 |        1.1 |  20.0 |  40.0
Neigh   |        0.4 |        0.5 |        0.6 |  40.0 |  20.0
Comm    |        0.1 |        0.1 |        0.1 |   0.0 |   4.0
Modify  |        0.7 |        0.8 |        0.9 |  25.0 |  32.0
Output  |          0 |          0 |          0 |   0.0 |   0.0
Other   |        0.1 |        0.1 |        0.1 |   0.0 |   4.0

Fix (ID style)                  |  min time  |  avg time  |  max time  |%varavg| %total
-----------------------------------------------------------------------------------------
fix ms multisphere              |        0.3 |        0.4 |        0.5 |  50.0 |  16.0
fix wall wall/gran              |        0.1 |        0.2 |        0.3 | 100.0 |   8.0
fix walls mesh/surface          |       0.01 |       0.02 |       0.03 | 100.0 |   0.8
fix integr nve/sphere           |        0.1 |        0.1 |        0.1 |   0.0 |   4.0
Neighbor list builds = 12

Loop time of 1.5 on 2 procs for 500 steps with 90 atoms

Section |  min time  |  avg time  |  max time  |%varavg| %total
---------------------------------------------------------------
Pair    |        0.5 |        0.5 |        0.5 |   0.0 |  33.3
Neigh   |        0.2 |        0.2 |        0.2 |   0.0 |  13.3
Comm    |        0.1 |        0.1 |        0.1 |   0.0 |   6.7
Modify  |        0.6 |        0.6 |        0.6 |   0.0 |  40.0
Output  |          0 |          0 |          0 |   0.0 |   0.0
Other   |        0.1 |        0.1 |        0.1 |   0.0 |   6.7

Fix (ID style)                  |  min time  |  avg time  |  max time  |%varavg| %total
-----------------------------------------------------------------------------------------
fix ms multisphere              |        0.3 |        0.3 |        0.3 |   0.0 |  20.0
"""

# LIGGGHTS 3.8 (old LAMMPS lines, means over the ranks; fixes under Other)
LIGGGHTS = """LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0, compiled 2022-01-26)
Loop time of 4.89531 on 1 procs for 2000 steps with 22560 atoms, finish time Sat Nov 21 16:03:59 2026

Pair  time (%) = 1.47608 (30.1528)
Neigh time (%) = 0.469084 (9.58231)
Comm  time (%) = 0.0112409 (0.229627)
Outpt time (%) = 0.000104256 (0.00212971)
Other time (%) = 2.93881 (60.0331)
"""


class ParseReports(unittest.TestCase):
    def test_contacts_are_averaged_per_run_and_weighted_by_steps(self):
        # Granary's header names the column c_contacts, LIGGGHTS' contacts; the
        # sum of contact/atom counts each contact at both ends
        text = ("Step Atoms KinEng c_contacts\n 0 10 1 100\n 500 10 1 300\n"
                "Loop time of 2 on 1 procs for 1000 steps with 10 atoms\n"
                "    Step    Atoms         KinEng       contacts \n 1000 10 1 600\n"
                "Loop time of 1 on 1 procs for 3000 steps with 10 atoms\n")
        info = bench.parse_output(text)
        # run 1: mean 200 ends = 100 contacts over 1000 steps; run 2: 300 over 3000
        self.assertAlmostEqual(info["contacts"], (100 * 1000 + 300 * 3000) / 4000)
        self.assertNotIn("contacts", bench.parse_output(GRANARY))

    def test_granary_sections_sum_over_runs(self):
        info = bench.parse_output(GRANARY)
        self.assertAlmostEqual(info["loop_s"], 4.0)
        self.assertEqual(info["steps"], 1500)
        self.assertEqual(info["particles"], 90)  # the last run's count
        split, most = info["time_split_s"], info["time_split_max_s"]
        self.assertAlmostEqual(split["pair"], 1.5)
        self.assertAlmostEqual(split["neigh"], 0.7)
        self.assertAlmostEqual(split["fixes"], 1.4)
        self.assertAlmostEqual(split["other"], 0.2)
        self.assertAlmostEqual(most["pair"], 1.6)
        self.assertAlmostEqual(most["fixes"], 1.5)
        # the per-fix lines: fix multisphere apart, the wall fixes together, others left out
        self.assertEqual(set(info["fix_split_s"]), {"multisphere", "walls"})
        self.assertAlmostEqual(info["fix_split_s"]["multisphere"], 0.7)
        self.assertAlmostEqual(info["fix_split_s"]["walls"], 0.22)

    def test_liggghts_sections(self):
        info = bench.parse_output(LIGGGHTS)
        self.assertAlmostEqual(info["loop_s"], 4.89531)
        self.assertEqual(info["particles"], 22560)
        split = info["time_split_s"]
        self.assertAlmostEqual(split["pair"], 1.47608)
        self.assertAlmostEqual(split["output"], 0.000104256)
        self.assertAlmostEqual(split["other"], 2.93881)
        self.assertNotIn("fixes", split)
        self.assertNotIn("time_split_max_s", info)
        self.assertNotIn("fix_split_s", info)

    def test_split_table_reports_imbalance_on_several_ranks(self):
        rows = [dict(program="granary", ranks=2, **bench.parse_output(GRANARY))]
        out = io.StringIO()
        bench.print_split(rows, out)
        lines = out.getvalue().splitlines()
        self.assertEqual(len(lines), 3)  # heading, rule, one row
        cells = [c.strip() for c in lines[2].strip("|").split("|")]
        self.assertEqual(cells[:4], ["granary", "2", "1.50", "0.70"])
        # (1.6 + 0.8 + 1.5) / (1.5 + 0.7 + 1.4), then fix multisphere and the walls
        self.assertEqual(cells[-3:], ["%.2f" % (3.9 / 3.6), "0.70", "0.22"])
        rows = [dict(program="liggghts", ranks=1, **bench.parse_output(LIGGGHTS))]
        out = io.StringIO()
        bench.print_split(rows, out)
        cells = [c.strip() for c in out.getvalue().splitlines()[2].strip("|").split("|")]
        self.assertEqual(cells[-3:], ["-", "-", "-"])


# the lines of tools/mpi_times.c, between the program's own output
MPI_TIMES = """Loop time of 2.5 on 2 procs for 1000 steps with 100 atoms
mpi_times rank 1: Sendrecv 2000 0.300000; Allreduce 1010 0.100000; Waitall 1000 0.050000;
mpi_times rank 0: Sendrecv 2000 0.200000; Allreduce 1010 0.150000;
"""


class MpiTimes(unittest.TestCase):
    def test_lines_give_mean_and_slowest_rank_per_call(self):
        m = bench.parse_mpi_times(MPI_TIMES)
        self.assertEqual(m["ranks"], 2)
        self.assertEqual(m["calls"], {"Sendrecv": 4000, "Allreduce": 2020, "Waitall": 1000})
        self.assertAlmostEqual(m["mean_s"]["Sendrecv"], 0.25)
        self.assertAlmostEqual(m["max_s"]["Allreduce"], 0.15)
        self.assertAlmostEqual(m["mean_s"]["Waitall"], 0.025)  # rank 0 made none
        self.assertAlmostEqual(m["total_mean_s"], (0.45 + 0.35) / 2)
        self.assertAlmostEqual(m["total_max_s"], 0.45)
        self.assertIsNone(bench.parse_mpi_times(GRANARY))

    def test_table_lists_the_costliest_calls(self):
        row = dict(program="granary", ranks=2, loop_s=2.5, mpi_times=bench.parse_mpi_times(MPI_TIMES))
        out = io.StringIO()
        bench.print_mpi_times([row], out, ncalls=2)
        lines = out.getvalue().splitlines()
        heads = [c.strip() for c in lines[0].strip("|").split("|")]
        self.assertEqual(heads[3:5], ["MPI_Sendrecv s (calls)", "MPI_Allreduce s (calls)"])
        cells = [c.strip() for c in lines[2].strip("|").split("|")]
        self.assertEqual(cells[3], "0.250 / 0.300 (4000)")
        self.assertEqual(cells[-2:], ["0.400 / 0.450", "%.3f" % (0.4 / 2.5)])


@unittest.skipUnless(os.path.exists(os.environ.get("GRANARY_BINARY", "")), "GRANARY_BINARY not set")
class RealRun(unittest.TestCase):
    @unittest.skipUnless(shutil.which("mpicc") and shutil.which("mpirun"), "mpicc or mpirun not on PATH")
    def test_mpi_times_are_recorded_per_rank(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "bench.json")
            r = subprocess.run([sys.executable, os.path.join(TOOLS, "bench.py"), "--only", "granary", "--ranks",
                                "2", "--nsteps", "50", "--granary", os.environ["GRANARY_BINARY"], "--json", out,
                                "--mpi-times"], capture_output=True, text=True, cwd=ROOT)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            with open(out) as f:
                row = json.load(f)["results"][0]
        m = row["mpi_times"]
        self.assertEqual(m["ranks"], 2)
        # every step each rank takes part in the rebuild decision (one MPI_Allreduce)
        # and receives its ghosts: their positions (both swaps of the split
        # dimension at once, one MPI_Waitall) or, at a rebuild, the ghosts
        # themselves (MPI_Sendrecv)
        self.assertGreaterEqual(m["calls"]["Allreduce"], 2 * 50)
        self.assertGreaterEqual(m["calls"]["Waitall"] + m["calls"].get("Sendrecv", 0), 2 * 50)
        self.assertGreater(m["total_mean_s"], 0.0)
        self.assertLess(m["total_max_s"], row["wall_s"])
        self.assertIn("time inside blocking MPI calls", r.stdout)
        # --mpi-times on one rank only: a usage error
        r = subprocess.run([sys.executable, os.path.join(TOOLS, "bench.py"), "--only", "granary", "--ranks", "1",
                            "--granary", os.environ["GRANARY_BINARY"], "--mpi-times"],
                           capture_output=True, text=True, cwd=ROOT)
        self.assertEqual(r.returncode, 2)
        self.assertIn("--mpi-times needs a rank count above 1", r.stderr)
        # a launcher that is not Open MPI's: refused before any run
        r = subprocess.run([sys.executable, os.path.join(TOOLS, "bench.py"), "--only", "granary", "--ranks", "2",
                            "--granary", os.environ["GRANARY_BINARY"], "--mpi-times", "--mpirun", shutil.which("echo")],
                           capture_output=True, text=True, cwd=ROOT)
        self.assertEqual(r.returncode, 2)
        self.assertIn("is not Open MPI's", r.stderr)

    def test_granary_run_is_measured_and_split(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "bench.json")
            r = subprocess.run([sys.executable, os.path.join(TOOLS, "bench.py"), "--only", "granary", "--ranks",
                                "1", "--nsteps", "100", "--granary", os.environ["GRANARY_BINARY"], "--json", out],
                               capture_output=True, text=True, cwd=ROOT)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            with open(out) as f:
                row = json.load(f)["results"][0]
        self.assertEqual(row["particles"], 20184)
        self.assertEqual(row["steps"], 100)
        self.assertGreater(row["particle_steps_per_s"], 0)
        self.assertGreater(row["peak_rss_mib"], 1)
        split = row["time_split_s"]
        for key in ("pair", "neigh", "comm", "fixes", "output", "other"):
            self.assertIn(key, split)
        # the sections and "other" make up the loop time
        self.assertAlmostEqual(sum(split.values()), row["loop_s"], delta=0.02 * row["loop_s"] + 1e-3)
        self.assertIn("time split", r.stdout)

    def test_scaling_script_measures_each_rank_count_and_reuses_the_bed(self):
        # tools/scaling.sh at a tiny size: a bed of about 13,000 particles, 1 and 2 ranks
        script = os.path.join(TOOLS, "scaling.sh")
        with tempfile.TemporaryDirectory() as tmp:
            cmd = ["bash", script, "--ranks", "2,1", "--vf", "0.02", "--settle", "50", "--nsteps", "50",
                   "--balance", "4", "--granary", os.environ["GRANARY_BINARY"], "--out", tmp]
            r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertIn("granary_insert:", r.stdout)
            with open(os.path.join(tmp, "granary.json")) as f:
                rows = json.load(f)["results"]
            self.assertEqual(sorted(row["ranks"] for row in rows), [1, 2])
            for row in rows:
                self.assertGreater(row["particles"], 10000)
                self.assertEqual(row["steps"], 50)
                self.assertIn("multisphere", row["fix_split_s"])
                # with mpicc, each rank's time in MPI on more than one rank
                self.assertEqual("mpi_times" in row, bool(shutil.which("mpicc")) and row["ranks"] > 1)
            with open(os.path.join(tmp, "granary_balance.json")) as f:
                rows = json.load(f)["results"]
            self.assertEqual([row["ranks"] for row in rows], [2])
            # a second call starts from the settled bed of the first; with
            # --contention, the bed cut into the two boxes of the 2-rank grid,
            # each box's particles run alone and beside the other
            r = subprocess.run(cmd + ["--contention", "--contention-steps", "60"], capture_output=True, text=True,
                               cwd=ROOT)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertNotIn("granary_insert:", r.stdout)
            self.assertNotIn("granary_settle:", r.stdout)
            self.assertIn("granary_discharge:", r.stdout)
            self.assertIn("contention:", r.stdout)
            with open(os.path.join(tmp, "contention.txt")) as f:
                text = f.read()
            self.assertIn("the 2 boxes of the", text)
            self.assertIn("discharged for 60 steps on one rank", text)
            shares = re.findall(r"share (\d): (\d+) particles, loop alone (\S+) s, beside the others (\S+) s", text)
            self.assertEqual([int(k) for k, _, _, _ in shares], [0, 1], text)
            # the boxes part the bed: together they hold it but for the clumps their faces cut
            total = rows[0]["particles"]
            held = sum(int(n) for _, n, _, _ in shares)
            self.assertLessEqual(held, total)
            self.assertGreater(held, 0.8 * total)
            self.assertTrue(all(int(n) > 0.2 * total for _, n, _, _ in shares), text)
            alone = sum(float(a) for _, _, a, _ in shares)
            beside = sum(float(b) for _, _, _, b in shares)
            a, b, ratio = map(float, re.search(r"alone / beside the others: (\S+) / (\S+) s = (\S+)", text).groups())
            self.assertAlmostEqual(a, alone, delta=0.001 * alone + 1e-3)
            self.assertAlmostEqual(b, beside, delta=0.001 * beside + 1e-3)
            self.assertAlmostEqual(ratio, alone / beside, delta=0.002 * ratio + 0.001)
            # the shares ran side by side: together for part of each one's run, never longer than it
            together, each = map(float, re.search(r"together: (\S+) s of the (\S+) s each", text).groups())
            self.assertGreater(together, 0.0, text)
            self.assertLessEqual(together, each * 1.001, text)
            for k in (0, 1):
                for name in ("c.alone%d" % k, "c.copy%d" % k):
                    with open(os.path.join(tmp, name + ".screen")) as f:
                        screen = f.read()
                    self.assertIn("for 60 steps", screen)
                    # the share sorted after the cut by a run of no steps before its discharge
                    self.assertLess(screen.index("for 0 steps"), screen.index("for 60 steps"))
            # an unknown option: a clear error, exit status 2
            r = subprocess.run(["bash", script, "--rank", "4"], capture_output=True, text=True, cwd=ROOT)
            self.assertEqual(r.returncode, 2)
            self.assertIn("unknown option '--rank'", r.stderr)

    @unittest.skipUnless(shutil.which("liggghts"), "liggghts not on PATH")
    def test_repeated_runs_take_turns_and_keep_the_fastest(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "bench.json")
            keep = os.path.join(tmp, "outputs")
            r = subprocess.run([sys.executable, os.path.join(TOOLS, "bench.py"), "--ranks", "1", "--nsteps", "20",
                                "--repeat", "2", "--granary", os.environ["GRANARY_BINARY"], "--json", out,
                                "--keep-output", keep],
                               capture_output=True, text=True, cwd=ROOT)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            with open(out) as f:
                rows = json.load(f)["results"]
            loops = {}
            for prog in ("liggghts", "granary"):
                for rep in (0, 1):
                    with open(os.path.join(keep, "%s_np1_rep%d.out" % (prog, rep))) as f:
                        loops.setdefault(prog, []).append(bench.parse_output(f.read())["loop_s"])
        order = [line.split()[1] for line in r.stdout.splitlines() if line.startswith("running ")]
        self.assertEqual(order, ["liggghts", "granary", "liggghts", "granary"])
        self.assertEqual([row["program"] for row in rows], ["liggghts", "granary"])
        for row in rows:
            self.assertEqual(row["steps"], 20)
            self.assertEqual(row["loop_s"], min(loops[row["program"]]))  # the faster of the two runs

if __name__ == "__main__":
    unittest.main()
