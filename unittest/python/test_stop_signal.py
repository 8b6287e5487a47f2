#!/usr/bin/python3
"""Cluster time limits: SIGTERM / SIGUSR1 stop a run cleanly (doc/clusters.md).

granary runs a small pour as a child process (1 rank directly, 2 ranks under
mpirun); once it is stepping it gets a signal. It must finish the step, write
the restart file of its `restart` command, print the final step's thermo line,
say how to continue and exit with status 75; the run continued from that
restart must end in the same state as an uninterrupted run (bit for bit). A
second signal ends the program at once. Every file is written whole: no
temporary file is left behind.
"""
import glob
import os
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
STOP_STATUS = 75
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")

PHYSICS = """
variable every index 1
neighbor 0.0005 bin
neigh_modify delay 0 every ${every}
fix m1 all property/global youngsModulus peratomtype 5.e6
fix m2 all property/global poissonsRatio peratomtype 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.9
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 0.00001
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix xw1 all wall/gran model hertz tangential history primitive type 1 xplane -0.008
fix xw2 all wall/gran model hertz tangential history primitive type 1 xplane 0.008
fix yw1 all wall/gran model hertz tangential history primitive type 1 yplane -0.008
fix yw2 all wall/gran model hertz tangential history primitive type 1 yplane 0.008
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
fix integr all nve/sphere
thermo_style custom step atoms ke
thermo 100
thermo_modify lost ignore norm no
restart 200 run.restart.*
dump d all custom/vtk 500 frames/p_*.vtp id vx
"""

# the pour from scratch, run up to step ${end}
FRESH = """atom_style granular
atom_modify map array
boundary m m m
units si
processors * * 1
region domain block -0.008 0.008 -0.008 0.008 0.0 0.03 units box
create_box 1 domain
""" + PHYSICS + """
lattice bcc 0.0025
region fill block -0.0068 0.0068 -0.0068 0.0068 0.0021 0.0251 units box
create_atoms 1 region fill
set group all diameter 0.002 density 2500
velocity all set 0.3 -0.2 -0.5 units box
run ${end} upto
write_dump all custom final.txt id x y z vx vy vz omegax omegay omegaz modify sort id format float %.17g
"""

# the continuation: read the restart, define the physics again, run to ${end}
CONTINUE = """atom_style granular
atom_modify map array
read_restart ${file}
""" + PHYSICS + """
run ${end} upto
write_dump all custom final.txt id x y z vx vy vz omegax omegay omegaz modify sort id format float %.17g
"""

FOREVER = 10_000_000  # steps: the run is stopped long before


def children(pid):
    """Process ids of the direct children of `pid`."""
    out = []
    for task in glob.glob(f"/proc/{pid}/task/*/children"):
        with open(task) as f:
            out += [int(w) for w in f.read().split()]
    return out


def command(nprocs, script, variables):
    cmd = [GRANARY, "-in", script]
    for k, v in variables.items():
        cmd += ["-var", k, str(v)]
    if nprocs > 1:
        cmd = [MPIRUN, "-np", str(nprocs), "--oversubscribe"] + cmd
    return cmd


@unittest.skipUnless(os.path.exists(GRANARY), f"granary not built ({GRANARY})")
class StopSignal(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="granary_signal_")
        os.mkdir(os.path.join(self.dir, "frames"))
        for name, text in (("in.fresh", FRESH), ("in.continue", CONTINUE)):
            with open(os.path.join(self.dir, name), "w") as f:
                f.write(text)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def start(self, nprocs, sub="stopped", variables=None):
        work = os.path.join(self.dir, sub)
        os.makedirs(os.path.join(work, "frames"))
        variables = dict(variables or {}, end=FOREVER)
        proc = subprocess.Popen(command(nprocs, "../in.fresh", variables), cwd=work, env=ENV,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        # stepping has begun, and particles touch the floor and each other,
        # once the second periodic restart file is there
        deadline = time.time() + 120
        while not os.path.exists(os.path.join(work, "run.restart.400")):
            if proc.poll() is not None or time.time() > deadline:
                proc.kill()
                self.fail("granary did not start stepping:\n" + proc.communicate()[0])
            time.sleep(0.02)
        return work, proc

    def finish(self, proc):
        try:
            out, _ = proc.communicate(timeout=120)
        except subprocess.TimeoutExpired:
            proc.kill()
            self.fail("granary did not stop after the signal:\n" + proc.communicate()[0])
        return proc.returncode, out

    def run_to(self, work, script, variables, nprocs):
        r = subprocess.run(command(nprocs, script, variables), cwd=work, env=ENV, capture_output=True,
                           text=True, timeout=600)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        with open(os.path.join(work, "final.txt")) as f:
            text = f.read()
        # the particle rows (the shrink-wrapped box is reset at each neighbour
        # list build, which a continued run does at its start)
        return text[text.index("ITEM: ATOMS"):]

    def check_stop(self, work, rc, out, signame):
        self.assertEqual(rc, STOP_STATUS, out)
        m = re.search(r"Run stopped by " + signame + r" at step (\d+) \(the run was to end at step (\d+)\)", out)
        self.assertIsNotNone(m, out)
        step = int(m.group(1))
        self.assertEqual(int(m.group(2)), FOREVER)
        restart = f"run.restart.{step}"
        self.assertIn(f"read_restart {restart}", out)
        self.assertTrue(os.path.isfile(os.path.join(work, restart)), out)
        # the log holds the thermo line of the final step (flushed before the exit)
        with open(os.path.join(work, "log.granary")) as f:
            log = f.read()
        self.assertRegex(log, r"(?m)^\s*" + str(step) + r"\s+\d+\s+\S+\s*$")
        self.assertIn("Run stopped by " + signame, log)
        # no temporary file of an atomic write is left, and the .pvd lists complete frames only
        leftovers = [p for p in glob.glob(os.path.join(work, "**", ".*"), recursive=True) if ".tmp-" in p]
        self.assertEqual(leftovers, [])
        with open(os.path.join(work, "frames", "p_.pvd")) as f:
            pvd = f.read()
        self.assertTrue(pvd.rstrip().endswith("</VTKFile>"), pvd)
        return step, restart

    def continue_and_compare(self, work, step, restart, nprocs):
        end = step + 300
        continued = self.run_to(work, "../in.continue", {"file": restart, "end": end}, nprocs)
        ref_dir = os.path.join(self.dir, "reference")
        os.makedirs(os.path.join(ref_dir, "frames"), exist_ok=True)
        reference = self.run_to(ref_dir, "../in.fresh", {"end": end}, nprocs)
        self.assertGreater(len(reference.splitlines()), 200)
        if nprocs == 1:
            self.assertEqual(continued, reference)  # bit for bit (%.17g)
            return
        # on several ranks a continued run rebuilds its lists at the stop step,
        # so contact forces are summed in another order: round-off only
        a = [[float(w) for w in line.split()] for line in continued.splitlines()[1:]]
        b = [[float(w) for w in line.split()] for line in reference.splitlines()[1:]]
        self.assertEqual([r[0] for r in a], [r[0] for r in b])  # the same particles
        worst = [max(abs(ra[c] - rb[c]) for ra, rb in zip(a, b)) for c in range(1, 10)]
        print("largest differences, x v omega:", worst)
        self.assertLess(max(worst[0:3]), 1e-12)  # m
        self.assertLess(max(worst[3:6]), 1e-9)  # m/s
        self.assertLess(max(worst[6:9]), 1e-6)  # rad/s

    def test_sigterm_one_rank(self):
        work, proc = self.start(1)
        proc.send_signal(signal.SIGTERM)
        rc, out = self.finish(proc)
        step, restart = self.check_stop(work, rc, out, "SIGTERM")
        self.continue_and_compare(work, step, restart, 1)

    @unittest.skipUnless(MPIRUN, "mpirun not found")
    def test_sigterm_to_one_of_two_ranks(self):
        # a batch system may reach the ranks at different times: only one gets
        # it here, and both must stop together at the same step
        work, proc = self.start(2)
        ranks = children(proc.pid)
        self.assertEqual(len(ranks), 2, ranks)
        os.kill(ranks[-1], signal.SIGTERM)
        rc, out = self.finish(proc)
        step, restart = self.check_stop(work, rc, out, "SIGTERM")
        self.continue_and_compare(work, step, restart, 2)

    @unittest.skipUnless(MPIRUN, "mpirun not found")
    def test_sigterm_to_one_of_two_ranks_between_list_checks(self):
        # the ranks agree on the signal with the reduction of the neighbour
        # list decision; with the lists checked every 7th step there is none
        # at the other steps, and they must agree all the same
        work, proc = self.start(2, variables={"every": 7})
        ranks = children(proc.pid)
        self.assertEqual(len(ranks), 2, ranks)
        os.kill(ranks[0], signal.SIGTERM)
        rc, out = self.finish(proc)
        self.check_stop(work, rc, out, "SIGTERM")

    @unittest.skipUnless(MPIRUN, "mpirun not found")
    def test_sigusr1_through_mpirun(self):
        # mpirun forwards SIGUSR1 to every rank
        work, proc = self.start(2)
        proc.send_signal(signal.SIGUSR1)
        rc, out = self.finish(proc)
        self.check_stop(work, rc, out, "SIGUSR1")

    def test_second_signal_exits_at_once(self):
        work, proc = self.start(1)
        proc.send_signal(signal.SIGTERM)
        proc.send_signal(signal.SIGUSR1)
        rc, out = self.finish(proc)
        self.assertIn(rc, (-signal.SIGTERM, -signal.SIGUSR1), out)
        self.assertNotIn("Run stopped by", out)

    def test_no_restart_command(self):
        # without a `restart` command the stop says so and writes nothing
        with open(os.path.join(self.dir, "in.fresh")) as f:
            text = f.read()
        with open(os.path.join(self.dir, "in.fresh"), "w") as f:
            # a dump writes the file that shows the run is stepping
            f.write(text.replace("restart 200 run.restart.*", "dump tick all custom 400 run.restart.* id"))
        work, proc = self.start(1)
        proc.send_signal(signal.SIGTERM)
        rc, out = self.finish(proc)
        self.assertEqual(rc, STOP_STATUS, out)
        self.assertIn("No restart file was written: the script has no restart command", out)

    def test_signal_between_runs_stops_before_the_next_command(self):
        # a long loop without any run (here a million passes of `next`): the
        # signal is acted on before the next command, with the place named
        work = os.path.join(self.dir, "loop")
        os.makedirs(work)
        with open(os.path.join(work, "in.loop"), "w") as f:
            f.write("variable i loop 1000000000\nlabel top\nprint started file started.txt\n"
                    "next i\njump SELF top\n")
        proc = subprocess.Popen([GRANARY, "-in", "in.loop", "-log", "log", "-echo", "none"], cwd=work, env=ENV,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        deadline = time.time() + 60
        while not os.path.exists(os.path.join(work, "started.txt")):
            if proc.poll() is not None or time.time() > deadline:
                proc.kill()
                self.fail("the loop did not start:\n" + proc.communicate()[0])
            time.sleep(0.02)
        t0 = time.time()
        proc.send_signal(signal.SIGTERM)
        rc, out = self.finish(proc)
        self.assertLess(time.time() - t0, 10)
        self.assertEqual(rc, STOP_STATUS, out)
        self.assertRegex(out, r"Stopped by SIGTERM before the command at in\.loop:[345] \(no run was in progress")
        with open(os.path.join(work, "log")) as f:
            self.assertIn("Stopped by SIGTERM before the command", f.read())


if __name__ == "__main__":
    unittest.main()
