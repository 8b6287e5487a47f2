"""Observables computed from files a run writes, for scripts that cannot
print them directly."""
import math

import numpy as np


def read_dump_columns(path):
    """Columns of a 'dump custom' / write_dump text file (last snapshot) by name."""
    with open(path) as f:
        lines = f.read().splitlines()
    start = max(i for i, ln in enumerate(lines) if ln.startswith("ITEM: ATOMS"))
    names = lines[start].split()[2:]
    rows = [list(map(float, ln.split())) for ln in lines[start + 1:] if ln.strip()]
    a = np.array(rows).reshape(-1, len(names))
    return {n: a[:, k] for k, n in enumerate(names)}


def heap_angle(path, central=(0.25, 0.75), bins=16, layout="axisymmetric"):
    """Angle of repose [deg] of a heap on the plane z = 0, from the free
    surface: the highest sphere top z + r in each bin of distance from the
    heap's axis, a straight line fitted to it over the central part of the
    heap's extent (fractions `central` of the distance holding 98 % of the
    spheres), away from the rounded apex and the spread-out foot.

    layout "axisymmetric": a conical heap; the distance is radial, from the
    vertical through its centre of mass, in rings.
    layout "cell": a heap poured against the wall at the low-x end of a
    rectangular cell (a side view, as a camera sees it); the distance is x
    from that wall (the lowest sphere surface x - r), in slabs across the
    cell's depth.

    Returns the angle and the number of bins fitted."""
    c = read_dump_columns(path)
    x, y, z, r = c["x"], c["y"], c["z"], c["radius"]
    if layout == "axisymmetric":
        rho = np.hypot(x - x.mean(), y - y.mean())
    elif layout == "cell":
        rho = x - np.min(x - r)
    else:
        raise ValueError(f"heap_angle: unknown layout '{layout}' (axisymmetric or cell)")
    rmax = np.percentile(rho, 98)
    edges = np.linspace(0, rmax, bins + 1)
    mids, tops = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        sel = (rho >= a) & (rho < b)
        if sel.any():
            mids.append(0.5 * (a + b))
            tops.append(np.max(z[sel] + r[sel]))
    mids, tops = np.array(mids), np.array(tops)
    use = (mids >= central[0] * rmax) & (mids <= central[1] * rmax)
    if use.sum() < 3:
        return math.nan, int(use.sum())
    slope = np.polyfit(mids[use], tops[use], 1)[0]
    return math.degrees(math.atan(-slope)), int(use.sum())
