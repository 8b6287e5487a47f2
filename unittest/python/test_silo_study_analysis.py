#!/usr/bin/python3
"""tools/silo_study_analysis.py on generated results with a hidden effect.

Avalanche sizes are drawn from exponential distributions whose means have a
minimum at a phi the test knows (and box quantities with a known dependence);
the analysis must find the minimum where it was put, call it significant, see
the sizes as exponential, and find nothing significant in data without an
effect; sizes that are not exponential must fail the exponential test.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.join(ROOT, "tools", "silo_study_analysis.py")
PHIS = [0.0, 0.01, 0.02, 0.03, 0.05, 0.075, 0.1]
M_BODY = 2.0e-5  # kg per body


def write_case(root, name, sizes, box=None, cycles=4, sphere_share=0.0):
    """avalanches.csv (and box.csv) of one case in the format of tools/silo_study.py;
    `sphere_share` of the box's solid volume and of each avalanche's mass are spheres (type 2)."""
    d = os.path.join(root, name)
    os.makedirs(d)
    n = len(sizes)
    per = int(np.ceil(n / cycles))
    rows, box_rows, t = [], [], 0.0
    for i, s in enumerate(sizes):
        c, k = i // per, i % per + 1
        bodies = int(round(s / M_BODY))
        dur = 0.005 * bodies + 0.01
        m2 = sphere_share * bodies * M_BODY
        rows.append([c, k, t, t + dur, t + dur + 0.03, dur, bodies, bodies * M_BODY, 0.0, 0.04, 3, bodies,
                     bodies * M_BODY - m2, 0, m2])
        if box:
            for j in range(1, 4):  # three box rows inside the avalanche
                tj = t + dur * j / 3
                phi_t, kte, kre, theta = box
                phi_s = sphere_share * phi_t
                box_rows.append([c, 1000 * i + j, tj, phi_t, phi_t - phi_s, phi_s, kte, kre, 30, 0.0, 0.0, 0, theta,
                                 0])
        t += dur + 0.05
    with open(os.path.join(d, "avalanches.csv"), "w") as f:
        f.write("# generated\ncycle,avalanche,t_start,t_end,t_clog,duration,bodies,mass,flow_rate,fill_height,"
                "arch_removed,bodies_t1,mass_t1,bodies_t2,mass_t2\n")
        for r in rows:
            f.write(",".join(f"{x:.10g}" for x in r) + "\n")
    if box:
        with open(os.path.join(d, "box.csv"), "w") as f:
            f.write("# generated\ncycle,step,time,phi,phi_c,phi_s,ke_c,erot_c,n_c,ke_s,erot_s,n_s,theta,state\n")
            for r in box_rows:
                f.write(",".join(f"{x:.10g}" for x in r) + "\n")


def analyse(data, out):
    r = subprocess.run([sys.executable, TOOL, "--data", data, "--out", out, "--bootstrap", "1000"],
                       capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"))
    if r.returncode != 0:
        raise AssertionError(r.stdout + r.stderr)
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


class HiddenMinimum(unittest.TestCase):
    def test_minimum_found_where_it_was_put(self):
        rng = np.random.default_rng(7)
        # <S>/<S0> = 1 - 0.45 at phi = 0.03, rising steeply after; box quantities with their extremum there
        ratio = {0.0: 1.0, 0.01: 0.8, 0.02: 0.65, 0.03: 0.55, 0.05: 0.75, 0.075: 1.3, 0.1: 2.2}
        kte = {0.0: 1.0, 0.01: 0.9, 0.02: 0.8, 0.03: 0.7, 0.05: 0.8, 0.075: 1.0, 0.1: 1.2}
        theta = {0.0: 0.9, 0.01: 0.92, 0.02: 0.95, 0.03: 0.98, 0.05: 0.96, 0.075: 0.93, 0.1: 0.9}
        with tempfile.TemporaryDirectory() as tmp:
            data = os.path.join(tmp, "data")
            for phi in PHIS:
                name = "r0_phi0" if phi == 0 else f"r3.2_phi{phi:g}"
                sizes = rng.exponential(ratio[phi] * 40 * M_BODY, 150) + M_BODY
                # the spheres reach the box at a third of the filled fraction, the discharge at half
                write_case(data, name, sizes, box=(0.51 + 0.4 * phi, 1e-6 * kte[phi], 2e-7 * kte[phi], theta[phi]),
                           sphere_share=phi / 3)
                if phi:  # the discharge: a mass share of phi / 2 instead
                    path = os.path.join(data, name, "avalanches.csv")
                    with open(path) as f:
                        text = f.read().splitlines()
                    out = text[:2]
                    for line in text[2:]:
                        v = [float(x) for x in line.split(",")]
                        v[14] = v[7] * phi / 2
                        v[12] = v[7] - v[14]
                        out.append(",".join(f"{x:.10g}" for x in v))
                    with open(path, "w") as f:
                        f.write("\n".join(out) + "\n")
            s = analyse(data, os.path.join(tmp, "out"))
            m = s["minimum"]["3.2"]
            self.assertEqual(m["phi_min"], 0.03)
            self.assertLess(m["p_below_phi0"], 0.01)
            self.assertLess(m["p_below_last"], 0.01)
            self.assertAlmostEqual(m["ratio_min"], 0.55, delta=0.15)
            self.assertEqual(m["n_phi"], len(PHIS))
            self.assertLess(m["p_all_alike"], 1e-3)  # <S> depends on phi
            lo, hi = s["cases"]["r3.2_phi0.03"]["ratio_ci95"]
            self.assertLess(hi, 1.0)
            self.assertLess(lo, 0.55 + 0.02)
            # every body of the generated avalanches is a cylinder: as many cylinders as the mass says
            c3 = s["cases"]["r3.2_phi0.03"]
            self.assertAlmostEqual(c3["cyl_ratio"], c3["ratio"], delta=0.02)
            self.assertLess(c3["cyl_ratio_ci95"][1], 1.0)
            for name, c in s["cases"].items():
                self.assertEqual(c["n"], 150 - 4, name)  # the first avalanche of each of 4 cycles apart
                self.assertEqual(c["first_n"], 4, name)
                self.assertGreater(c["ks_p"], 0.001, name)  # exponential sizes pass
                self.assertAlmostEqual(c["cv"], 1.0, delta=0.3)
            # the box: kinetic energy ratio with its minimum and theta with its maximum at phi = 0.03
            kr = {n: c["box_k_te_ratio"] for n, c in s["cases"].items()}
            self.assertEqual(min(kr, key=kr.get), "r3.2_phi0.03")
            th = {n: c["box_theta"] for n, c in s["cases"].items()}
            self.assertEqual(max(th, key=th.get), "r3.2_phi0.03")
            self.assertAlmostEqual(s["cases"]["r3.2_phi0.03"]["box_phi"], 0.51 + 0.4 * 0.03, places=6)
            # the composition where it was put: box a third, discharge half of the filled fraction
            for name, c in s["cases"].items():
                phi = c["phi"]
                self.assertAlmostEqual(c["box_sphere_share"], phi / 3, places=9, msg=name)
                if phi:
                    self.assertAlmostEqual(c["discharge_sphere_mass_share"], phi / 2, places=9, msg=name)
            with open(os.path.join(tmp, "out", "summary.md")) as f:
                self.assertIn("| r3.2_phi0.03 | 0.03 | 0.0100 ± 0.0000 | 0.0150 |", f.read())
            for f in ("mean_avalanche.png", "distributions.png", "box.png", "summary.md"):
                self.assertGreater(os.path.getsize(os.path.join(tmp, "out", f)), 1000, f)

    def test_no_effect_no_significant_minimum(self):
        rng = np.random.default_rng(11)
        with tempfile.TemporaryDirectory() as tmp:
            data = os.path.join(tmp, "data")
            for phi in PHIS:
                name = "r0_phi0" if phi == 0 else f"r3.2_phi{phi:g}"
                write_case(data, name, rng.exponential(40 * M_BODY, 150) + M_BODY)
            s = analyse(data, os.path.join(tmp, "out"))
            m = s["minimum"]["3.2"]
            # the smallest of seven equal means is below phi = 0 by chance only: with a
            # correction for the six comparisons, not significant
            self.assertGreater(min(1.0, 6 * m.get("p_below_phi0", 1.0)), 0.05)
            self.assertGreater(m["p_all_alike"], 0.05)  # seven cases of one distribution

    def test_cylinders_counted_apart_from_the_spheres_mass(self):
        # spheres add mass (a third of it at phi = 0.1) to avalanches of as many cylinders as at
        # phi = 0: <S>/<S0> rises by 1.5, the cylinders per avalanche do not
        rng = np.random.default_rng(13)
        with tempfile.TemporaryDirectory() as tmp:
            data = os.path.join(tmp, "data")
            write_case(data, "r0_phi0", rng.exponential(40 * M_BODY, 300) + M_BODY)
            write_case(data, "r3.2_phi0.1", rng.exponential(40 * M_BODY, 300) + M_BODY)
            path = os.path.join(data, "r3.2_phi0.1", "avalanches.csv")
            with open(path) as f:
                text = f.read().splitlines()
            out = text[:2]
            for line in text[2:]:
                v = [float(x) for x in line.split(",")]
                v[7] *= 1.5  # mass: the cylinders' plus half as much glass
                v[14] = v[7] / 3
                v[12] = v[7] - v[14]
                out.append(",".join(f"{x:.10g}" for x in v))
            with open(path, "w") as f:
                f.write("\n".join(out) + "\n")
            c = analyse(data, os.path.join(tmp, "out"))["cases"]["r3.2_phi0.1"]
            self.assertGreater(c["ratio_ci95"][0], 1.2)
            self.assertAlmostEqual(c["cyl_ratio"], c["ratio"] / 1.5, places=9)
            self.assertLess(c["cyl_ratio_ci95"][0], 1.0)
            self.assertGreater(c["cyl_ratio_ci95"][1], 1.0)

    def test_sizes_that_are_not_exponential_fail(self):
        rng = np.random.default_rng(3)
        with tempfile.TemporaryDirectory() as tmp:
            data = os.path.join(tmp, "data")
            write_case(data, "r0_phi0", rng.exponential(40 * M_BODY, 150) + M_BODY)
            write_case(data, "r3.2_phi0.05", rng.normal(40 * M_BODY, 5 * M_BODY, 150))
            s = analyse(data, os.path.join(tmp, "out"))
            self.assertLess(s["cases"]["r3.2_phi0.05"]["ks_p"], 0.01)
            self.assertLess(s["cases"]["r3.2_phi0.05"]["cv"], 0.3)
            self.assertGreater(s["cases"]["r0_phi0"]["ks_p"], 0.01)

    def test_empty_avalanches_are_counted_apart(self):
        rng = np.random.default_rng(5)
        with tempfile.TemporaryDirectory() as tmp:
            data = os.path.join(tmp, "data")
            sizes = np.concatenate([rng.exponential(40 * M_BODY, 60) + M_BODY, np.zeros(9)])
            write_case(data, "r0_phi0", sizes, cycles=1)
            s = analyse(data, os.path.join(tmp, "out"))
            c = s["cases"]["r0_phi0"]
            masses = np.round(sizes / M_BODY) * M_BODY
            # one cycle: its first avalanche is reported apart, the empty ones are counted apart
            self.assertEqual(c["n"], 59)
            self.assertEqual(c["n_empty"], 9)
            self.assertAlmostEqual(c["S_mean"], float(np.mean(masses[1:60])), places=12)
            self.assertAlmostEqual(c["first_S_mean"], float(masses[0]), places=12)
            # 59 non-empty avalanches: short of the 100 that complete a case
            self.assertFalse(c["complete"])
            with open(os.path.join(tmp, "out", "summary.md")) as f:
                self.assertIn("| r0_phi0 (in progress) |", f.read())

    def test_first_avalanche_of_a_cycle_apart_and_found_smaller(self):
        # the first avalanche of every cycle drawn with a third of the mean: reported apart,
        # and the Mann-Whitney test against the others says they differ
        rng = np.random.default_rng(9)
        with tempfile.TemporaryDirectory() as tmp:
            data = os.path.join(tmp, "data")
            sizes = rng.exponential(40 * M_BODY, 200) + M_BODY
            sizes[::10] /= 3  # 20 cycles of 10 avalanches: the first of each
            write_case(data, "r0_phi0", sizes, cycles=20)
            s = analyse(data, os.path.join(tmp, "out"))
            c = s["cases"]["r0_phi0"]
            self.assertEqual(c["first_n"], 20)
            self.assertEqual(c["n"], 180)
            self.assertLess(c["first_vs_rest_p"], 0.01)
            self.assertLess(c["first_S_mean"], 0.5 * c["S_mean"])


class CandidateCauses(unittest.TestCase):
    """The cases of the candidate causes (another clump resolution, cohesion of the spheres) against
    the study's case of the same r and phi: a cause hidden in one of them is found, the other,
    which changes nothing once normalised by its own <S0>, is not; adding them leaves the study's
    numbers as they were."""

    def write_study(self, data, rng):
        write_case(data, "r0_phi0", rng.exponential(40 * M_BODY, 150) + M_BODY)
        write_case(data, "r4.6_phi0.075", rng.exponential(1.5 * 40 * M_BODY, 150) + M_BODY)
        # 50-sphere clumps: <S0> 0.6 times the 10-sphere one
        write_case(data, "r0_phi0_n50", rng.exponential(0.6 * 40 * M_BODY, 150) + M_BODY)

    def test_hidden_cause_found_the_other_not(self):
        rng = np.random.default_rng(21)
        with tempfile.TemporaryDirectory() as tmp:
            data = os.path.join(tmp, "data")
            self.write_study(data, rng)
            alone = analyse(data, os.path.join(tmp, "alone"))
            self.assertEqual(alone["candidates"], {})
            # cohesion halves <S>/<S0> (1.5 -> 0.75); the 50-sphere clumps keep it at 1.5 of their own <S0>
            write_case(data, "r4.6_phi0.075_coh10000", rng.exponential(0.75 * 40 * M_BODY, 150) + M_BODY)
            write_case(data, "r4.6_phi0.075_n50", rng.exponential(1.5 * 0.6 * 40 * M_BODY, 150) + M_BODY)
            s = analyse(data, os.path.join(tmp, "out"))
            coh, n50 = s["candidates"]["r4.6_phi0.075_coh10000"], s["candidates"]["r4.6_phi0.075_n50"]
            self.assertEqual(coh["baseline"], "r4.6_phi0.075")
            self.assertEqual(n50["baseline"], "r4.6_phi0.075")
            self.assertIn("cohesion", coh["cause"])
            self.assertIn("50-sphere", n50["cause"])
            self.assertAlmostEqual(coh["change"], 0.5, delta=0.15)
            self.assertLess(coh["change_ci95"][1], 1.0)
            self.assertLess(coh["p_no_change"], 0.01)
            self.assertGreater(coh["share_below_1"], 0.9)
            # normalised by its own <S0> (r0_phi0_n50) the 50-sphere case changes nothing; by the
            # 10-sphere <S0> it would seem to shrink by 0.6
            self.assertAlmostEqual(n50["change"], 1.0, delta=0.25)
            self.assertLess(n50["change_ci95"][0], 1.0)
            self.assertGreater(n50["change_ci95"][1], 1.0)
            self.assertGreater(n50["p_no_change"], 0.05)
            self.assertLess(n50["share_below_1"], 0.1)
            self.assertEqual(s["cases"]["r4.6_phi0.075_coh10000"]["kcoh"], 10000.0)
            # the study's cases: the same numbers with and without the candidates
            for name, row in alone["cases"].items():
                self.assertEqual(row, s["cases"][name], name)
            self.assertEqual(alone["minimum"], s["minimum"])
            with open(os.path.join(tmp, "out", "summary.md")) as f:
                md = f.read()
            self.assertIn("| cohesion of the spheres (sjkr, 10000 J/m^3) | r4.6_phi0.075_coh10000 | r4.6_phi0.075 |",
                          md)
            self.assertIn("| clump resolution (50-sphere clumps) | r4.6_phi0.075_n50 | r4.6_phi0.075 |", md)


class UpdateDocs(unittest.TestCase):
    """--update-docs: the tables are replaced between their markers, the
    text around them kept; a missing block is refused and the file left as
    it was; the cost table marks a case short of 100 avalanches."""

    def setUp(self):
        sys.path.insert(0, os.path.join(ROOT, "tools"))
        import silo_study
        import silo_study_analysis
        self.tool, self.study = silo_study_analysis, silo_study

    def test_block_replaced_text_around_kept(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "doc.md")
            with open(path, "w") as f:
                f.write("intro\n\n| case | cycles | avalanches |\n|---|\n| old | 1 | 2 |\n\nColumns: `bodies` ...\nend\n")
            self.tool.replace_block(path, "| case | cycles | avalanches |", lambda ln: ln.startswith("Columns"),
                                    "| case | cycles | avalanches |\n|---|\n| new | 3 | 4 |\n\n")
            with open(path) as f:
                self.assertEqual(f.read(), "intro\n\n| case | cycles | avalanches |\n|---|\n| new | 3 | 4 |\n\n"
                                           "Columns: `bodies` ...\nend\n")

    def test_missing_block_refused_file_unchanged(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "doc.md")
            text = "intro\n| case | cycles | avalanches |\n| old | 1 | 2 |\n"  # no closing marker
            with open(path, "w") as f:
                f.write(text)
            with self.assertRaises(SystemExit) as e:
                self.tool.replace_block(path, "| case | cycles | avalanches |", lambda ln: ln.startswith("Columns"),
                                        "x\n")
            self.assertIn(path, str(e.exception))
            with open(path) as f:
                self.assertEqual(f.read(), text)

    def test_cost_table_marks_cases_in_progress(self):
        rng = np.random.default_rng(3)
        with tempfile.TemporaryDirectory() as tmp:
            write_case(tmp, "r0_phi0", rng.exponential(40 * M_BODY, 120) + M_BODY, cycles=4)
            write_case(tmp, "r1.6_phi0.01", rng.exponential(40 * M_BODY, 50) + M_BODY, cycles=2)
            for name, ncyc in (("r0_phi0", 4), ("r1.6_phi0.01", 2)):
                with open(os.path.join(tmp, name, "cycles.csv"), "w") as f:
                    f.write("# generated\ncycle,new_fill,wall_s,ranks,particle_steps\n")
                    for c in range(ncyc):
                        f.write(f"{c},1,1800,2,1000000000\n")
            table, total = self.study.cost_markdown(tmp)
            rows = table.split("\n")[2:]
            self.assertEqual(rows[0], "| r0_phi0 | 4 | 116 | 4.00 | 4.00e+09 |")  # 120 less the 4 first of a cycle
            self.assertEqual(rows[1], "| r1.6_phi0.01 (in progress) | 2 | 48 | 2.00 | 2.00e+09 |")
            self.assertAlmostEqual(total, 6.0)


if __name__ == "__main__":
    unittest.main(verbosity=2)
