#!/usr/bin/python3
"""Contacts of a granular bed from the diagnostic dumps of
examples/silo_liggghts/in.silo_both (-var diag 1), written alike by Granary
and LIGGGHTS 3.8:
  diag_atoms.<step>.txt   dump custom: id type id_multisphere x y z radius
  diag_pairs.<step>.txt   dump local: the IDs of every contact the pair style found

    /usr/bin/python3 tools/bed_contacts.py check DIR      # does the pair find every contact?
    /usr/bin/python3 tools/bed_contacts.py beads DIR...   # contact numbers of the settled beds
    /usr/bin/python3 tools/bed_contacts.py beads --flow DIR...   # ... averaged over the discharge

check: at every dumped step, the contacts by geometry (two spheres of
different bodies whose centres are closer than the sum of their radii by
more than --tol times the smaller radius; spheres of one clump never touch)
against the contacts the pair style reports. A contact deeper than --tol that
the pair does not report is missed (e.g. by a neighbour list that was not
rebuilt in time); the pair reporting two spheres with a gap wider than --tol
is counted too. Contacts within --tol of touching count either way (the
dumps' 10 digits). Exit status 1 when a contact is missed.

beads: at the first dumped step of each folder (the settled bed at the start
of the discharge; with --flow the mean over the dumps after it), per bead
(type 2): contacts with clump spheres (type 1),
distinct clumps touched, contacts with beads; the share of beads touching no
particle; per clump, contacts with spheres of other clumps; and the beads'
mean overlap over their radius.
"""
import argparse
import glob
import os
import re
import sys

import numpy as np
from scipy.spatial import cKDTree


def read_items(path):
    """Column names and rows (float array) of the last ITEM: ATOMS / ITEM:
    ENTRIES block of a text dump."""
    with open(path) as f:
        lines = f.read().splitlines()
    heads = [k for k, ln in enumerate(lines) if ln.startswith("ITEM: ATOMS") or ln.startswith("ITEM: ENTRIES")]
    if not heads:
        raise SystemExit(f"{path}: no 'ITEM: ATOMS' or 'ITEM: ENTRIES' line; not a dump")
    names = lines[heads[-1]].split()[2:]
    rows = [ln.split() for ln in lines[heads[-1] + 1:] if ln.strip()]
    if any(len(r) != len(names) for r in rows):
        raise SystemExit(f"{path}: a row has not {len(names)} values (a truncated file?)")
    return names, np.array(rows, dtype=float).reshape(-1, len(names))


def steps(folder):
    out = []
    for p in glob.glob(os.path.join(folder, "diag_atoms.*.txt")):
        m = re.search(r"diag_atoms\.(\d+)\.txt$", p)
        if m and os.path.exists(os.path.join(folder, f"diag_pairs.{m.group(1)}.txt")):
            out.append(int(m.group(1)))
    if not out:
        raise SystemExit(f"{folder}: no diag_atoms.<step>.txt with its diag_pairs.<step>.txt "
                         "(run in.silo_both with -var diag 1)")
    return sorted(out)


def particles(folder, step):
    names, a = read_items(os.path.join(folder, f"diag_atoms.{step}.txt"))
    col = {n: a[:, k] for k, n in enumerate(names)}
    body = col.get("id_multisphere", col.get("body"))
    if body is None:
        raise SystemExit(f"{folder}/diag_atoms.{step}.txt: no id_multisphere (or body) column")
    return (col["id"].astype(np.int64), col["type"].astype(int), body.astype(np.int64),
            np.c_[col["x"], col["y"], col["z"]], col["radius"])


def geometric_contacts(ids, body, x, r, tol):
    """{(id_lo, id_hi): overlap / smaller radius} of the sphere pairs of
    different bodies that overlap by more than -tol times the smaller radius."""
    tree = cKDTree(x)
    pairs = np.array(sorted(tree.query_pairs(2 * r.max())), dtype=np.int64).reshape(-1, 2)
    i, j = pairs[:, 0], pairs[:, 1]
    rel = (r[i] + r[j] - np.linalg.norm(x[i] - x[j], axis=1)) / np.minimum(r[i], r[j])
    keep = (rel > tol) & ~((body[i] >= 0) & (body[i] == body[j]))
    return {(min(a, b), max(a, b)): float(o) for a, b, o in zip(ids[i[keep]], ids[j[keep]], rel[keep])}


def cmd_check(a):
    worst = 0.0
    for step in steps(a.folder):
        ids, _, body, x, r = particles(a.folder, step)
        _, p = read_items(os.path.join(a.folder, f"diag_pairs.{step}.txt"))
        found = {(int(min(u, v)), int(max(u, v))) for u, v in p[:, :2]}
        geo = geometric_contacts(ids, body, x, r, -a.tol)
        deep = {k: o for k, o in geo.items() if o > a.tol}
        missed = [deep[k] for k in deep if k not in found]
        shallow = [k for k in found if k not in geo]
        worst = max([worst] + missed)
        print(f"step {step}: contacts by geometry {len(deep)}, found by the pair {len(found)}, "
              f"missed {len(missed)} (deepest {max(missed, default=0):.3g} of the radius), "
              f"reported by the pair with a gap of more than {a.tol:g} of the radius {len(shallow)}")
    print("no contact missed" if worst == 0 else f"MISSED contacts, the deepest {worst:.3g} of the radius")
    return 1 if worst > 0 else 0


def bead_stats(folder, dc, flow=False):
    """The contact numbers at the first dump (the settled bed), or with
    `flow` averaged over the dumps after it (the discharge)."""
    if not flow:
        return bead_stats_at(folder, steps(folder)[0], dc)
    later = steps(folder)[1:]
    if not later:
        raise SystemExit(f"{folder}: --flow needs dumps after the first (the discharge)")
    each = [bead_stats_at(folder, st, dc) for st in later]
    out = {k: (float(np.mean([e[k] for e in each])) if isinstance(each[0][k], float) else each[0][k])
           for k in each[0]}
    out["step"] = f"{later[0]}-{later[-1]}"
    return out


def bead_stats_at(folder, step, dc):
    ids, typ, body, x, r = particles(folder, step)
    geo = geometric_contacts(ids, body, x, r, 0.0)
    index = {int(v): k for k, v in enumerate(ids)}
    n_clsph = np.zeros(len(ids), int)
    n_bead = np.zeros(len(ids), int)
    touched = [set() for _ in ids]
    n_cc = {}
    overlaps = []
    for (u, v), rel in geo.items():
        i, j = index[u], index[v]
        for p, q in ((i, j), (j, i)):
            if typ[q] == 2:
                n_bead[p] += 1
            else:
                n_clsph[p] += 1
                touched[p].add(int(body[q]))
            if typ[p] == 2:
                overlaps.append(rel * min(r[i], r[j]) / r[p])
        if typ[i] == 1 and typ[j] == 1:
            n_cc[body[i]] = n_cc.get(body[i], 0) + 1
            n_cc[body[j]] = n_cc.get(body[j], 0) + 1
    beads = np.where(typ == 2)[0]
    clumps = np.unique(body[body >= 0])
    return {"folder": folder, "step": step, "beads": len(beads), "clumps": len(clumps),
            "beads_in_slab": int(np.sum((x[beads, 2] > 2 * dc) & (x[beads, 2] < 6 * dc))),
            "bead_clump_sphere_contacts": float(n_clsph[beads].mean()),
            "bead_clumps_touched": float(np.mean([len(touched[i]) for i in beads])),
            "bead_bead_contacts": float(n_bead[beads].mean()),
            "beads_touching_nothing": float(np.mean(n_clsph[beads] + n_bead[beads] == 0)),
            "clump_clump_contacts": float(np.mean([n_cc.get(b, 0) for b in clumps])),
            "bead_overlap_over_radius": float(np.mean(overlaps)) if overlaps else 0.0}


def cmd_beads(a):
    keys = ["beads", "beads_in_slab", "bead_clump_sphere_contacts", "bead_clumps_touched", "bead_bead_contacts",
            "beads_touching_nothing", "clump_clump_contacts", "bead_overlap_over_radius"]
    print("folder step " + " ".join(keys))
    for folder in a.folders:
        s = bead_stats(folder, a.dc, a.flow)
        print(f"{folder} {s['step']} " + " ".join(f"{s[k]:.4g}" for k in keys))
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("check", help="does the pair find every contact?")
    c.add_argument("folder")
    c.add_argument("--tol", type=float, default=1e-6,
                   help="overlap (over the smaller radius) below which a contact counts as touching only "
                        "(the dumps' 10 digits; default 1e-6)")
    b = sub.add_parser("beads", help="contact numbers of the settled beds")
    b.add_argument("folders", nargs="+")
    b.add_argument("--dc", type=float, default=3.2e-3, help="cylinder size for the 2-6 dc slab [m]")
    b.add_argument("--flow", action="store_true",
                   help="average over the dumps after the first (the discharge) instead of the first")
    a = ap.parse_args(argv)
    return {"check": cmd_check, "beads": cmd_beads}[a.cmd](a)


if __name__ == "__main__":
    sys.exit(main())
