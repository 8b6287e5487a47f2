#!/usr/bin/python3
"""tools/make_silo_stl.py: geometry of the silo meshes (normals, slit, areas)."""
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

TOOLS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools")
sys.path.insert(0, TOOLS)
import make_silo_stl as m  # noqa: E402


class MakeSiloStl(unittest.TestCase):
    W, D, H, S, DC = 16.0, 4.0, 25.0, 2.8, 3.2e-3

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        r = subprocess.run([sys.executable, os.path.join(TOOLS, "make_silo_stl.py"), "--W", str(self.W), "--D",
                            str(self.D), "--H", str(self.H), "--slit", str(self.S), "--dc", str(self.DC), "--out",
                            self.tmp.name], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.wn, self.wt = m.read_stl(os.path.join(self.tmp.name, "silo_walls.stl"))
        self.sn, self.st = m.read_stl(os.path.join(self.tmp.name, "silo_shutter.stl"))

    def tearDown(self):
        self.tmp.cleanup()

    def test_counts_and_orientation(self):
        self.assertEqual(len(self.wt), 12)
        self.assertEqual(len(self.st), 2)
        for n, t in zip(np.vstack([self.wn, self.sn]), np.vstack([self.wt, self.st])):
            # written normal = right-hand normal of the vertex order, unit length
            c = np.cross(t[1] - t[0], t[2] - t[0])
            np.testing.assert_allclose(n, c / np.linalg.norm(c), atol=1e-8)
            # every normal points into the silo: towards its centre line x = y = 0 at mid height
            centroid = t.mean(axis=0)
            inward = np.array([0.0, 0.0, self.H * self.DC / 2]) - centroid
            if abs(n[2]) > 0.5:  # bottom: up
                self.assertGreater(n[2], 0.99)
            else:
                inward[2] = 0
                self.assertGreater(np.dot(n, inward), 0)

    def test_areas_and_slit(self):
        dc2 = self.DC**2
        area = lambda t: 0.5 * np.linalg.norm(np.cross(t[1] - t[0], t[2] - t[0]))  # noqa: E731
        total = sum(area(t) for t in self.wt) / dc2
        expect = 2 * self.D * self.H + 2 * self.W * self.H + (self.W - self.S) * self.D
        self.assertAlmostEqual(total, expect, places=5)
        self.assertAlmostEqual(sum(area(t) for t in self.st) / dc2, self.S * self.D, places=6)
        # bottom plates leave exactly the slit |x| < s/2 open across the full depth, the shutter covers it
        bottom = [t for t, n in zip(self.wt, self.wn) if n[2] > 0.99]
        self.assertEqual(len(bottom), 4)
        inner = sorted(min(abs(t[:, 0])) for t in bottom)
        self.assertAlmostEqual(inner[0] / self.DC, self.S / 2, places=6)
        self.assertTrue(all(np.allclose(t[:, 2], 0) for t in bottom))
        np.testing.assert_allclose(self.st[:, :, 0].min() / self.DC, -self.S / 2, atol=1e-7)
        np.testing.assert_allclose(self.st[:, :, 0].max() / self.DC, self.S / 2, atol=1e-7)
        np.testing.assert_allclose(np.ptp(self.st[:, :, 1]) / self.DC, self.D, atol=1e-7)
        # the walls span the whole box
        allv = self.wt.reshape(-1, 3) / self.DC
        np.testing.assert_allclose(allv.min(axis=0), [-self.W / 2, -self.D / 2, 0], atol=1e-7)
        np.testing.assert_allclose(allv.max(axis=0), [self.W / 2, self.D / 2, self.H], atol=1e-6)

    def test_bad_slit(self):
        r = subprocess.run([sys.executable, os.path.join(TOOLS, "make_silo_stl.py"), "--W", "4", "--slit", "5",
                            "--out", self.tmp.name], capture_output=True, text=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("slit", r.stderr)


if __name__ == "__main__":
    unittest.main()
