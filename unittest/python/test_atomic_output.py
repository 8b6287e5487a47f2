#!/usr/bin/python3
"""Kills never leave a partial file under a final name (core/atomic_file.h).

A pour writes large ASCII VTK frames (serial .vtp, and .pvtp with pieces on 2
ranks), their .pvd collections, one text dump file per frame and restart files
every few steps; granary is killed with SIGKILL at random moments, mostly while
it writes. Every file found under its final name afterwards must be complete
(VTK XML that ends its root element, a text dump with all its rows, a restart
that the next run reads), and every frame listed in a .pvd must exist.
"""
import glob
import os
import random
import re
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
GRANARY = os.environ.get("GRANARY_BINARY", os.path.join(ROOT, "build", "granary"))
MPIRUN = shutil.which("mpirun")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
KILLS = 8

SCRIPT = """atom_style granular
atom_modify map array
boundary m m m
units si
processors * * 1
region domain block -0.01 0.01 -0.01 0.01 0.0 0.04 units box
create_box 1 domain
neighbor 0.0005 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5.e6
fix m2 all property/global poissonsRatio peratomtype 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.9
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 0.00001
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
fix integr all nve/sphere
lattice bcc 0.0025
region fill block -0.0085 0.0085 -0.0085 0.0085 0.0051 0.0301 units box
create_atoms 1 region fill
set group all diameter 0.002 density 2500
thermo 1000
dump v all custom/vtk 2 out/p_*.${ext} id type x y z vx vy vz fx fy fz omegax omegay omegaz radius mass
dump_modify v binary no
dump t all custom 2 out/t_*.txt id x y z vx vy vz
restart 3 out/r.a out/r.b
run 1000000
"""


def complete_xml(path):
    with open(path, "rb") as f:
        data = f.read()
    return data.rstrip().endswith(b"</VTKFile>")


def complete_dump(path):
    with open(path) as f:
        lines = f.read().splitlines()
    if len(lines) < 9 or lines[2] != "ITEM: NUMBER OF ATOMS":
        return False
    return len(lines) == 9 + int(lines[3]) and len(lines[-1].split()) == 7


@unittest.skipUnless(os.path.exists(GRANARY), f"granary not built ({GRANARY})")
class KilledWriters(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="granary_atomic_")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def kill_and_check(self, nprocs, ext, seed):
        rng = random.Random(seed)
        killed_while_stepping = 0
        for k in range(KILLS):
            work = os.path.join(self.dir, f"{ext}{nprocs}_{k}")
            os.makedirs(os.path.join(work, "out"))
            with open(os.path.join(work, "in.pour"), "w") as f:
                f.write(SCRIPT)
            cmd = [GRANARY, "-in", "in.pour", "-var", "ext", ext, "-log", "none", "-screen", "none"]
            if nprocs > 1:
                cmd = [MPIRUN, "-np", str(nprocs), "--oversubscribe"] + cmd
            proc = subprocess.Popen(cmd, cwd=work, env=ENV, start_new_session=True)
            deadline = time.time() + 120
            while not glob.glob(os.path.join(work, "out", "t_*.txt")):
                self.assertIsNone(proc.poll(), "granary ended before writing")
                self.assertLess(time.time(), deadline)
                time.sleep(0.01)
            time.sleep(rng.uniform(0.05, 1.0))
            if proc.poll() is None:
                killed_while_stepping += 1
            os.killpg(proc.pid, signal.SIGKILL)  # every rank and mpirun at once
            proc.wait()

            out = os.path.join(work, "out")
            frames = sorted(glob.glob(os.path.join(out, f"p_*.{ext}")))
            self.assertTrue(frames)
            for path in frames:
                self.assertTrue(complete_xml(path), f"partial frame {path}")
            for path in glob.glob(os.path.join(out, "p_*_*.vtp")):  # pieces of .pvtp frames
                self.assertTrue(complete_xml(path), f"partial piece {path}")
            for path in glob.glob(os.path.join(out, "t_*.txt")):
                self.assertTrue(complete_dump(path), f"partial dump {path}")
            with open(os.path.join(out, "p_.pvd")) as f:
                pvd = f.read()
            self.assertTrue(pvd.rstrip().endswith("</VTKFile>"), pvd)
            for name in re.findall(r'file="([^"]+)"', pvd):
                self.assertTrue(os.path.exists(os.path.join(out, name)), name)
            # the restart files read back (checksums verified)
            for r in glob.glob(os.path.join(out, "r.[ab]")):
                with open(os.path.join(work, "in.read"), "w") as f:
                    f.write(f"atom_style granular\nread_restart {r}\n")
                res = subprocess.run([GRANARY, "-in", "in.read", "-log", "none"], cwd=work, env=ENV,
                                     capture_output=True, text=True, timeout=120)
                self.assertEqual(res.returncode, 0, res.stdout + res.stderr)
        self.assertGreater(killed_while_stepping, KILLS // 2)

    def test_serial_frames(self):
        self.kill_and_check(1, "vtp", 1)

    @unittest.skipUnless(MPIRUN, "mpirun not found")
    def test_parallel_frames(self):
        self.kill_and_check(2, "pvtp", 2)


if __name__ == "__main__":
    unittest.main()
