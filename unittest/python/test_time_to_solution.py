#!/usr/bin/python3
"""tools/time_to_solution.py: the paper's full case from a campaign's results (a made-up case)."""
import math
import os
import subprocess
import sys
import tempfile
import unittest

TOOLS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools")


def write(path, header, lines):
    with open(path, "w") as f:
        f.write("# made up\n" + header + "\n" + "\n".join(lines) + "\n")


class TimeToSolution(unittest.TestCase):
    def run_tool(self, *extra):
        with tempfile.TemporaryDirectory() as tmp:
            case = os.path.join(tmp, "r3.2_phi0.05")
            os.makedirs(case)
            # one complete cycle and one unfinished one (left out); avalanches:
            # 100 bodies, 10 g from t = 1.0 to 3.0 s, then an empty one to 3.5 s
            write(os.path.join(case, "cycles.csv"), "cycle,finished,sim_time_s", ["0,1,99", "1,0,99"])
            write(os.path.join(case, "avalanches.csv"), "cycle,t_start,t_end,bodies,mass",
                  ["0,1.0,3.0,100,0.01", "0,3.0,3.5,0,0", "1,9.0,9.5,7,0.001"])
            # variants of the study (another clump resolution, cohesion): named, not estimated
            for variant in ("r3.2_phi0.05_n50", "r3.2_phi0.05_coh10000"):
                os.makedirs(os.path.join(tmp, variant))
                for f in ("cycles.csv", "avalanches.csv"):
                    os.link(os.path.join(case, f), os.path.join(tmp, variant, f))
            r = subprocess.run([sys.executable, os.path.join(TOOLS, "time_to_solution.py"), "--results", tmp]
                               + list(extra), capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        row = [line for line in r.stdout.splitlines() if line.startswith("| r3.2_phi0.05")]
        self.assertEqual(len(row), 1, r.stdout)
        self.assertIn("(variants left out: r3.2_phi0.05_coh10000, r3.2_phi0.05_n50)", r.stdout)
        return [c.strip() for c in row[0].strip("|").split("|")]

    def test_by_hand(self):
        cells = self.run_tool("--granary-rate", "1.5e7", "--liggghts-rate", "6e6")
        dc3 = 3.2e-3 ** 3
        solid = 0.51 * 65 * 30 * 10 * dc3
        cylinders = solid * 0.95 / 15.086e-9
        spheres = solid * 0.05 / (math.pi / 6 * 1e-9)  # glass spheres of 1 mm (r = 3.2)
        self.assertAlmostEqual(float(cells[1]) / (50 * cylinders + spheres), 1.0, delta=1e-5)
        # 2.5 s of avalanches + 0.2 s of settling for 10 g; avalanches of 100 bodies of 0.1 g, both
        # scaled by the slit length 10/6; a cycle discharges 25/65 of the bed
        s_per_kg, scale = 2.7 / 0.01, 10 / 6
        cycle_mass = 25 / 65 * solid * (0.95 * 1190 + 0.05 * 2500)
        cycles = 100 / (cycle_mass / 1e-4 / (100 * scale))
        self.assertAlmostEqual(float(cells[2]), cycles, delta=0.06)
        sim_time = cycles * cycle_mass * s_per_kg / scale
        self.assertAlmostEqual(float(cells[3]) / sim_time, 1.0, delta=0.01)
        # the timestep: 0.2 Rayleigh times of the glass spheres (radius 0.5 mm, below the clump spheres' 0.66 mm)
        g = 5e6 / 2.9
        dt = 0.2 * math.pi * 0.5e-3 * math.sqrt(2500 / g) / (0.1631 * 0.45 + 0.8766)
        self.assertAlmostEqual(float(cells[4]), dt * 1e6, delta=0.06)
        steps = sim_time / dt
        self.assertAlmostEqual(float(cells[5]) / steps, 1.0, delta=0.01)
        psteps = steps * (50 * cylinders + spheres) * 52.5 / 65
        self.assertAlmostEqual(float(cells[6]) / psteps, 1.0, delta=0.01)
        g1, g16, g64 = (float(x) for x in cells[7].split("/"))
        l1, l16, l64 = (float(x) for x in cells[8].split("/"))
        self.assertAlmostEqual(g1 / (psteps / 1.5e7 / 3600), 1.0, delta=0.02)
        self.assertAlmostEqual(l1 / (psteps / 6e6 / 3600), 1.0, delta=0.02)
        self.assertAlmostEqual(g16 / (g1 / (16 * 0.52)), 1.0, delta=0.02)
        self.assertAlmostEqual(l64 / (l1 / (64 * 0.49)), 1.0, delta=0.02)

    def test_default_rates(self):
        # without the options the tool uses its RATE table
        sys.path.insert(0, TOOLS)
        import time_to_solution
        cells = self.run_tool()
        g1 = float(cells[7].split("/")[0])
        psteps = float(cells[6])
        self.assertAlmostEqual(g1 / (psteps / time_to_solution.RATE["granary"] / 3600), 1.0, delta=0.02)

    def test_bad_rate_refused(self):
        r = subprocess.run([sys.executable, os.path.join(TOOLS, "time_to_solution.py"), "--liggghts-rate", "0"],
                           capture_output=True, text=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("must be positive", r.stderr)

    def test_more_avalanches_cost_in_proportion(self):
        a, b = self.run_tool(), self.run_tool("--avalanches", "300")
        self.assertAlmostEqual(float(b[6]) / float(a[6]), 3.0, delta=0.01)


if __name__ == "__main__":
    unittest.main()
