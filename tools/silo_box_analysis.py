#!/usr/bin/python3
"""Flow state in the box above the silo's exit, averaged over the avalanches (Fig. 8 style).

Usage: tools/silo_box_analysis.py --box B1.dat [B2.dat ...] [--avalanches A1.csv ...]
                                  [--phi 0 0.05 ...] [--labels ...] [--out DIR]

Each box file is written by fix ave/time in the silo example
(examples/silo_clogging/in.silo): LAMMPS' ave/time format, '#' lines and one
row per output step; the column names come from the last '#' line before the
data (title2), e.g.

    # step time phi phi_c phi_s ke_c erot_c n_c ke_s erot_s n_s theta state

Needed columns: time [s], phi (total volume fraction in the box), ke_c and
erot_c (translational and rotational kinetic energy of the clumps whose centre
is in the box [J]), n_c (their number), theta (their mean angle between long
axis and vertical [rad]). Optional: ke_s, erot_s, n_s (the free spheres in the
box), phi_c, phi_s (volume fraction per species), state (fix clog-detect's
state averaged over the sampling window: 0 flowing).

Rows count as flowing when their state is 0 (if the column exists) and, when
the case's avalanche CSV is given, their time lies between t_start and t_end
of one of its avalanches. For every case the script reports the mean over all
flowing rows of
  phi, phi_c, phi_s      volume fractions
  k_te = (ke_c + ke_s) / (n_c + n_s)    translational kinetic energy per body [J]
  k_re = (erot_c + erot_s) / (n_c + n_s) rotational kinetic energy per body [J]
  theta                  mean orientation of the cylinders with the vertical [deg]
with its standard error over the avalanches (the spread of the per-avalanche
means; over the rows when there are fewer than two avalanches), prints the
table, writes DIR/box_stats.csv, DIR/box_vs_phi.png (the four quantities
against phi, or against the case) and DIR/box_timeseries.png.
"""
import argparse
import csv
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from avalanche_stats import CsvError, read_avalanches  # noqa: E402

NEEDED = ("time", "phi", "ke_c", "erot_c", "n_c", "theta")
QUANTITIES = ("phi", "phi_c", "phi_s", "k_te", "k_re", "theta_deg")


def read_box(path):
    """Dict column -> array of a fix ave/time file with named columns."""
    names, rows = None, []
    try:
        with open(path) as f:
            for lineno, line in enumerate(f, 1):
                if line.startswith("#"):
                    words = line[1:].split()
                    if words:
                        names = words
                    continue
                if not line.strip():
                    continue
                if names is None:
                    raise CsvError(f"{path}: line {lineno}: data before the '# step time ...' title line")
                words = line.split()
                if len(words) != len(names):
                    raise CsvError(f"{path}: line {lineno}: {len(words)} values, the title names {len(names)}")
                try:
                    rows.append([float(w) for w in words])
                except ValueError:
                    raise CsvError(f"{path}: line {lineno}: a value is not a number")
    except OSError as e:
        raise CsvError(f"{path}: cannot read: {e.strerror}")
    if names is None:
        raise CsvError(f"{path}: no title line naming the columns")
    names = ["step" if n.lower() == "timestep" else n for n in names]
    missing = [c for c in NEEDED if c not in names]
    if missing:
        raise CsvError(f"{path}: the columns {', '.join(missing)} are missing (found {' '.join(names)})")
    data = np.array(rows, dtype=float).reshape(-1, len(names))
    return {n: data[:, k] for k, n in enumerate(names)}


def derived(d):
    """The per-row quantities of the table."""
    n = len(d["time"])
    zero = np.zeros(n)
    nb = d["n_c"] + d.get("n_s", zero)
    with np.errstate(invalid="ignore", divide="ignore"):
        q = {
            "phi": d["phi"],
            "phi_c": d.get("phi_c", np.full(n, np.nan)),
            "phi_s": d.get("phi_s", np.full(n, np.nan)),
            "k_te": np.where(nb > 0, (d["ke_c"] + d.get("ke_s", zero)) / nb, np.nan),
            "k_re": np.where(nb > 0, (d["erot_c"] + d.get("erot_s", zero)) / nb, np.nan),
            "theta_deg": np.where(d["n_c"] > 0, np.degrees(d["theta"]), np.nan),
        }
    return q


def flowing_rows(d, aval):
    """Boolean mask of the flowing rows and the avalanche index of each row (-1: none)."""
    t = d["time"]
    keep = np.ones(len(t), dtype=bool)
    if "state" in d:
        keep &= d["state"] == 0
    which = np.full(len(t), -1)
    if aval is not None:
        for k, (t0, t1) in enumerate(zip(aval["t_start"], aval["t_end"])):
            which[(t >= t0) & (t <= t1)] = k
        keep &= which >= 0
    return keep, which


def summarise(q, keep, which):
    out = {"rows": int(keep.sum())}
    groups = sorted(set(which[keep]) - {-1})
    out["avalanches"] = len(groups)
    for name, x in q.items():
        xs = x[keep]
        xs = xs[np.isfinite(xs)]
        out[name] = float(np.mean(xs)) if len(xs) else float("nan")
        if len(groups) >= 2:
            means = [np.nanmean(x[keep & (which == g)]) for g in groups if np.any(np.isfinite(x[keep & (which == g)]))]
            out[name + "_se"] = float(np.std(means, ddof=1) / np.sqrt(len(means))) if len(means) >= 2 else float("nan")
        else:
            out[name + "_se"] = float(np.std(xs, ddof=1) / np.sqrt(len(xs))) if len(xs) >= 2 else float("nan")
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--box", nargs="+", required=True, help="box-average files, one per case")
    ap.add_argument("--avalanches", nargs="+", help="avalanche CSV of each case (selects the flowing periods)")
    ap.add_argument("--phi", type=float, nargs="+", help="sphere volume fraction of each case")
    ap.add_argument("--labels", nargs="+")
    ap.add_argument("--out", default=".")
    ap.add_argument("--no-plots", action="store_true")
    a = ap.parse_args(argv)
    n = len(a.box)
    for opt in ("avalanches", "phi", "labels"):
        v = getattr(a, opt)
        if v is not None and len(v) != n:
            sys.exit(f"silo_box_analysis.py: {len(v)} values of --{opt} for {n} box files")
    cases = []
    for k, path in enumerate(a.box):
        try:
            d = read_box(path)
            aval = read_avalanches(a.avalanches[k]) if a.avalanches else None
            if aval is not None and ("t_start" not in aval or "t_end" not in aval):
                raise CsvError(f"{a.avalanches[k]}: the columns t_start and t_end are missing")
        except CsvError as e:
            sys.exit(f"silo_box_analysis.py: {e}")
        q = derived(d)
        keep, which = flowing_rows(d, aval)
        phi = a.phi[k] if a.phi else float("nan")
        label = a.labels[k] if a.labels else (f"phi={phi:g}" if a.phi else os.path.basename(path))
        s = summarise(q, keep, which)
        s.update({"label": label, "phi_spheres": phi})
        cases.append((s, d, q, keep))
        if s["rows"] == 0:
            print(f"silo_box_analysis.py: warning: {path}: no flowing rows", file=sys.stderr)

    cols = ["label", "phi_spheres", "rows", "avalanches"] + [c for q in QUANTITIES for c in (q, q + "_se")]
    print(f"{'case':>12} {'rows':>5} {'aval':>4} {'<phi>':>16} {'<k_te> [J]':>22} {'<k_re> [J]':>22} "
          f"{'<theta> [deg]':>16}")
    for s, *_ in cases:
        print(f"{s['label']:>12} {s['rows']:>5d} {s['avalanches']:>4d} {s['phi']:>7.4f} +- {s['phi_se']:<6.4f} "
              f"{s['k_te']:>10.4g} +- {s['k_te_se']:<8.2g} {s['k_re']:>10.4g} +- {s['k_re_se']:<8.2g} "
              f"{s['theta_deg']:>6.2f} +- {s['theta_deg_se']:<5.2f}")
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "box_stats.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for s, *_ in cases:
            w.writerow([s[c] if isinstance(s[c], str) else f"{s[c]:.8g}" for c in cols])
    if a.no_plots:
        return

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    have_phi = a.phi is not None
    x = a.phi if have_phi else list(range(n))
    titles = {"phi": "<phi_t> (box)", "k_te": "<k_te> per body [J]", "k_re": "<k_re> per body [J]",
              "theta_deg": "<theta> from vertical [deg]"}
    fig, axes = plt.subplots(2, 2, figsize=(9, 7))
    for ax, name in zip(axes.flat, titles):
        ax.errorbar(x, [s[name] for s, *_ in cases], yerr=[s[name + "_se"] for s, *_ in cases], fmt="o-", capsize=3)
        if name == "phi" and any(np.isfinite(s["phi_c"]) for s, *_ in cases):
            ax.errorbar(x, [s["phi_c"] for s, *_ in cases], yerr=[s["phi_c_se"] for s, *_ in cases], fmt="s--",
                        capsize=3, label="cylinders")
            ax.legend(["total", "cylinders"], fontsize=8)
        ax.set_ylabel(titles[name])
        ax.set_xlabel("sphere volume fraction phi" if have_phi else "case")
        if not have_phi:
            ax.set_xticks(x)
            ax.set_xticklabels([s["label"] for s, *_ in cases])
    fig.suptitle("Box above the exit, averaged over the flowing periods")
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "box_vs_phi.png"), dpi=120)
    plt.close(fig)

    fig, axes = plt.subplots(4, 1, figsize=(8, 9), sharex=True)
    for s, d, q, keep in cases:
        for ax, name in zip(axes, titles):
            line, = ax.plot(d["time"], q[name], "-", lw=0.8, label=s["label"])
            ax.plot(d["time"][keep], q[name][keep], ".", ms=3, color=line.get_color())
            ax.set_ylabel(titles[name], fontsize=8)
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("time [s] (dots: flowing rows)")
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "box_timeseries.png"), dpi=120)
    plt.close(fig)
    print(f"wrote {a.out}/box_stats.csv, box_vs_phi.png, box_timeseries.png")


if __name__ == "__main__":
    main()
