#!/usr/bin/python3
"""tools/portable_bundle.sh: the bundle runs Granary (and LIGGGHTS) on 1 and 2
ranks with its own libraries only.

Every process started through the bundle is traced by the dynamic loader
(LD_DEBUG=files, one file per process): once a process has loaded a library
of the bundle (a wrapper's shell, which loads the system's, execs the bundled
loader in the same process), it loads no other library."""
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
SCRIPT = os.path.join(ROOT, "tools", "portable_bundle.sh")

# a script both programs run: 147 spheres on a simple cubic lattice falling
# onto a floor, in a box of periodic x and y
DEMO = """atom_style granular
atom_modify map array
boundary p p f
newton off
communicate single vel yes
units si
region domain block 0 0.02 0 0.02 0 0.02 units box
create_box 1 domain
neighbor 0.0004 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5.e6
fix m2 all property/global poissonsRatio peratomtype 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 0.00001
lattice sc 0.0025
region fill block 0.001 0.019 0.001 0.019 0.001 0.008 units box
create_atoms 1 region fill
set type 1 diameter 0.002 density 2500
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
fix integr all nve/sphere
run 100
"""


def loaded_objects(trace_dir):
    """Per traced process: the files whose initialisers the loader called."""
    out = []
    for path in glob.glob(os.path.join(trace_dir, "ld.*")):
        with open(path, errors="replace") as f:
            out.append(re.findall(r"calling init: (\S+)", f.read()))
    return out


class PortableBundle(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.bundle = os.path.join(cls.tmp.name, "pb")
        r = subprocess.run(["bash", SCRIPT, "--out", cls.bundle, "--granary", os.environ["GRANARY_BINARY"]],
                           capture_output=True, text=True, cwd=ROOT)
        if r.returncode != 0:
            raise AssertionError(r.stdout + r.stderr)
        cls.made = r.stdout
        with open(os.path.join(cls.tmp.name, "in.demo"), "w") as f:
            f.write(DEMO)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def run_traced(self, cmd):
        trace = tempfile.mkdtemp(dir=self.tmp.name)
        env = dict(os.environ, LD_DEBUG="files", LD_DEBUG_OUTPUT=os.path.join(trace, "ld"))
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=self.tmp.name, env=env, timeout=300)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        lib = self.bundle + os.sep  # lib/, and the plugins of ompi/
        ours = 0
        for objects in loaded_objects(trace):
            first = next((k for k, o in enumerate(objects) if o.startswith(lib)), None)
            if first is None:
                continue  # a shell or tool of the system only
            ours += 1
            after = objects[first:]
            self.assertEqual([o for o in after if not o.startswith(lib)], [],
                             "a program of the bundle loaded a library from elsewhere")
            # the bundle's own C library and Open MPI (or the program) were loaded
            self.assertTrue(any(o.endswith("/libc.so.6") for o in after), after)
        return r.stdout, ours

    def test_granary_on_one_and_two_ranks(self):
        b = os.path.join(self.bundle, "bin")
        out, ours = self.run_traced([os.path.join(b, "granary"), "-in", "in.demo", "-log", "none"])
        self.assertIn("Loop time of", out)
        self.assertIn("on 1 procs for 100 steps with 147 atoms", out)
        self.assertEqual(ours, 1)
        out, ours = self.run_traced([os.path.join(b, "mpirun"), "--allow-run-as-root", "-np", "2",
                                     os.path.join(b, "granary"), "-in", "in.demo", "-log", "none"])
        self.assertIn("on 2 procs for 100 steps with 147 atoms", out)
        self.assertGreaterEqual(ours, 3)  # mpirun and the two ranks

    @unittest.skipUnless(shutil.which("liggghts"), "liggghts not on PATH")
    def test_liggghts_on_two_ranks(self):
        b = os.path.join(self.bundle, "bin")
        self.assertIn("liggghts", self.made)
        out, ours = self.run_traced([os.path.join(b, "mpirun"), "--allow-run-as-root", "-np", "2",
                                     os.path.join(b, "liggghts"), "-in", "in.demo", "-log", "none"])
        self.assertIn("on 2 procs for 100 steps with 147 atoms", out)
        self.assertGreaterEqual(ours, 3)

    def test_bad_options_are_refused(self):
        r = subprocess.run(["bash", SCRIPT, "--outdir", "x"], capture_output=True, text=True, cwd=ROOT)
        self.assertEqual(r.returncode, 2)
        self.assertIn("unknown option '--outdir'", r.stderr)
        # a folder that is not a bundle is not replaced
        r = subprocess.run(["bash", SCRIPT, "--out", self.tmp.name], capture_output=True, text=True, cwd=ROOT)
        self.assertEqual(r.returncode, 2)
        self.assertIn("is not a bundle", r.stderr)
        self.assertTrue(os.path.exists(os.path.join(self.tmp.name, "in.demo")))
        r = subprocess.run(["bash", SCRIPT, "--help"], capture_output=True, text=True, cwd=ROOT)
        self.assertEqual(r.returncode, 0)
        self.assertIn("--no-liggghts", r.stdout)


if __name__ == "__main__":
    if not (os.path.exists("/usr/bin/orterun") and shutil.which("ldd")):
        # ctest reports exit status 77 as skipped
        print("SKIPPED: the bundle needs Open MPI's /usr/bin/orterun and ldd")
        sys.exit(77)
    unittest.main()
