#!/usr/bin/env python3
"""Sphere clumps that approximate a cylinder of elliptical cross-section.

The particle is the one of the silo experiments: a cylinder of length
L = 3.1 mm whose cross-section is an ellipse with axes 3.2 mm and 2.2 mm
(semi-axes a = 1.6 mm, b = 1.1 mm). The cylinder axis is x, the long axis of
the ellipse y and the short one z; the clump is centred at the origin.

Spheres are placed in layers along the axis. In each layer some spheres sit on
the major axis of the ellipse ("core") and the others on a ring, an ellipse
shrunk from the cross-section so that ring spheres touch its boundary; the
rings of alternate layers are turned by half a step, mirror-symmetrically about
the middle, so that the clump keeps the cylinder's principal axes. No sphere reaches past the
end faces or the elliptical mantle's extent. The layer count, the split into
core and ring, the two radii, the ring size and the inset of the end layers
are chosen to maximise the overlap (intersection over union, on a grid
of sample points) between the union of the spheres and the cylinder, among
layouts whose principal moments of inertia are ordered as the cylinder's
(smallest about the cylinder axis, largest about the short axis z), so that
the clump's long axis is the cylinder axis.

For every clump the script reports the solid volume (overlaps counted once),
the moments of inertia and the extents along the three axes against the true
cylinder:
volume pi a b L = 17.14 mm^3, extents 3.1 x 3.2 x 2.2 mm, and the diameter of
the sphere of equal volume, 3.20 mm.

Usage: tools/make_clump.py [--out DIR] [N ...]   (default: 10 20 50 100 into potentials/)
Only the Python standard library is used.
"""
import argparse
import math
import os
import sys

L = 3.1e-3   # cylinder length [m]
A = 1.6e-3   # semi-axis along y [m]
B = 1.1e-3   # semi-axis along z [m]
V_TRUE = math.pi * A * B * L

# layer count, core spheres per layer, ring spheres per layer (product = N)
LAYOUTS = {
    10: [(2, 1, 4), (2, 0, 5), (1, 2, 8), (2, 2, 3)],
    20: [(4, 1, 4), (2, 2, 8), (2, 1, 9), (4, 0, 5)],
    50: [(5, 2, 8), (5, 1, 9), (5, 0, 10), (2, 5, 20)],
    100: [(10, 2, 8), (5, 2, 18), (10, 1, 9), (5, 4, 16)],
}


def inside_cylinder(x, y, z):
    return abs(x) <= 0.5 * L and (y / A) ** 2 + (z / B) ** 2 <= 1.0


def grid(n, margin=0.1):
    """Regular grid of sample points over the box around the cylinder."""
    lo = [-(0.5 + margin) * L, -(1 + margin) * A, -(1 + margin) * B]
    hi = [-v for v in lo]
    pts = []
    for i in range(n):
        x = lo[0] + (i + 0.5) * (hi[0] - lo[0]) / n
        for j in range(n):
            y = lo[1] + (j + 0.5) * (hi[1] - lo[1]) / n
            for k in range(n):
                z = lo[2] + (k + 0.5) * (hi[2] - lo[2]) / n
                pts.append((x, y, z, inside_cylinder(x, y, z)))
    cell = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]) / n ** 3
    return pts, cell


def build(layout, p):
    """Spheres (x, y, z, r) of a layout for parameters p = (r_core, r_ring, ring, inset)."""
    nl, ncore, nring = layout
    r_core, r_ring, ring_scale, inset = p
    spheres = []
    if nl == 1:
        xs = [0.0]
    else:
        # end layers stay inside the end faces: inset counts from the largest radius
        rmax = max(r_core if ncore else 0.0, r_ring if nring else 0.0)
        x0 = max(0.5 * L - rmax - inset, 0.0)
        xs = [-x0 + 2 * x0 * i / (nl - 1) for i in range(nl)]
    for li, x in enumerate(xs):
        # core: on the major axis, spread so that the outer ones touch the ellipse
        for c in range(ncore):
            ymax = max(A - r_core, 0.0)
            y = 0.0 if ncore == 1 else -ymax + 2 * ymax * c / (ncore - 1)
            spheres.append((x, y, 0.0, r_core))
        # ring: on the ellipse shrunk by the ring radius, scaled by ring_scale
        ay, bz = max(A - r_ring, 0.0) * ring_scale, max(B - r_ring, 0.0) * ring_scale
        # staggered rings, mirror-symmetric about x = 0 so that x, y, z stay principal axes
        stagger = 0.5 * (min(li, nl - 1 - li) % 2)
        for k in range(nring):
            t = 2 * math.pi * (k + stagger) / nring
            spheres.append((x, ay * math.cos(t), bz * math.sin(t), r_ring))
    return spheres


def overlap(spheres, pts, cell):
    """Intersection over union with the cylinder, the union volume, and the
    principal moments per unit mass (Ix, Iy, Iz) [m^2] (the clumps are
    symmetric, so x, y, z are principal axes)."""
    both = either = union = 0
    sxx = syy = szz = 0.0
    for (x, y, z, inc) in pts:
        ins = False
        for (sx, sy, sz, r) in spheres:
            dx, dy, dz = x - sx, y - sy, z - sz
            if dx * dx + dy * dy + dz * dz <= r * r:
                ins = True
                break
        if ins:
            union += 1
            sxx += x * x
            syy += y * y
            szz += z * z
        both += ins and inc
        either += ins or inc
    n = max(union, 1)
    moments = ((syy + szz) / n, (sxx + szz) / n, (sxx + syy) / n)
    return both / either, union * cell, moments


def cylinder_moments():
    """Principal moments per unit mass of the true cylinder (Ix, Iy, Iz) [m^2]."""
    return ((A * A + B * B) / 4, B * B / 4 + L * L / 12, A * A / 4 + L * L / 12)


def score(spheres, pts, cell):
    """Overlap, penalised unless the moments are ordered as the cylinder's
    (Ix < Iy < Iz: the cylinder axis is the axis of the smallest moment)."""
    j, _, (ix, iy, iz) = overlap(spheres, pts, cell)
    return j if ix < iy < iz else j - 1.0


def optimise(layout, pts, cell):
    """Coordinate search over (r_core, r_ring, ring_scale, inset)."""
    lo = [0.3 * B, 0.25 * B, 0.5, 0.0]
    hi = [1.0 * B, 1.0 * B, 1.0, 0.3 * L / 2]
    p = [0.8 * B, 0.6 * B, 1.0, 0.0]
    nl, ncore, nring = layout
    if ncore == 0:
        lo[0] = hi[0] = p[0] = 0.5 * B
    if nring == 0:
        lo[1] = hi[1] = p[1] = 0.5 * B
    best = score(build(layout, p), pts, cell)
    step = [(h - l) / 4 for l, h in zip(lo, hi)]
    for _ in range(6):
        improved = True
        while improved:
            improved = False
            for d in range(4):
                for sign in (-1, 1):
                    q = list(p)
                    q[d] = min(hi[d], max(lo[d], q[d] + sign * step[d]))
                    if q == p:
                        continue
                    j = score(build(layout, q), pts, cell)
                    if j > best + 1e-12:
                        best, p, improved = j, q, True
        step = [s / 2 for s in step]
    return best, p


def extents(spheres):
    ext = []
    for d in range(3):
        ext.append(max(s[d] + s[3] for s in spheres) - min(s[d] - s[3] for s in spheres))
    return ext


def make(n, out_dir, log):
    coarse, coarse_cell = grid(18)
    best = None
    for layout in LAYOUTS[n]:
        j, p = optimise(layout, coarse, coarse_cell)
        log(f"  N={n} layout {layout}: overlap {j:.4f} on the coarse grid")
        if best is None or j > best[0]:
            best = (j, layout, p)
    _, layout, p = best
    spheres = build(layout, p)
    fine, fine_cell = grid(60)
    j, vol, mom = overlap(spheres, fine, fine_cell)
    cyl = cylinder_moments()
    if not mom[0] < mom[1] < mom[2]:
        log(f"WARNING: N={n}: the moments of inertia are not ordered as the cylinder's")
    ext = extents(spheres)
    d_eq = (6 * vol / math.pi) ** (1 / 3)
    d_true = (6 * V_TRUE / math.pi) ** (1 / 3)
    path = os.path.join(out_dir, f"cylinder_ellipse_{n}.clump")
    with open(path, "w") as f:
        f.write(f"# Cylinder of elliptical cross-section as a clump of {n} spheres (x y z r in m, one sphere per line)\n")
        f.write("# true cylinder: length 3.1 mm along x, axes 3.2 mm (y) and 2.2 mm (z),\n")
        f.write(f"#   volume pi a b L = {V_TRUE * 1e9:.4f} mm^3, equal-volume sphere diameter {d_true * 1e3:.3f} mm\n")
        f.write(f"# this clump: volume {vol * 1e9:.4f} mm^3 ({vol / V_TRUE:.4f} of the cylinder), equal-volume sphere "
                f"diameter {d_eq * 1e3:.3f} mm,\n")
        f.write(f"#   extents x y z {ext[0] * 1e3:.3f} {ext[1] * 1e3:.3f} {ext[2] * 1e3:.3f} mm (cylinder 3.1 3.2 2.2), "
                f"overlap with the cylinder (intersection/union) {j:.4f}\n")
        f.write(f"# moments of inertia per unit mass Ix Iy Iz {mom[0] * 1e6:.4f} {mom[1] * 1e6:.4f} {mom[2] * 1e6:.4f} mm^2 "
                f"(cylinder {cyl[0] * 1e6:.4f} {cyl[1] * 1e6:.4f} {cyl[2] * 1e6:.4f}); the cylinder axis x has the smallest\n")
        radii = []
        if layout[1]:
            radii.append(f"core radius {p[0] * 1e3:.4f} mm")
        if layout[2]:
            radii.append(f"ring radius {p[1] * 1e3:.4f} mm")
        f.write(f"# layout: {layout[0]} layers along x, {layout[1]} core + {layout[2]} ring spheres per layer, "
                f"{', '.join(radii)}\n")
        f.write("# made by tools/make_clump.py; volumes from a 60^3 sample grid (about 0.5% uncertainty)\n")
        for (x, y, z, r) in spheres:
            f.write(f"{x:.8e} {y:.8e} {z:.8e} {r:.8e}\n")
    log(f"N={n}: layout {layout}, volume {vol * 1e9:.3f} mm^3 = {vol / V_TRUE:.3f} x cylinder "
        f"({V_TRUE * 1e9:.3f}), equal-volume diameter {d_eq * 1e3:.3f} mm (cylinder {d_true * 1e3:.3f}), "
        f"extents {ext[0] * 1e3:.3f} x {ext[1] * 1e3:.3f} x {ext[2] * 1e3:.3f} mm (3.1 x 3.2 x 2.2), "
        f"intersection/union {j:.4f}, moments/mass {mom[0] * 1e6:.3f} {mom[1] * 1e6:.3f} {mom[2] * 1e6:.3f} mm^2 "
        f"(cylinder {cyl[0] * 1e6:.3f} {cyl[1] * 1e6:.3f} {cyl[2] * 1e6:.3f}) -> {os.path.relpath(path)}")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sizes", nargs="*", type=int, default=[10, 20, 50, 100])
    ap.add_argument("--out", default=os.path.normpath(os.path.join(here, "..", "potentials")))
    args = ap.parse_args()
    for n in args.sizes:
        if n not in LAYOUTS:
            sys.exit(f"no layout for {n} spheres; choose from {sorted(LAYOUTS)}")
        make(n, args.out, lambda s: print(s, flush=True))


if __name__ == "__main__":
    main()
