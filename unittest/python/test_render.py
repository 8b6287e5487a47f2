#!/usr/bin/python3
"""tools/render.py: ParaView pictures of a silo run, checked pixel by pixel.

granary writes a small scene between the walls of a silo made by
tools/make_silo_stl.py (6 x 1.5 x 8 dc, slit 2 dc): four clumps of
potentials/cylinder_ellipse_10.clump in known orientations and four free spheres
in one layer at y = 0, one of them moving, with the dumps of
examples/silo_clogging/in.silo (custom/vtk, bodies/vtk, mesh/vtk with their .pvd
collections every 5 steps, and the clog_*.vtp files of write_dump). pvbatch
renders it with tools/render.py and the PNG is read back with the world-to-pixel
mapping of its JSON: every sphere and clump must show in its colour at its
projected centre, with its projected size along its axes (so the cylinders'
orientation and elliptical cross-section are checked), the walls' outline at
the side walls and the floor with the slit open, no particle colour outside
the silo's outline, and the frame chosen by --time. A picture is blank when it
has no sphere- and no clump-coloured pixel: the negative control renders a
particles file with no points and no bodies and must be found blank. Errors
(missing folder, collection without frames, missing or damaged file, missing
array) must give a message and exit status 1. With GRANARY_KEEP_RENDER=DIR the
scene and the pictures are copied to DIR at the end.

Without pvbatch able to import paraview.simple, or without any way to render
(no X display, no xvfb-run, no headless OpenGL), the module exits with status
77, which ctest reports as skipped. Debian's ParaView renders through X only;
the renders run under xvfb-run with -noreset (see doc/paraview.md).
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import matplotlib.image as mpimg

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
RENDER = os.path.join(ROOT, "tools", "render.py")
SKIP = 77
XVFB = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24 -noreset"]

DC = 3.2e-3
W, D, H, SLIT = 6.0, 1.5, 8.0, 2.0  # silo in dc
MM = 1e-3
# clumps: name, centre (x, z) in mm at y = 0, quaternion, expected projected extents
# (mm) along two picture directions (unit vectors in x, z): (direction, extent)
SQ = 0.7071067811865476
CLUMPS = [
    ("A", (-5.5, 3.0), (1, 0, 0, 0), [((1, 0), 3.1), ((0, 1), 2.2)]),  # axis x, minor axis z
    ("B", (5.5, 3.0), (SQ, 0, SQ, 0), [((1, 0), 2.2), ((0, 1), 3.1)]),  # 90 deg about y: axis -z
    ("C", (0.0, 9.0), (SQ, SQ, 0, 0), [((1, 0), 3.1), ((0, 1), 3.2)]),  # 90 deg about x: major axis z
    ("D", (-5.0, 16.0), (0.9238795325112867, 0, 0.3826834323650898, 0),  # 45 deg about y
     [((SQ, -SQ), 3.1), ((SQ, SQ), 2.2)]),
]
# free spheres (diameter 1 mm): centre (x, z) in mm at the end; S4 moves at 4 m/s along x
SPHERES = [("S1", (0.0, 1.5)), ("S2", (-7.0, 9.0)), ("S3", (7.0, 9.0)), ("S4", (4.0, 16.0))]
SPHERE_D = 1.0
V4, DT, STEPS = 4.0, 1e-4, 10


def scene_input(potdir):
    lines = [
        "units si", "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
        "communicate single vel yes",
        "region domain block %g %g %g %g %g %g units box" % (-(W / 2 + 1) * DC, (W / 2 + 1) * DC,
                                                             -(D / 2 + 1) * DC, (D / 2 + 1) * DC, -2 * DC,
                                                             (H + 1) * DC),
        "create_box 2 domain",
        "neighbor 0.0005 bin", "neigh_modify delay 0",
        "fix m1 all property/global youngsModulus peratomtype 1e6 1e6",
        "fix m2 all property/global poissonsRatio peratomtype 0.45 0.45",
        "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5",
        "fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5",
        "pair_style gran model hertz tangential history", "pair_coeff * *",
        "timestep %g" % DT,
        "fix walls all mesh/surface file silo_walls.stl type 1",
        "fix wall all wall/gran model hertz tangential history mesh n_meshes 1 meshes walls",
        "fix cyl all particletemplate/multisphere 15485867 atom_type 1 density constant 1190 nspheres 10 "
        "ntry 100000 spheres file %s/cylinder_ellipse_10.clump scale 1.0 type 1" % potdir,
        "fix ms all multisphere", "fix integr all nve/sphere",
    ]
    for _, (x, z), q, _ in CLUMPS:
        lines.append("create_clump cyl %g 0 %g quat %.16g %.16g %.16g %.16g" % (x * MM, z * MM, *q))
    for name, (x, z) in SPHERES:
        x0 = x - V4 * DT * STEPS / MM if name == "S4" else x
        lines.append("create_atoms 2 single %g 0 %g" % (x0 * MM, z * MM))
    lines += [
        "set type 2 diameter %g density 2500" % (SPHERE_D * MM),
        "region mover sphere %g 0 %g 0.0003 units box" % (0.0, SPHERES[3][1][1] * MM),
        "set region mover vx %g" % V4,
        "dump dpart all custom/vtk 5 particles_*.vtp id type x y z vx vy vz radius",
        "dump dbody all bodies/vtk 5 bodies_*.vtp",
        "dump dmesh all mesh/vtk 5 mesh_*.vtp walls",
        "run %d" % STEPS,
        # the final state as examples/silo_clogging/in.silo writes it
        "write_dump all custom/vtk clog_particles.vtp id type x y z vx vy vz radius",
        "write_dump all bodies/vtk clog_bodies.vtp",
        "write_dump all mesh/vtk clog_mesh.vtp walls",
        # negative control: a particles file with no points, the walls, no bodies
        "region nowhere block 0 1e-4 0 1e-4 %g %g units box" % (-1.9 * DC, -1.8 * DC),
        "group nobody region nowhere",
        "write_dump nobody custom/vtk empty/clog_particles.vtp id type x y z radius",
        "write_dump all mesh/vtk empty/clog_mesh.vtp walls",
        # a particles file without the radius array
        "write_dump all custom/vtk noradius/clog_particles.vtp id type x y z",
    ]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- reading the picture


class Picture:
    """A PNG of render.py with its JSON: pixel classes by colour and the world-to-pixel mapping."""

    def __init__(self, png):
        with open(png + ".json") as fh:
            self.meta = json.load(fh)
        img = mpimg.imread(png)
        self.rgb = np.rint(img[..., :3] * 255).astype(int)
        self.h, self.w = self.rgb.shape[:2]
        assert (self.w, self.h) == (self.meta["width"], self.meta["height"])
        c = self.meta["colours"]
        v = self.rgb.max(axis=2)
        chroma = self.rgb / np.maximum(v, 1)[..., None]

        def lit(colour):
            # lit surfaces: the colour times a factor in [0.3, 1]: same chromaticity
            c = np.array(colour, float) / max(colour)
            return (v >= 0.25 * max(colour)) & (np.abs(chroma - c).max(axis=2) < 0.1)

        def flat(colour):
            return np.abs(self.rgb - np.array(colour)).max(axis=2) <= 3

        self.sphere = lit(c["spheres"])
        self.clump = lit(c["clumps"])
        self.wall = flat(c["walls"])
        self.edge = flat(c["wall_edges"])
        self.background = flat(c["background"])
        self.particle = self.sphere | self.clump

    def blank(self):
        """No sphere- or clump-coloured pixel: nothing of the particles was drawn."""
        return not self.particle.any()

    def pixel(self, x, z):
        """(col, row) of world (x, z) in metres, as floats (pixel centres at integers)."""
        m = self.meta
        col = (x - m["centre_x"]) / m["metres_per_pixel"] + self.w / 2 - 0.5
        row = self.h / 2 - 0.5 - (z - m["centre_z"]) / m["metres_per_pixel"]
        return col, row

    def world(self, col, row):
        m = self.meta
        return (m["centre_x"] + (col + 0.5 - self.w / 2) * m["metres_per_pixel"],
                m["centre_z"] - (row + 0.5 - self.h / 2) * m["metres_per_pixel"])

    def at(self, mask, x, z):
        col, row = self.pixel(x, z)
        return bool(mask[int(round(row)), int(round(col))])

    def run_length(self, mask, x, z, direction):
        """Length (m) of the run of mask pixels through world (x, z) along the picture direction (dx, dz)."""
        col0, row0 = self.pixel(x, z)
        d = np.array(direction, float) / np.linalg.norm(direction)
        total = 0.0
        for sign in (1, -1):
            s = 0.0
            while True:
                c = col0 + sign * (s + 0.25) * d[0]
                r = row0 - sign * (s + 0.25) * d[1]
                ci, ri = int(round(c)), int(round(r))
                if not (0 <= ci < self.w and 0 <= ri < self.h) or not mask[ri, ci]:
                    break
                s += 0.25
            total += s
        return total * self.meta["metres_per_pixel"]


# ---------------------------------------------------------------- running the tools


def pvbatch_cmd():
    return shutil.which("pvbatch")


def render_launcher():
    """How to run pvbatch so that it can render: (prefix, None) or (None, reason)."""
    probe = os.path.join(tempfile.mkdtemp(prefix="granary_pvprobe_"), "probe.py")
    with open(probe, "w") as fh:
        fh.write("from paraview.modules import vtkRemotingViews as rv\n"
                 "info = rv.vtkPVRenderingCapabilitiesInformation\n"
                 "caps = info.GetLocalCapabilities()\n"
                 "print('CAN_RENDER' if caps & (info.ONSCREEN_RENDERING | info.HEADLESS_RENDERING) else 'NO')\n")
    try:
        launchers = ([XVFB] if shutil.which("xvfb-run") else []) + [[]]
        for prefix in launchers:
            r = subprocess.run(prefix + [pvbatch_cmd(), probe], capture_output=True, text=True, timeout=120)
            if "CAN_RENDER" in r.stdout:
                return prefix, None
        return None, "ParaView cannot render here (no X display, no xvfb-run, no EGL/OSMesa)"
    finally:
        shutil.rmtree(os.path.dirname(probe), ignore_errors=True)


def paraview_available():
    exe = pvbatch_cmd()
    if exe is None:
        return "no pvbatch on PATH (Debian: paraview, python3-paraview)"
    tmp = tempfile.mkdtemp(prefix="granary_pvprobe_")
    try:
        probe = os.path.join(tmp, "probe.py")
        with open(probe, "w") as fh:
            fh.write("import paraview.simple\n")
        r = subprocess.run([exe, probe], capture_output=True, text=True, timeout=120)
        if r.returncode != 0:
            return "pvbatch cannot import paraview.simple: %s" % " ".join(r.stderr.strip().splitlines()[-1:])
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return None


LAUNCHER = []


def render(run_dir, *args):
    return subprocess.run(LAUNCHER + [pvbatch_cmd(), RENDER, run_dir, *args], capture_output=True, text=True,
                          timeout=300)


def render_no_display(run_dir, *args):
    """render.py for the error paths, which fail before anything is rendered."""
    return subprocess.run([pvbatch_cmd(), RENDER, run_dir, *args], capture_output=True, text=True, timeout=300)


class RenderSilo(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        granary = os.environ.get("GRANARY_BINARY") or os.path.join(ROOT, "build", "granary")
        if not os.path.isfile(granary):
            raise RuntimeError("granary not found at %s (set GRANARY_BINARY)" % granary)
        cls.tmp = tempfile.TemporaryDirectory(prefix="granary_render_")
        cls.dir = cls.tmp.name
        for sub in ("empty", "noradius"):
            os.makedirs(os.path.join(cls.dir, sub))
        r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_silo_stl.py"), "--W", str(W), "--D",
                            str(D), "--H", str(H), "--slit", str(SLIT), "--dc", str(DC), "--out", cls.dir],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        with open(os.path.join(cls.dir, "scene.in"), "w") as fh:
            fh.write(scene_input(os.path.join(ROOT, "potentials")))
        env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        r = subprocess.run([granary, "-in", "scene.in", "-log", "none"], cwd=cls.dir, capture_output=True,
                           text=True, env=env, stdin=subprocess.DEVNULL, timeout=300)
        assert r.returncode == 0, r.stdout + r.stderr

    @classmethod
    def tearDownClass(cls):
        keep = os.environ.get("GRANARY_KEEP_RENDER")
        if keep:
            shutil.rmtree(keep, ignore_errors=True)
            shutil.copytree(cls.dir, keep)
        cls.tmp.cleanup()

    def png(self, name):
        return os.path.join(self.dir, name)

    def assert_rendered(self, r, png):
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertTrue(os.path.isfile(png), r.stdout + r.stderr)
        self.assertTrue(os.path.isfile(png + ".json"))
        return Picture(png)

    def check_outline(self, pic):
        """Particle colours only inside the silo; the side walls and the floor drawn, the slit open."""
        mpp = pic.meta["metres_per_pixel"]
        tol = 1.5 * mpp
        rows, cols = np.nonzero(pic.particle)
        xs, zs = pic.world(cols, rows)
        self.assertTrue(np.all(np.abs(xs) <= W / 2 * DC + tol), "particle colour beyond the side walls")
        self.assertTrue(np.all(zs >= -tol), "particle colour below the floor")
        self.assertTrue(np.all(zs <= H * DC + tol), "particle colour above the silo")
        # side walls: edge lines at x = +-W/2 from the floor up (where no particle hides them)
        for x in (-W / 2 * DC, W / 2 * DC):
            for z in (6 * DC, 6.5 * DC):
                col, row = pic.pixel(x, z)
                near = pic.edge[int(round(row)), int(round(col)) - 2:int(round(col)) + 3]
                self.assertTrue(near.any(), "no wall edge at x = %g, z = %g" % (x, z))
        # floor: edge pixels along z = 0 beside the slit, none across the open slit
        def floor_edge(x):
            col, row = pic.pixel(x, 0.0)
            return pic.edge[int(round(row)) - 2:int(round(row)) + 3, int(round(col))].any()
        self.assertTrue(floor_edge(-2.0 * DC) and floor_edge(2.0 * DC) and floor_edge(-1.2 * DC))
        for x in np.linspace(-0.8, 0.8, 9) * DC:
            self.assertFalse(floor_edge(x), "a wall edge across the slit at x = %g" % x)
        # inside: the back wall; outside: the white background
        self.assertTrue(pic.at(pic.wall, 0.0, 5.5 * DC))
        self.assertTrue(pic.at(pic.background, -(W / 2 + 1) * DC, 3 * DC))
        self.assertTrue(pic.at(pic.background, 0.0, -1.0 * DC))

    def test_clog_state(self):
        os.makedirs(self.png("pictures"), exist_ok=True)
        png = self.png(os.path.join("pictures", "clog.png"))
        r = render(self.dir, "--out", png, "--size", "800", "600")
        pic = self.assert_rendered(r, png)
        m = pic.meta
        self.assertEqual(m["state"], "clog state")
        self.assertEqual(m["counts"]["clumps"], len(CLUMPS))
        self.assertEqual(m["counts"]["spheres"], len(SPHERES))
        self.assertTrue(m["files"]["particles"].endswith("clog_particles.vtp"))
        # named relative to the picture's folder (a kept picture names no machine's paths)
        for key in ("particles", "bodies", "mesh"):
            self.assertFalse(os.path.isabs(m["files"][key]), m["files"][key])
            self.assertEqual(os.path.realpath(os.path.join(os.path.dirname(png), m["files"][key])),
                             os.path.realpath(os.path.join(self.dir, "clog_%s.vtp" % key)))
        self.assertAlmostEqual(m["time"], DT * STEPS, delta=1e-12)
        # slit view: x from -6 to 6 dc, z from -2 to 7 dc, in a 4:3 picture
        self.assertAlmostEqual(m["metres_per_pixel"], 12 * DC / 800, delta=1e-12)
        self.assertAlmostEqual(m["centre_x"], 0.0, delta=1e-12)
        self.assertAlmostEqual(m["centre_z"], 2.5 * DC, delta=1e-12)
        self.assertFalse(pic.blank())
        mpp = m["metres_per_pixel"]
        for name, (x, z), _, extents in CLUMPS:
            with self.subTest(clump=name):
                self.assertTrue(pic.at(pic.clump, x * MM, z * MM), "clump colour missing at %s" % name)
                for direction, extent in extents:
                    got = pic.run_length(pic.clump, x * MM, z * MM, direction)
                    self.assertAlmostEqual(got, extent * MM, delta=2.5 * mpp,
                                           msg="clump %s along %s: %.3f mm, expected %.3f mm" %
                                           (name, direction, got / MM, extent))
        for name, (x, z) in SPHERES:
            with self.subTest(sphere=name):
                self.assertTrue(pic.at(pic.sphere, x * MM, z * MM), "sphere colour missing at %s" % name)
                for direction in ((1, 0), (0, 1)):
                    got = pic.run_length(pic.sphere, x * MM, z * MM, direction)
                    self.assertAlmostEqual(got, SPHERE_D * MM, delta=2.5 * mpp)
        # the picture holds exactly these bodies: clump and sphere pixels add up to their silhouettes
        ell = np.pi / 4  # area of an ellipse / its bounding rectangle
        clump_area = 2 * 3.1 * 2.2 + 3.1 * 3.2 + 3.1 * 2.2 + 2.2 * 2.2 * ell  # A, B, C side-on; D about
        self.assertAlmostEqual(pic.clump.sum() * mpp**2 / MM**2, clump_area, delta=0.15 * clump_area)
        sphere_area = len(SPHERES) * np.pi / 4 * SPHERE_D**2
        self.assertAlmostEqual(pic.sphere.sum() * mpp**2 / MM**2, sphere_area, delta=0.15 * sphere_area)
        self.check_outline(pic)

    def test_time_and_silo_view(self):
        png = self.png("t.png")
        r = render(self.dir, "--out", png, "--size", "400", "600", "--view", "silo", "--time", "0.0007")
        pic = self.assert_rendered(r, png)
        m = pic.meta
        # the frame at or before t = 0.0007: step 5, t = 5e-4; S4 half-way
        self.assertAlmostEqual(m["time"], 5 * DT, delta=1e-12)
        self.assertEqual(m["step"], 5)
        for key, name in (("particles", "particles_5.vtp"), ("bodies", "bodies_5.vtp"), ("mesh", "mesh_5.vtp")):
            self.assertEqual(os.path.basename(m["files"][key]), name)
        z4 = SPHERES[3][1][1] * MM
        self.assertTrue(pic.at(pic.sphere, 2.0 * MM, z4))
        self.assertFalse(pic.at(pic.sphere, 4.0 * MM, z4))
        self.assertFalse(pic.at(pic.sphere, 0.0, z4))
        # the whole silo with a margin: its top shows, the back wall below it, white above
        self.assertTrue(pic.at(pic.wall, 0.0, (H - 0.2) * DC))
        self.assertTrue(pic.at(pic.background, 0.0, (H + 0.2) * DC))
        self.assertTrue(pic.at(pic.background, 0.0, -0.2 * DC))
        self.assertEqual(m["counts"]["spheres"], len(SPHERES))
        # --time last: the last frame of the collections (step 10), not the clog files
        png = self.png("last.png")
        r = render(self.dir, "--out", png, "--size", "400", "300", "--time", "last")
        pic = self.assert_rendered(r, png)
        self.assertEqual(pic.meta["step"], STEPS)
        self.assertEqual(os.path.basename(pic.meta["files"]["particles"]), "particles_10.vtp")
        self.assertTrue(pic.at(pic.sphere, 4.0 * MM, z4))

    def test_empty_dump_is_blank(self):
        """Negative control: no points and no bodies give a picture the check calls blank."""
        run = os.path.join(self.dir, "empty")
        png = os.path.join(run, "empty.png")
        r = render(run, "--out", png, "--size", "800", "600")
        pic = self.assert_rendered(r, png)
        self.assertIn("no clog_bodies.vtp", r.stdout)
        self.assertEqual(pic.meta["counts"], {"particles": 0, "spheres": 0, "clumps": 0})
        self.assertTrue(pic.blank())
        self.assertTrue(pic.edge.any() and pic.wall.any())  # the walls are there

    def test_paraview_reads_the_collection(self):
        """ParaView's own .pvd reader: the frames with their simulated times and every particle."""
        script = os.path.join(self.dir, "pvd.py")
        with open(script, "w") as fh:
            fh.write("from paraview.simple import PVDReader\n"
                     "r = PVDReader(FileName=%r)\n"
                     "r.UpdatePipeline(r.TimestepValues[-1])\n"
                     "print('TIMES', *r.TimestepValues)\n"
                     "print('POINTS', r.GetDataInformation().GetNumberOfPoints())\n"
                     % os.path.join(self.dir, "particles_.pvd"))
        res = subprocess.run([pvbatch_cmd(), script], capture_output=True, text=True, timeout=120)
        self.assertEqual(res.returncode, 0, res.stderr)
        times = [float(w) for w in res.stdout.split("TIMES", 1)[1].split("\n")[0].split()]
        np.testing.assert_allclose(times, [0, 5 * DT, 10 * DT], atol=1e-12)
        npts = int(res.stdout.split("POINTS", 1)[1].split()[0])
        self.assertEqual(npts, len(SPHERES) + 10 * len(CLUMPS))

    def test_errors(self):
        r = render_no_display(os.path.join(self.dir, "no_such_run"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("does not exist", r.stderr)
        bad = os.path.join(self.dir, "bad")
        os.makedirs(bad, exist_ok=True)
        r = render_no_display(bad)
        self.assertEqual(r.returncode, 1)
        self.assertIn("neither clog_particles.vtp", r.stderr)
        with open(os.path.join(bad, "particles_.pvd"), "w") as fh:
            fh.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n'
                     '</Collection>\n</VTKFile>\n')
        r = render_no_display(bad)
        self.assertEqual(r.returncode, 1)
        self.assertIn("lists no frames", r.stderr)
        with open(os.path.join(bad, "particles_.pvd"), "w") as fh:
            fh.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n'
                     '<DataSet timestep="0.5" group="" part="0" file="particles_9.vtp"/>\n'
                     '</Collection>\n</VTKFile>\n')
        r = render_no_display(bad)
        self.assertEqual(r.returncode, 1)
        self.assertIn("particles_9.vtp does not exist", r.stderr)
        r = render_no_display(bad, "--time", "0.1")
        self.assertEqual(r.returncode, 1)
        self.assertIn("no frame at or before t = 0.1", r.stderr)
        r = render_no_display(os.path.join(self.dir, "noradius"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("no point array 'radius'", r.stderr)
        # a damaged file (cut short): the reader delivers fewer points than the file holds
        cut = os.path.join(self.dir, "cut")
        os.makedirs(cut, exist_ok=True)
        with open(os.path.join(self.dir, "clog_particles.vtp"), "rb") as fh:
            data = fh.read()
        with open(os.path.join(cut, "clog_particles.vtp"), "wb") as fh:
            fh.write(data[:len(data) // 2])
        r = render_no_display(cut)
        self.assertEqual(r.returncode, 1)
        self.assertIn("could not read the particles file", r.stderr)
        self.assertIn("holds %d points, 0 were read" % (len(SPHERES) + 10 * len(CLUMPS)), r.stderr)
        r = render_no_display(self.dir, "--view", "top")
        self.assertEqual(r.returncode, 2)
        r = render_no_display(self.dir, "--time", "soon")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--time", r.stderr)


if __name__ == "__main__":
    reason = paraview_available()
    if reason is None:
        LAUNCHER, reason = render_launcher()
    if reason is not None:
        print("SKIPPED: %s" % reason)
        sys.exit(SKIP)
    unittest.main()
