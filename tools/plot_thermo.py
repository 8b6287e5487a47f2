#!/usr/bin/python3
"""Plot thermo columns of a Granary or LIGGGHTS log file against the step.

Usage: tools/plot_thermo.py LOG [--out FILE.png] [--columns KinEng c_rke ...] [--log-y]

Reads every thermo table in the log (a header line of column names starting
with "Step", rows of numbers, ended by a "Loop time" line) and draws one panel
per column. Uses only numpy and matplotlib (Debian's python3-matplotlib).
"""
import argparse
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_thermo(path):
    """Return (column names, rows as a 2-D array) of all thermo tables in a log."""
    names, rows = None, []
    with open(path) as f:
        table = False
        for line in f:
            words = line.split()
            if words and words[0] == "Step":
                if names is not None and words != names:
                    raise SystemExit(f"{path}: thermo columns change between runs ({names} vs {words})")
                names, table = words, True
                continue
            if not table:
                continue
            if not words or line.startswith("Loop time"):
                table = False
                continue
            try:
                rows.append([float(w) for w in words])
            except ValueError:
                continue  # progress or warning lines between rows
    if names is None:
        raise SystemExit(f"{path}: no thermo table found (no line starting with 'Step')")
    rows = [r for r in rows if len(r) == len(names)]
    return names, np.array(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("log")
    ap.add_argument("--out", default="thermo.png")
    ap.add_argument("--columns", nargs="*", help="columns to plot (default: all but Step)")
    ap.add_argument("--log-y", action="store_true", help="logarithmic y axes")
    a = ap.parse_args()
    names, data = read_thermo(a.log)
    cols = a.columns or [n for n in names if n != "Step"]
    missing = [c for c in cols if c not in names]
    if missing:
        sys.exit(f"columns not in the log: {missing}; available: {names}")
    fig, axes = plt.subplots(len(cols), 1, figsize=(7, 2.4 * len(cols)), sharex=True, squeeze=False)
    step = data[:, names.index("Step")]
    for ax, c in zip(axes[:, 0], cols):
        y = data[:, names.index(c)]
        ax.plot(step, y, lw=1.2)
        ax.set_ylabel(c)
        if a.log_y and np.all(y > 0):
            ax.set_yscale("log")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("Step")
    fig.suptitle(a.log)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
