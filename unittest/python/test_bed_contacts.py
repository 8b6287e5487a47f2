#!/usr/bin/python3
"""tools/bed_contacts.py on dumps written by the test: a clump of two
overlapping spheres, beads touching it and each other, one bead apart.

check must count the contacts by geometry (never two spheres of one clump),
report a contact the pair dump leaves out as missed (exit status 1), and pass
when the pair dump has them all; beads must give the contact numbers the
geometry has; a truncated dump is refused.
"""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.join(ROOT, "tools", "bed_contacts.py")

R, RB = 1.0e-3, 0.5e-3
# id type body x y z radius: clump 7 of spheres 1, 2 (overlapping, same body);
# bead 3 on sphere 1, bead 4 in the groove on spheres 1 and 2, bead 5 on bead 4,
# bead 6 alone
ATOMS = [(1, 1, 7, 0.0, 0.0, 0.0, R), (2, 1, 7, 1.2e-3, 0.0, 0.0, R),
         (3, 2, -1, -0.6e-3, 0.0, 1.35e-3, RB), (4, 2, -1, 0.6e-3, 0.0, 1.35e-3, RB),
         (5, 2, -1, 0.6e-3, 0.0, 2.34e-3, RB), (6, 2, -1, 0.0, 5e-3, 0.0, RB)]


def write(folder, step, atoms, pairs, truncate=False):
    with open(os.path.join(folder, f"diag_atoms.{step}.txt"), "w") as f:
        f.write(f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{len(atoms)}\nITEM: BOX BOUNDS ff ff ff\n"
                "-1 1\n-1 1\n-1 1\nITEM: ATOMS id type id_multisphere x y z radius\n")
        for a in atoms:
            f.write(" ".join(str(v) for v in a) + "\n")
        if truncate:
            f.write("6 2 -1 0.0\n")
    with open(os.path.join(folder, f"diag_pairs.{step}.txt"), "w") as f:
        f.write(f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ENTRIES\n{len(pairs)}\nITEM: BOX BOUNDS ff ff ff\n"
                "-1 1\n-1 1\n-1 1\nITEM: ENTRIES c_p[1] c_p[2]\n")
        for i, j in pairs:
            f.write(f"{i} {j}\n")


def run(*args):
    return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True)


class BedContacts(unittest.TestCase):
    # the geometry: 1-3, 1-4, 2-4, 4-5 (never 1-2, one clump)
    ALL = [(3, 1), (1, 4), (2, 4), (5, 4)]

    def test_all_found(self):
        with tempfile.TemporaryDirectory() as tmp:
            write(tmp, 100, ATOMS, self.ALL)
            r = run("check", tmp)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertIn("contacts by geometry 4, found by the pair 4, missed 0", r.stdout)

    def test_missed_contact_reported(self):
        with tempfile.TemporaryDirectory() as tmp:
            write(tmp, 100, ATOMS, self.ALL[:3])
            r = run("check", tmp)
            self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
            self.assertIn("missed 1", r.stdout)
            self.assertIn("MISSED", r.stdout)

    def test_bead_numbers(self):
        with tempfile.TemporaryDirectory() as tmp:
            write(tmp, 100, ATOMS, self.ALL)
            write(tmp, 200, ATOMS[:3], [])  # a later step: beads reads the first
            r = run("beads", tmp, "--dc", "1e-3")
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            v = r.stdout.splitlines()[1].split()[2:]
            beads, slab, clsph, clumps, bb, nothing, cc = (float(x) for x in v[:7])
            self.assertEqual(beads, 4)
            # bead 3: sphere 1; bead 4: spheres 1 and 2 (one clump) and bead 5; bead 6: nothing
            self.assertAlmostEqual(clsph, 3 / 4)
            self.assertAlmostEqual(clumps, 2 / 4)
            self.assertAlmostEqual(bb, 2 / 4)
            self.assertAlmostEqual(nothing, 1 / 4)
            self.assertEqual(cc, 0)  # one clump: no clump-clump contact
            # --flow: the dumps after the first (step 200: the clump and bead 3 only)
            r = run("beads", tmp, "--dc", "1e-3", "--flow")
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            v = r.stdout.splitlines()[1].split()
            self.assertEqual(v[1], "200-200")
            self.assertEqual(float(v[2]), 1)  # one bead
            self.assertAlmostEqual(float(v[4]), 1.0)  # bead 3 on sphere 1

    def test_truncated_dump_refused(self):
        with tempfile.TemporaryDirectory() as tmp:
            write(tmp, 100, ATOMS, self.ALL, truncate=True)
            r = run("check", tmp)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("truncated", r.stderr)


class SiloDiagnostic(unittest.TestCase):
    """in.silo_both -var diag 1 in Granary (a short fill and 25 steps of
    discharge): the dumps are written and the pair misses no contact."""

    def test_silo_both_diag(self):
        granary = os.environ.get("GRANARY_BINARY", os.path.join(ROOT, "build", "granary"))
        if not os.path.exists(granary):
            self.skipTest(f"no granary binary at {granary} (set GRANARY_BINARY)")
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_silo_stl.py"), "--W", "15", "--D", "6",
                            "--H", "30", "--slit", "4", "--out", tmp], check=True, capture_output=True)
            r = subprocess.run([granary, "-in", os.path.join(ROOT, "examples", "silo_liggghts", "in.silo_both"),
                                "-var", "potdir", os.path.join(ROOT, "potentials"), "-var", "s", "4",
                                "-var", "settle", "0.02", "-var", "tmax", "0.0025", "-var", "diag", "1",
                                "-var", "ndiag", "125", "-log", "none", "-echo", "none"],
                               cwd=tmp, capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stdout[-2000:] + r.stderr[-2000:])
            self.assertTrue(os.path.exists(os.path.join(tmp, "diag_atoms.2125.txt")))
            c = run("check", tmp)
            self.assertEqual(c.returncode, 0, c.stdout + c.stderr)
            self.assertIn("no contact missed", c.stdout)


if __name__ == "__main__":
    unittest.main(verbosity=2)
