#!/usr/bin/env pvbatch
"""Render one state of a silo run folder with ParaView (a picture seen from the front).

Usage: pvbatch tools/render.py RUN_DIR [--out PNG] [--size W H] [--view slit|silo]
                              [--time T|last] [--dc 0.0032] [--sphere-type 2]
                              [--clump-size L A B]
Without a display (Debian's ParaView renders through X only, even with --force-offscreen-rendering):
       xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" pvbatch tools/render.py RUN_DIR ...
(-noreset: without it Xvfb resets whenever its last client disconnects, and
pvbatch, which connects more than once, fails now and then with "bad X server
connection")

Which state: without --time, the files RUN_DIR/clog_particles.vtp (or .pvtp,
written on several ranks), clog_bodies.vtp and clog_mesh.vtp when
clog_particles exists (the final state that examples/silo_clogging/in.silo
writes); otherwise, and always with --time, the frames of the collections
particles_.pvd, bodies_.pvd and mesh_.pvd: with --time last (the default
there) the last particle frame, with --time T the last frame at or before the
simulated time T (s); the clump and wall frames are the last ones at or before
the time of the particle frame. Only the particles are required; without a
bodies or mesh file no clumps or walls are drawn.

What is drawn, in flat fixed colours on a white background:
  * free spheres: the points of the particles dump of atom type --sphere-type
    (default 2) as spheres of their `radius` (the dump needs the fields type
    and radius), orange;
  * clumps: one cylinder per point of the bodies dump (bodies/vtk), blue: a
    cylinder of length L along the clump's long axis (the `long_axis` array,
    the body x axis) with an elliptical cross-section of axes A along the body
    y axis and B along the body z axis, placed by the `quaternion` array
    (--clump-size L A B, default 3.1e-3 3.2e-3 2.2e-3 m: the cylinders of
    potentials/cylinder_ellipse_*.clump); drawn with ParaView's Tensor Glyph
    filter from a cylinder source;
  * walls: the triangles of the mesh dump (mesh/vtk) in light grey with their
    back faces culled (the front wall, whose normal points into the silo,
    away from the camera, is not drawn, so the silo is seen through it), and
    as dark grey lines the boundary and feature edges (30 degrees) of the
    triangles seen edge-on (|normal y| < 0.5: side walls, floor plates; the
    slit is the gap in the floor line).
Spheres and clumps are lit by a single white headlight: a pixel is the colour
times 0.3 + 0.7 cos(angle to the viewer), so its hue stays that of the colour.

The view: parallel projection looking along +y (x to the right, z up). --view
slit (default) frames x from -6 dc to 6 dc and z from -2 dc to 7 dc around
the slit at x = 0, z = 0 (dc = --dc, default 3.2 mm); --view silo frames the
walls (or, without walls, the particles) with a margin of 4 %. The frame is
centred in the picture and enlarged in one direction to the picture's aspect.

Output: the PNG (--out, default RUN_DIR/render.png) and beside it PNG.json with
the world-to-pixel mapping (image centre in world x, z, metres per pixel, image
size), the colours (0-255), the files drawn (relative to the PNG's folder) and the time, and the numbers of
spheres and clumps. Exit status 1 for a missing or unreadable file (also one
that ParaView reads with fewer points than its header declares), a collection
without frames or a missing array; 2 for bad arguments; 3 when
ParaView cannot render (no X display and no headless OpenGL).
"""
import argparse
import json
import math
import os
import re
import sys
import xml.etree.ElementTree as ET

# colours (RGB in 0..1)
BACKGROUND = (1.0, 1.0, 1.0)
SPHERE_COLOUR = (0.93, 0.49, 0.10)
CLUMP_COLOUR = (0.17, 0.39, 0.80)
WALL_COLOUR = (0.88, 0.88, 0.88)
EDGE_COLOUR = (0.30, 0.30, 0.30)
AMBIENT, DIFFUSE = 0.3, 0.7

# the slit view in units of dc: x from -SLIT_HALF_WIDTH to SLIT_HALF_WIDTH, z from SLIT_ZMIN to SLIT_ZMAX
SLIT_HALF_WIDTH, SLIT_ZMIN, SLIT_ZMAX = 6.0, -2.0, 7.0
SILO_MARGIN = 0.04

EXIT_DATA, EXIT_USAGE, EXIT_RENDER = 1, 2, 3


class RenderError(Exception):
    """A problem with the run folder or its files (exit status 1)."""


def fail(message, status=EXIT_DATA):
    sys.stderr.write("render.py: error: %s\n" % message)
    sys.exit(status)


def note(message):
    sys.stdout.write("render.py: %s\n" % message)


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog="render.py",
        description="Render one state of a silo run folder (free spheres, clumps as cylinders, walls) "
        "with ParaView, seen from the front. Run with pvbatch; without a display under "
        "xvfb-run -a -s '-screen 0 1280x1024x24 -noreset' pvbatch tools/render.py ...")
    p.add_argument("run_dir", metavar="RUN_DIR", help="folder with the dumps of one run")
    p.add_argument("--out", metavar="PNG", help="picture to write (default RUN_DIR/render.png)")
    p.add_argument("--size", nargs=2, type=int, metavar=("W", "H"), default=[1200, 900],
                   help="picture size in pixels (default 1200 900)")
    p.add_argument("--view", choices=["slit", "silo"], default="slit",
                   help="slit: x from -6 to 6 dc, z from -2 to 7 dc (default); silo: the whole silo")
    p.add_argument("--time", metavar="T|last",
                   help="draw the frame of the .pvd collections at or before simulated time T (s), or the "
                   "last one; without it the clog_* files when present, else the last frame")
    p.add_argument("--dc", type=float, default=3.2e-3, help="length unit of the slit view in m (default 3.2e-3)")
    p.add_argument("--sphere-type", type=int, default=2, help="atom type of the free spheres (default 2)")
    p.add_argument("--clump-size", nargs=3, type=float, metavar=("L", "A", "B"), default=[3.1e-3, 3.2e-3, 2.2e-3],
                   help="cylinder length and cross-section axes in m (default 3.1e-3 3.2e-3 2.2e-3)")
    a = p.parse_args(argv)
    if a.size[0] < 16 or a.size[1] < 16 or a.size[0] > 8192 or a.size[1] > 8192:
        p.error("--size: W and H must lie between 16 and 8192 pixels")
    if a.time is not None and a.time != "last":
        try:
            a.time = float(a.time)
        except ValueError:
            p.error("--time: expected a time in seconds or 'last', got '%s'" % a.time)
        if not math.isfinite(a.time):
            p.error("--time: expected a finite time, got '%s'" % a.time)
    if not a.dc > 0:
        p.error("--dc must be positive")
    if not all(v > 0 for v in a.clump_size):
        p.error("--clump-size: L, A and B must be positive")
    return a


# ---------------------------------------------------------------- which files


def pvd_frames(path):
    """[(time, file)] of a ParaView collection, sorted by time (stable), files as absolute paths."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as err:
        raise RenderError("cannot read the collection %s: %s" % (path, err))
    coll = root.find("Collection")
    if root.get("type") != "Collection" or coll is None:
        raise RenderError("%s is not a ParaView collection (no <Collection> element)" % path)
    frames = []
    for ds in coll.findall("DataSet"):
        t, f = ds.get("timestep"), ds.get("file")
        if t is None or f is None:
            raise RenderError("%s: a DataSet entry lacks its timestep or file attribute" % path)
        try:
            t = float(t)
        except ValueError:
            raise RenderError("%s: timestep '%s' is not a number" % (path, t))
        frames.append((t, os.path.join(os.path.dirname(os.path.abspath(path)), f)))
    frames.sort(key=lambda tf: tf[0])
    return frames


def frame_at(frames, t):
    """The last frame at or before time t (a relative tolerance of 1e-9), or None."""
    tol = 1e-9 * max(abs(t), 1e-300) + 1e-15
    chosen = None
    for ft, f in frames:
        if ft <= t + tol:
            chosen = (ft, f)
    return chosen


def check_readable(path):
    """The file exists; for a .pvtp index also every piece it names."""
    if not os.path.isfile(path):
        raise RenderError("%s does not exist" % path)
    if path.endswith(".pvtp"):
        try:
            root = ET.parse(path).getroot()
        except (OSError, ET.ParseError) as err:
            raise RenderError("cannot read %s: %s" % (path, err))
        for piece in root.iter("Piece"):
            src = piece.get("Source")
            if src is not None:
                full = os.path.join(os.path.dirname(path), src)
                if not os.path.isfile(full):
                    raise RenderError("%s names the piece %s, which does not exist" % (path, full))


def clog_particles(run_dir):
    """RUN_DIR/clog_particles.vtp or .pvtp (the newer of the two), or None."""
    found = [os.path.join(run_dir, "clog_particles" + ext) for ext in (".vtp", ".pvtp")]
    found = [f for f in found if os.path.isfile(f)]
    if not found:
        return None
    return max(found, key=os.path.getmtime)


def choose_state(run_dir, time):
    """{'label', 'time', 'particles', 'bodies', 'mesh'}: files (bodies, mesh may be None)."""
    if not os.path.isdir(run_dir):
        raise RenderError("run folder %s does not exist" % run_dir)
    if time is None:
        part = clog_particles(run_dir)
        if part is not None:
            state = {"label": "clog state", "time": None, "particles": part}
            for key, name in (("bodies", "clog_bodies.vtp"), ("mesh", "clog_mesh.vtp")):
                f = os.path.join(run_dir, name)
                state[key] = f if os.path.isfile(f) else None
                if state[key] is None:
                    note("no %s in %s: no %s drawn" % (name, run_dir, "clumps" if key == "bodies" else "walls"))
            return state
        time = "last"
    pvd = os.path.join(run_dir, "particles_.pvd")
    if not os.path.isfile(pvd):
        raise RenderError("%s has neither clog_particles.vtp (or .pvtp) nor particles_.pvd" % run_dir)
    frames = pvd_frames(pvd)
    if not frames:
        raise RenderError("%s lists no frames" % pvd)
    if time == "last":
        t, part = frames[-1]
    else:
        chosen = frame_at(frames, time)
        if chosen is None:
            raise RenderError("%s has no frame at or before t = %g s (the first is at t = %g s)" %
                              (pvd, time, frames[0][0]))
        t, part = chosen
    state = {"label": "frame t = %g s" % t, "time": t, "particles": part}
    for key, name in (("bodies", "bodies_.pvd"), ("mesh", "mesh_.pvd")):
        f = os.path.join(run_dir, name)
        state[key] = None
        what = "clumps" if key == "bodies" else "walls"
        if not os.path.isfile(f):
            note("no %s in %s: no %s drawn" % (name, run_dir, what))
            continue
        chosen = frame_at(pvd_frames(f), t)
        if chosen is None:
            note("%s has no frame at or before t = %g s: no %s drawn" % (f, t, what))
            continue
        state[key] = chosen[1]
    return state


# ---------------------------------------------------------------- ParaView pipeline

# point-data array 'cylinder_frame' (9 components, the tensor of Tensor Glyph): the
# matrix R S that takes the cylinder source (axis y, height 1, radius 0.5) to the clump:
# S sends source y to body x (length L), source x to body y (axis A), source z to body
# -z (axis B; the sign keeps det > 0), R is the clump's rotation (its first column is
# long_axis). Tensor Glyph without eigenvalue extraction uses the tensor's columns as
# the glyph's axes; the 9 values are stored column by column.
FRAME_SCRIPT = """
import numpy as np
L, A, B = %r, %r, %r
q = np.asarray(inputs[0].PointData['quaternion'], dtype=float).reshape(-1, 4)
q = q / np.linalg.norm(q, axis=1)[:, None] if len(q) else q
w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
R = np.empty((len(q), 3, 3))
R[:, 0, 0] = 1 - 2 * (y * y + z * z); R[:, 0, 1] = 2 * (x * y - w * z); R[:, 0, 2] = 2 * (x * z + w * y)
R[:, 1, 0] = 2 * (x * y + w * z); R[:, 1, 1] = 1 - 2 * (x * x + z * z); R[:, 1, 2] = 2 * (y * z - w * x)
R[:, 2, 0] = 2 * (x * z - w * y); R[:, 2, 1] = 2 * (y * z + w * x); R[:, 2, 2] = 1 - 2 * (x * x + y * y)
S = np.array([[0.0, L, 0.0], [A, 0.0, 0.0], [0.0, 0.0, -B]])
M = np.einsum('nij,jk->nik', R, S)
output.PointData.append(np.ascontiguousarray(M.transpose(0, 2, 1).reshape(-1, 9)), 'cylinder_frame')
"""


def point_arrays(src):
    return set(src.PointData.keys())


def field_value(src, name):
    if name in src.FieldData.keys():
        return src.FieldData[name].GetRange(0)[0]
    return None


def declared_points(path):
    """Number of points a .vtp file (or the pieces of a .pvtp) says it holds, from the
    Piece elements of its XML header; None when the header does not tell."""
    if path.endswith(".pvtp"):
        root = ET.parse(path).getroot()
        counts = [declared_points(os.path.join(os.path.dirname(path), piece.get("Source")))
                  for piece in root.iter("Piece") if piece.get("Source")]
        return None if any(c is None for c in counts) else sum(counts)
    with open(path, "rb") as fh:
        head = fh.read(1 << 16).decode("latin-1")
    head = head.split("<AppendedData", 1)[0]
    counts = re.findall(r'<Piece[^>]*\bNumberOfPoints="(\d+)"', head)
    return sum(int(c) for c in counts) if counts else None


def open_file(pv, path, what):
    check_readable(path)
    src = pv.OpenDataFile(path)
    if src is None:
        raise RenderError("ParaView cannot open the %s file %s" % (what, path))
    src.UpdatePipeline()
    # a damaged file: the reader reports its errors on the terminal and delivers less
    declared = declared_points(path)
    got = src.GetDataInformation().GetNumberOfPoints()
    if declared is not None and got != declared:
        raise RenderError("ParaView could not read the %s file %s: it holds %d points, %d were read" %
                          (what, path, declared, got))
    return src


def surface_look(display, colour, ambient, diffuse):
    display.ColorArrayName = ["POINTS", ""]
    display.DiffuseColor = list(colour)
    display.AmbientColor = list(colour)
    display.Ambient = ambient
    display.Diffuse = diffuse
    display.Specular = 0.0


def render(args, state, out):
    import paraview.simple as pv
    from paraview.modules import vtkRemotingViews

    # ---- read the files
    part = open_file(pv, state["particles"], "particles")
    npart = part.GetDataInformation().GetNumberOfPoints()
    arrays = point_arrays(part)
    if npart > 0:
        for name in ("type", "radius"):
            if name not in arrays:
                raise RenderError("%s has no point array '%s' (dump the particles with the fields type and "
                                  "radius, e.g. custom/vtk ... id type x y z radius)" % (state["particles"], name))
    bodies = open_file(pv, state["bodies"], "bodies") if state["bodies"] else None
    nbodies = bodies.GetDataInformation().GetNumberOfPoints() if bodies else 0
    if nbodies > 0 and "quaternion" not in point_arrays(bodies):
        raise RenderError("%s has no point array 'quaternion' (write it with dump bodies/vtk)" % state["bodies"])
    mesh = open_file(pv, state["mesh"], "mesh") if state["mesh"] else None
    if mesh is not None and mesh.GetDataInformation().GetNumberOfCells() == 0:
        mesh = None
    t = state["time"]
    if t is None:
        t = field_value(part, "TimeValue")
    step = field_value(part, "Step")

    # ---- can ParaView render here?
    info = vtkRemotingViews.vtkPVRenderingCapabilitiesInformation
    caps = info.GetLocalCapabilities()
    if not caps & (info.ONSCREEN_RENDERING | info.HEADLESS_RENDERING):
        fail("ParaView cannot render here: no X display (DISPLAY is '%s') and this ParaView has no headless "
             "OpenGL (EGL or OSMesa); run it under a virtual X server: "
             "xvfb-run -a -s '-screen 0 1280x1024x24 -noreset' pvbatch tools/render.py ..."
             % os.environ.get("DISPLAY", ""), EXIT_RENDER)

    W, H = args.size
    view = pv.CreateView("RenderView")
    view.ViewSize = [W, H]
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = list(BACKGROUND)
    view.UseFXAA = 0
    view.UseLight = 0  # no light kit (its lights are tinted): one white headlight
    light = pv.AddLight(view=view)
    light.Coords = "Headlight"
    light.Intensity = 1.0
    light.DiffuseColor = [1.0, 1.0, 1.0]

    # ---- free spheres
    nspheres = 0
    if npart > 0:
        th = pv.Threshold(Input=part, Scalars=["POINTS", "type"], LowerThreshold=args.sphere_type,
                          UpperThreshold=args.sphere_type, ThresholdMethod="Between")
        th.UpdatePipeline()
        nspheres = th.GetDataInformation().GetNumberOfPoints()
        if nspheres > 0:
            g = pv.Glyph(Input=th, GlyphType="Sphere")
            g.OrientationArray = ["POINTS", "No orientation array"]
            g.ScaleArray = ["POINTS", "radius"]
            g.ScaleFactor = 2.0  # the sphere source has radius 0.5
            g.GlyphMode = "All Points"
            g.GlyphType.ThetaResolution = 24
            g.GlyphType.PhiResolution = 16
            surface_look(pv.Show(g, view), SPHERE_COLOUR, AMBIENT, DIFFUSE)

    # ---- clumps
    if nbodies > 0:
        L, A, B = args.clump_size
        frame = pv.ProgrammableFilter(Input=bodies)
        frame.OutputDataSetType = "Same as Input"
        frame.CopyArrays = 1
        frame.Script = FRAME_SCRIPT % (L, A, B)
        tg = pv.TensorGlyph(Input=frame, GlyphType="Cylinder")
        tg.Tensors = ["POINTS", "cylinder_frame"]
        tg.ExtractEigenvalues = 0
        tg.Symmetric = 0
        tg.ThreeGlyphs = 0
        tg.ColorGlyphs = 0
        tg.LimitScalingByEigenvalues = 0
        tg.ScaleFactor = 1.0
        tg.GlyphType.Resolution = 36
        tg.GlyphType.Height = 1.0
        tg.GlyphType.Radius = 0.5
        tg.GlyphType.Capping = 1
        tg.UpdatePipeline()
        surface_look(pv.Show(tg, view), CLUMP_COLOUR, AMBIENT, DIFFUSE)

    # ---- walls
    if mesh is not None:
        d = pv.Show(mesh, view)
        d.Representation = "Surface"
        surface_look(d, WALL_COLOUR, 1.0, 0.0)
        d.ColorArrayName = ["CELLS", ""]
        d.BackfaceRepresentation = "Cull Backface"
        # the outline: the edges of the triangles seen edge-on (|normal y| < 0.5; side
        # walls, floor plates), not those of the front and back walls, whose bottom edges
        # would cross the slit
        edge_on = mesh
        if "normal" in mesh.CellData.keys():
            facing = pv.PythonCalculator(Input=mesh, ArrayAssociation="Cell Data", ArrayName="facing",
                                         Expression="abs(inputs[0].CellData['normal'][:, 1])")
            edge_on = pv.ExtractSurface(Input=pv.Threshold(
                Input=facing, Scalars=["CELLS", "facing"], LowerThreshold=0.0, UpperThreshold=0.5,
                ThresholdMethod="Between"))
        edges = pv.FeatureEdges(Input=edge_on, BoundaryEdges=1, FeatureEdges=1, NonManifoldEdges=1,
                                ManifoldEdges=0, FeatureAngle=30.0, Coloring=0)
        e = pv.Show(edges, view)
        surface_look(e, EDGE_COLOUR, 1.0, 0.0)
        e.LineWidth = max(1.0, round(min(W, H) / 450.0))

    # ---- camera: parallel projection along +y, x to the right, z up
    if args.view == "slit":
        xlo, xhi = -SLIT_HALF_WIDTH * args.dc, SLIT_HALF_WIDTH * args.dc
        zlo, zhi = SLIT_ZMIN * args.dc, SLIT_ZMAX * args.dc
    else:
        boxes = [s.GetDataInformation().GetBounds() for s in ([mesh] if mesh is not None else
                                                              [x for x in (part, bodies) if x is not None])]
        boxes = [b for b in boxes if b[0] <= b[1]]
        if not boxes:
            raise RenderError("--view silo: nothing to frame (no walls and no particles)")
        xlo, xhi = min(b[0] for b in boxes), max(b[1] for b in boxes)
        zlo, zhi = min(b[4] for b in boxes), max(b[5] for b in boxes)
        span = max(xhi - xlo, zhi - zlo, 1e-9)
        xlo, xhi = xlo - SILO_MARGIN * span, xhi + SILO_MARGIN * span
        zlo, zhi = zlo - SILO_MARGIN * span, zhi + SILO_MARGIN * span
    cx, cz = 0.5 * (xlo + xhi), 0.5 * (zlo + zhi)
    half_h = max(0.5 * (zhi - zlo), 0.5 * (xhi - xlo) * H / W)  # world half-height of the picture
    ys = [b for s in (part, bodies, mesh) if s is not None for b in s.GetDataInformation().GetBounds()[2:4]]
    ys = [y for y in ys if abs(y) < 1e30] or [0.0]
    ymin, ymax = min(ys), max(ys)
    depth = max(ymax - ymin, xhi - xlo, zhi - zlo)
    pv.Render(view)  # the first render resets the camera: set it afterwards
    view.CameraParallelProjection = 1
    view.CameraFocalPoint = [cx, 0.5 * (ymin + ymax), cz]
    view.CameraPosition = [cx, ymin - 10.0 * depth, cz]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraParallelScale = half_h
    view.ViewTime = t if t is not None else 0.0
    pv.Render(view)
    pv.SaveScreenshot(out, view, ImageResolution=[W, H], TransparentBackground=0)
    if not os.path.isfile(out):
        fail("ParaView did not write %s" % out, EXIT_RENDER)

    mpp = 2.0 * half_h / H

    def rgb(c):
        return [int(round(255 * v)) for v in c]

    meta = {
        "image": os.path.basename(out),
        "width": W,
        "height": H,
        "view": args.view,
        "projection": "parallel, looking along +y: x to the right, z up",
        "centre_x": cx,
        "centre_z": cz,
        "metres_per_pixel": mpp,
        "pixel_to_world": "x = centre_x + (col + 0.5 - width/2) * metres_per_pixel, "
                          "z = centre_z - (row + 0.5 - height/2) * metres_per_pixel "
                          "(col counted from the left, row from the top, from 0)",
        "colours": {"background": rgb(BACKGROUND), "spheres": rgb(SPHERE_COLOUR), "clumps": rgb(CLUMP_COLOUR),
                    "walls": rgb(WALL_COLOUR), "wall_edges": rgb(EDGE_COLOUR)},
        "shading": "spheres and clumps: colour times (%g + %g cos(angle to the viewer)), white headlight; "
                   "walls and edges: flat colour" % (AMBIENT, DIFFUSE),
        "state": state["label"],
        "time": t,
        "step": int(step) if step is not None else None,
        # relative to the picture's folder, so that a picture kept with its JSON names no machine's paths
        "files": {k: (os.path.relpath(state[k], os.path.dirname(out)) if state[k] else state[k])
                  for k in ("particles", "bodies", "mesh")},
        "counts": {"particles": int(npart), "spheres": int(nspheres), "clumps": int(nbodies)},
        "sphere_type": args.sphere_type,
        "clump_size": list(args.clump_size),
        "dc": args.dc,
    }
    with open(out + ".json", "w") as fh:
        json.dump(meta, fh, indent=1)
        fh.write("\n")
    return meta


def main(argv):
    args = parse_args(argv)
    run_dir = os.path.abspath(args.run_dir)
    out = os.path.abspath(args.out) if args.out else os.path.join(run_dir, "render.png")
    if not out.lower().endswith(".png"):
        fail("--out must name a .png file, got '%s'" % out, EXIT_USAGE)
    if not os.path.isdir(os.path.dirname(out)):
        fail("the folder of %s does not exist" % out)
    try:
        state = choose_state(run_dir, args.time)
        meta = render(args, state, out)
    except RenderError as err:
        fail(str(err))
    t = meta["time"]
    note("wrote %s (%dx%d, view %s, %s%s: %d clumps, %d spheres) and %s.json" %
         (out, meta["width"], meta["height"], meta["view"], state["label"],
          "" if state["time"] is not None or t is None else ", t = %g s" % t,
          meta["counts"]["clumps"], meta["counts"]["spheres"], os.path.basename(out)))


if __name__ == "__main__":
    # ParaView's Programmable Filter star-imports numpy and VTK's numpy algorithms
    # (min, max, round, ...) into the module __main__ when it runs: run this file's
    # code as a module of its own so that its names stay the builtins
    import importlib.util
    spec = importlib.util.spec_from_file_location("granary_render", os.path.abspath(__file__))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.main(sys.argv[1:])
