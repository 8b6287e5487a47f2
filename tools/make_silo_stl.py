#!/usr/bin/python3
"""Write the STL meshes (ASCII) of a flat-bottomed rectangular silo with a slit.

Usage: tools/make_silo_stl.py [--W 10] [--D 3] [--H 18] [--slit 2.2] [--dc 0.0032]
                              [--out DIR] [--walls silo_walls.stl] [--shutter silo_shutter.stl]

Lengths are given in units of the particle size dc (metres per dc: --dc) and
written in metres. The silo occupies -W/2 <= x <= W/2 (width), -D/2 <= y <= D/2
(depth) and 0 <= z <= H (height). The bottom z = 0 has a slit of width s
across the full depth at the centre (-s/2 < x < s/2).

Two files:
  walls    the two side walls (x = -W/2, x = W/2), the front and back walls
           (y = -D/2, y = D/2) and the two bottom plates (z = 0, from the side
           walls to the slit), 2 triangles per rectangle, 12 in all
  shutter  the plate that closes the slit (z = 0, -s/2 <= x <= s/2, full
           depth), 2 triangles; removing it opens the silo

Every facet normal points into the silo (towards the particles); vertices are
ordered counter-clockwise seen from that side. Uses only the standard library
and numpy.
"""
import argparse
import os
import sys

import numpy as np


def rectangle(origin, u, v, inward):
    """Two triangles of the rectangle origin + a u + b v (0 <= a, b <= 1), oriented so
    that their normal is along `inward`."""
    o, u, v = (np.asarray(a, dtype=float) for a in (origin, u, v))
    n = np.cross(u, v)
    if np.dot(n, inward) < 0:
        u, v = v, u
    p0, p1, p2, p3 = o, o + u, o + u + v, o + v
    return [(p0, p1, p2), (p0, p2, p3)]


def silo_triangles(W, D, H, s):
    """(walls, shutter): lists of triangles (3 vertices each) in units of dc."""
    if not (W > 0 and D > 0 and H > 0):
        raise ValueError("W, D and H must be positive")
    if not (0 < s < W):
        raise ValueError(f"the slit width s = {s} must lie between 0 and the width W = {W}")
    x0, x1, y0, y1 = -W / 2, W / 2, -D / 2, D / 2
    walls = []
    walls += rectangle((x0, y0, 0), (0, D, 0), (0, 0, H), (1, 0, 0))  # left side wall
    walls += rectangle((x1, y0, 0), (0, D, 0), (0, 0, H), (-1, 0, 0))  # right side wall
    walls += rectangle((x0, y0, 0), (W, 0, 0), (0, 0, H), (0, 1, 0))  # front wall
    walls += rectangle((x0, y1, 0), (W, 0, 0), (0, 0, H), (0, -1, 0))  # back wall
    plate = (W - s) / 2
    walls += rectangle((x0, y0, 0), (plate, 0, 0), (0, D, 0), (0, 0, 1))  # left bottom plate
    walls += rectangle((s / 2, y0, 0), (plate, 0, 0), (0, D, 0), (0, 0, 1))  # right bottom plate
    shutter = rectangle((-s / 2, y0, 0), (s, 0, 0), (0, D, 0), (0, 0, 1))
    return walls, shutter


def write_stl(path, name, triangles, scale):
    """ASCII STL with unit facet normals; coordinates multiplied by `scale`."""
    with open(path, "w") as f:
        f.write(f"solid {name}\n")
        for tri in triangles:
            a, b, c = (np.asarray(p) * scale for p in tri)
            n = np.cross(b - a, c - a)
            n /= np.linalg.norm(n)
            f.write(f"  facet normal {n[0]:.9e} {n[1]:.9e} {n[2]:.9e}\n    outer loop\n")
            for p in (a, b, c):
                f.write(f"      vertex {p[0]:.9e} {p[1]:.9e} {p[2]:.9e}\n")
            f.write("    endloop\n  endfacet\n")
        f.write(f"endsolid {name}\n")


def read_stl(path):
    """(normals, triangles) of an ASCII STL file as arrays (n, 3) and (n, 3, 3)."""
    normals, verts = [], []
    with open(path) as f:
        for line in f:
            w = line.split()
            if w[:2] == ["facet", "normal"]:
                normals.append([float(x) for x in w[2:5]])
            elif w and w[0] == "vertex":
                verts.append([float(x) for x in w[1:4]])
    return np.array(normals), np.array(verts).reshape(-1, 3, 3)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--W", type=float, default=10.0, help="width (x) in dc")
    ap.add_argument("--D", type=float, default=3.0, help="depth (y) in dc")
    ap.add_argument("--H", type=float, default=18.0, help="height (z) in dc")
    ap.add_argument("--slit", type=float, default=2.2, help="slit width in dc")
    ap.add_argument("--dc", type=float, default=3.2e-3, help="size of the particles dc in metres")
    ap.add_argument("--out", default=".", help="output folder")
    ap.add_argument("--walls", default="silo_walls.stl")
    ap.add_argument("--shutter", default="silo_shutter.stl")
    a = ap.parse_args(argv)
    if not a.dc > 0:
        sys.exit("make_silo_stl.py: --dc must be positive")
    try:
        walls, shutter = silo_triangles(a.W, a.D, a.H, a.slit)
    except ValueError as e:
        sys.exit(f"make_silo_stl.py: {e}")
    os.makedirs(a.out, exist_ok=True)
    write_stl(os.path.join(a.out, a.walls), "silo_walls", walls, a.dc)
    write_stl(os.path.join(a.out, a.shutter), "silo_shutter", shutter, a.dc)
    print(f"silo {a.W:g} x {a.D:g} x {a.H:g} dc, slit {a.slit:g} dc, dc = {a.dc:g} m: "
          f"{os.path.join(a.out, a.walls)} ({len(walls)} facets), "
          f"{os.path.join(a.out, a.shutter)} ({len(shutter)} facets)")


if __name__ == "__main__":
    main()
