#!/usr/bin/python3
"""Statistics and figures of the silo clogging study from its committed results.

Reads DATA/<case>/avalanches.csv and box.csv (written by tools/silo_study.py)
for every case r<r>_phi<phi>[_n<nres>][_coh<kcoh>] and writes to OUT:
  summary.json              every number below, per case
  summary.md                the tables of doc/silo_study.md
  mean_avalanche.png        <S>/<S0> against phi for each size ratio, 95 % CIs (the paper's Fig. 6b)
  distributions.png         P(S/<S>) per case with the exponential exp(-x) (Fig. 7b)
  box.png                   <phi_t>, <k_te>/<k_te0>, <k_re>/<k_re0>, <theta> against phi (Fig. 8a, b)

    /usr/bin/python3 tools/silo_study_analysis.py [--data DIR] [--out DIR] [--keep-first]
                     [--bootstrap 4000] [--seed 1] [--complete 100] [--update-docs]

--update-docs also writes the tables into doc/silo_study.md (the block from
"| case | cycles | avalanches |" to "Columns: `bodies`") and the cost table
into examples/silo_study/README.md (through "In all ... core-hours so far.").

A case with fewer than --complete non-empty avalanches is analysed as it
stands and marked "(in progress)" in the tables ("complete": false in
summary.json).

Definitions:
  S         mass of an avalanche (kg), over the non-empty avalanches of all
            completed cycles that began at an arch removal; empty avalanches
            (an arch removal after which nothing passed) are counted apart.
            The first avalanche of every cycle begins at the opened shutter,
            from a freshly settled bed, and is left out (its mean is reported
            apart); --keep-first keeps it.
  <S>       mean, 95 % CI from the t-distribution and from a percentile
            bootstrap (B resamples, fixed seed).
  <S>/<S0>  ratio to the case phi = 0 with the same clump resolution; 95 % CI
            from the bootstrap of both means (percentile).
  exponential   the maximum-likelihood exponential has mean <S>; fit quality:
            the Kolmogorov-Smirnov distance D to it with a p-value from a
            parametric bootstrap (Lilliefors: the mean is estimated), and the
            coefficient of variation sd/mean (1 for an exponential); the same
            for the tail, the excesses S - s20 over the 20 % quantile s20
            (exponential above s20 if the sizes are exponential there).
  box       rows of box.csv whose averaging window lies inside an avalanche
            (t_start + window <= time <= t_end of the same cycle), averaged:
            phi_t = total solid fraction in the box, k_te = translational and
            k_re = rotational kinetic energy of the bodies in the box (J),
            theta = mean angle of the cylinders' long axes to the vertical (deg);
            CIs from the spread of the avalanche means (t-distribution).
  cylinders the mean number of cylinders (type 1 bodies) per non-empty avalanche, over that of
            phi = 0 with the same clump resolution, with a bootstrap CI: S is a mass and
            grows with the spheres' share of it even when as many cylinders pass.
  minimum   for each r (its complete cases) the phi with the smallest <S>/<S0>; its depth 1 - min,
            and one-sided Mann-Whitney p-values that S there is smaller than at
            phi = 0 and than at the largest phi; and the Kruskal-Wallis p-value
            that the sizes at every phi of that r (phi = 0 included) come from
            one distribution (a small p: <S> depends on phi somewhere).
Needs numpy, scipy and matplotlib.
"""
import argparse
import csv
import json
import math
import os
import re
import sys

import numpy as np
from scipy import stats

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from avalanche_stats import bootstrap_means, mean_ci_t  # noqa: E402
from silo_study import CASE_NAME, cost_markdown  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def read_table(path):
    """Dict column -> numpy array of a CSV with '#' comment lines."""
    with open(path, newline="") as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")]
    if not lines:
        raise ValueError(f"{path}: no header")
    header = [h.strip() for h in lines[0].split(",")]
    rows = [[float(x) for x in line.split(",")] for line in lines[1:]]
    data = np.array(rows, float).reshape(-1, len(header))
    return {h: data[:, k] for k, h in enumerate(header)}


def parse_case(name):
    """(r, phi, nres, kcoh) of a case name r<r>_phi<phi>[_n<nres>][_coh<kcoh>] (the driver's
    CASE_NAME), None for other names."""
    m = CASE_NAME.fullmatch(name)
    if not m:
        return None
    return float(m.group(1)), float(m.group(2)), int(m.group(3) or 10), float(m.group(4) or 0)


def phi0_case(summary, row):
    """The name of the phi = 0 case with the clump resolution of `row`, None when there is none."""
    return next((n for n, b in summary["cases"].items() if b["phi"] == 0 and b["nres"] == row["nres"]), None)


def is_main(row):
    """A case of the study's curves: 10-sphere clumps, no cohesion."""
    return row["nres"] == 10 and row.get("kcoh", 0) == 0


def is_candidate(row):
    """A case that tests a candidate cause: spheres, and another clump resolution or cohesion."""
    return row["phi"] > 0 and not is_main(row)


def cause(row):
    if row.get("kcoh", 0) > 0:
        return f"cohesion of the spheres (sjkr, {row['kcoh']:g} J/m^3)"
    return f"clump resolution ({row['nres']}-sphere clumps)"


def mean_ci(x):
    """(mean, half-width of its 95 % t interval)."""
    m, _, lo, hi = mean_ci_t(np.asarray(x, float))
    return m, (hi - m) if np.isfinite(hi) else float("nan")


def ks_exponential(x, B, rng):
    """KS distance to the exponential of the same mean and its Lilliefors p-value."""
    x = np.sort(np.asarray(x, float))
    n = len(x)
    if n < 5:
        return float("nan"), float("nan")

    def dist(s):
        s = np.sort(s)
        cdf = 1 - np.exp(-s / s.mean())
        i = np.arange(1, len(s) + 1)
        return max(np.max(i / len(s) - cdf), np.max(cdf - (i - 1) / len(s)))

    d = dist(x)
    sims = np.array([dist(rng.exponential(1.0, n)) for _ in range(B)])
    return float(d), float((np.sum(sims >= d) + 1) / (B + 1))


def load_case(d, keep_first):
    av = read_table(os.path.join(d, "avalanches.csv"))
    keep = np.ones(len(av["mass"]), bool)
    first = (av["avalanche"] == 1) & (av["bodies"] > 0)
    if not keep_first:
        keep &= av["avalanche"] > 1
    nonempty = keep & (av["bodies"] > 0)
    empty = keep & (av["bodies"] == 0)
    out = {"S": av["mass"][nonempty], "bodies": av["bodies"][nonempty], "n_empty": int(empty.sum()),
           "S_first": av["mass"][first],
           "arch_removed": av["arch_removed"][keep], "cycles": int(av["cycle"].max() + 1) if len(av["cycle"]) else 0,
           "types": {k: av[k][nonempty] for k in av if k.startswith("bodies_t") or k.startswith("mass_t")}}
    box_path = os.path.join(d, "box.csv")
    if os.path.exists(box_path):
        box = read_table(box_path)
        # the averaging window of a row: the time since the previous row of its cycle
        t = box["time"]
        window = np.full(len(t), np.nan)
        for c in np.unique(box["cycle"]):
            m = np.where(box["cycle"] == c)[0]
            if len(m) > 1:
                window[m[1:]] = np.diff(t[m])
                window[m[0]] = window[m[1]]
        per_av = {k: [] for k in ("phi", "k_te", "k_re", "theta", "sphere_share")}
        for i in np.where(keep & (av["bodies"] > 0))[0]:
            c, t0, t1 = av["cycle"][i], av["t_start"][i], av["t_end"][i]
            rows = (box["cycle"] == c) & (t - window >= t0 - 1e-9) & (t <= t1 + 1e-9) & (box["n_c"] > 0)
            if not rows.any():
                continue
            per_av["phi"].append(box["phi"][rows].mean())
            per_av["k_te"].append((box["ke_c"][rows] + box["ke_s"][rows]).mean())
            per_av["k_re"].append((box["erot_c"][rows] + box["erot_s"][rows]).mean())
            per_av["theta"].append(np.degrees(box["theta"][rows]).mean())
            # the spheres' share of the solid volume in the box
            per_av["sphere_share"].append((box["phi_s"][rows] / box["phi"][rows]).mean())
        out["box"] = {k: np.array(v) for k, v in per_av.items()}
    return out


def analyse(a):
    rng = np.random.default_rng(a.seed)
    cases = {}
    for name in sorted(os.listdir(a.data)):
        p = parse_case(name)
        if p and os.path.exists(os.path.join(a.data, name, "avalanches.csv")):
            cases[name] = (p, load_case(os.path.join(a.data, name), a.keep_first))
    if not cases:
        raise SystemExit(f"silo_study_analysis: no case with results in {a.data}")
    summary = {"keep_first": a.keep_first, "bootstrap": a.bootstrap, "cases": {}}
    boots = {}
    # the cases of the candidate causes after the others, so that adding one leaves the
    # bootstrap draws (and so the numbers) of the study's cases as they were
    order = sorted(cases, key=lambda n: is_candidate({"phi": cases[n][0][1], "nres": cases[n][0][2],
                                                        "kcoh": cases[n][0][3]}))
    for name in order:
        (r, phi, nres, kcoh), c = cases[name]
        S = c["S"]
        m, h = mean_ci(S)
        bm = bootstrap_means(S, rng, a.bootstrap) if len(S) > 1 else np.full(a.bootstrap, np.nan)
        boots[name] = bm
        d, p = ks_exponential(S, a.bootstrap // 4, rng)
        tail = S[S > np.quantile(S, 0.2)] - np.quantile(S, 0.2) if len(S) >= 10 else np.array([])
        dt_, pt_ = ks_exponential(tail, a.bootstrap // 4, rng) if len(tail) >= 5 else (float("nan"), float("nan"))
        row = {"r": r, "phi": phi, "nres": nres, **({"kcoh": kcoh} if kcoh > 0 else {}), "n": int(len(S)),
               "n_empty": c["n_empty"], "cycles": c["cycles"],
               "S_mean": m, "S_ci95_t": h, "S_ci95_boot": [float(np.nanpercentile(bm, 2.5)),
                                                       float(np.nanpercentile(bm, 97.5))],
               "bodies_mean": float(np.mean(c["bodies"])) if len(S) else float("nan"),
               "cv": float(np.std(S, ddof=1) / np.mean(S)) if len(S) > 1 else float("nan"),
               "ks_D": d, "ks_p": p, "tail_ks_D": dt_, "tail_ks_p": pt_,
               "tail_cv": float(np.std(tail, ddof=1) / np.mean(tail)) if len(tail) > 1 else float("nan"),
               "first_n": int(len(c["S_first"])),
               "first_S_mean": float(np.mean(c["S_first"])) if len(c["S_first"]) else float("nan"),
               "first_vs_rest_p": float(stats.mannwhitneyu(c["S_first"], S, alternative="two-sided").pvalue)
               if len(c["S_first"]) >= 3 and len(S) >= 3 else float("nan"),
               "arch_removed_mean": float(np.mean(c["arch_removed"])) if len(c["arch_removed"]) else float("nan")}
        if "box" in c and len(c["box"]["phi"]):
            for k, v in c["box"].items():
                mm, hh = mean_ci(v)
                row[f"box_{k}"] = mm
                row[f"box_{k}_ci95"] = hh
        # the spheres' (type 2) share of the discharged mass
        if "mass_t2" in c["types"] and np.sum(S) > 0:
            row["discharge_sphere_mass_share"] = float(np.sum(c["types"]["mass_t2"]) / np.sum(S))
        row["complete"] = bool(row["n"] >= a.complete)
        summary["cases"][name] = row
    summary["complete_at"] = a.complete
    # ratios to phi = 0 of the same clump resolution
    for name, row in summary["cases"].items():
        base = phi0_case(summary, row)
        if base is None:
            continue
        ratio = boots[name] / boots[base]
        b = summary["cases"][base]
        row["ratio"] = row["S_mean"] / b["S_mean"]
        row["ratio_ci95"] = [float(np.nanpercentile(ratio, 2.5)), float(np.nanpercentile(ratio, 97.5))]
        for k in ("k_te", "k_re"):
            if f"box_{k}" in row and f"box_{k}" in b:
                row[f"box_{k}_ratio"] = row[f"box_{k}"] / b[f"box_{k}"]
                rel = math.hypot(row[f"box_{k}_ci95"] / row[f"box_{k}"], b[f"box_{k}_ci95"] / b[f"box_{k}"])
                row[f"box_{k}_ratio_ci95"] = row[f"box_{k}_ratio"] * rel
    # the minimum of <S>/<S0> per size ratio
    summary["minimum"] = {}
    for r in sorted({row["r"] for row in summary["cases"].values() if row["phi"] > 0 and is_main(row)}):
        # complete cases only (one short of its avalanches is provisional)
        names = [n for n, row in summary["cases"].items()
                 if is_main(row) and (row["r"] == r or row["phi"] == 0) and row["complete"]]
        names.sort(key=lambda n: summary["cases"][n]["phi"])
        rows = [summary["cases"][n] for n in names]
        if not rows or rows[0]["phi"] != 0 or len(rows) < 3:
            continue
        k = int(np.argmin([x["S_mean"] for x in rows]))
        best, base, last = names[k], names[0], names[-1]
        S = {n: cases[n][1]["S"] for n in (best, base, last)}
        res = {"phi_min": rows[k]["phi"], "ratio_min": rows[k].get("ratio", 1.0),
               "ratio_min_ci95": rows[k].get("ratio_ci95"), "depth": 1 - rows[k].get("ratio", 1.0)}
        if best != base:
            res["p_below_phi0"] = float(stats.mannwhitneyu(S[best], S[base], alternative="less").pvalue)
        if best != last:
            res["p_below_last"] = float(stats.mannwhitneyu(S[best], S[last], alternative="less").pvalue)
            res["phi_last"] = rows[-1]["phi"]
        res["n_phi"] = len(names)
        res["p_all_alike"] = float(stats.kruskal(*[cases[n][1]["S"] for n in names]).pvalue)
        summary["minimum"][f"{r:g}"] = res
    # cylinders per avalanche against phi = 0 of the same clump resolution: S is a mass (the paper's
    # measure) and grows with the spheres' share of it even when as many cylinders pass; the
    # cylinders alone say whether the cylinders clog sooner or later. Own bootstrap draws (seed + 2),
    # made in the order above, so that they leave the other numbers, and the study's cases'
    # values when candidate cases are added, as they were.
    rng_cyl = np.random.default_rng(a.seed + 2)
    cyl_boot = {}
    for name in order:
        t1 = cases[name][1]["types"].get("bodies_t1")
        if t1 is not None and len(t1) > 1:
            cyl_boot[name] = (float(np.mean(t1)), bootstrap_means(t1, rng_cyl, a.bootstrap))
    for name, row in summary["cases"].items():
        base = phi0_case(summary, row)
        if row["phi"] == 0 or base is None or name not in cyl_boot or base not in cyl_boot:
            continue
        row["cylinders_mean"] = cyl_boot[name][0]
        row["cyl_ratio"] = cyl_boot[name][0] / cyl_boot[base][0]
        cr = cyl_boot[name][1] / cyl_boot[base][1]
        row["cyl_ratio_ci95"] = [float(np.nanpercentile(cr, 2.5)), float(np.nanpercentile(cr, 97.5))]
    # each candidate cause against the study's case of the same r and phi: its <S>/<S0> (with the
    # <S0> of its own clump resolution), the change of <S>/<S0> it makes with a bootstrap CI and a
    # two-sided bootstrap p-value that it makes none, and the bootstrap share of <S>/<S0> < 1 (the
    # paper's experiments at r = 4.6 have <S>/<S0> below 1 over a range of phi)
    summary["candidates"] = {}
    for name, row in summary["cases"].items():
        if not is_candidate(row) or "ratio" not in row:
            continue
        base = next((n for n, b in summary["cases"].items()
                     if is_main(b) and b["phi"] == row["phi"] and b["r"] == row["r"] and "ratio" in b), None)
        if base is None:
            continue
        s0 = {x: phi0_case(summary, summary["cases"][x]) for x in (name, base)}
        rc = boots[name] / boots[s0[name]]
        rb = boots[base] / boots[s0[base]]
        change = rc / rb
        below = float(np.nanmean(change < 1))
        summary["candidates"][name] = {
            "cause": cause(row), "baseline": base, "ratio": row["ratio"], "ratio_ci95": row["ratio_ci95"],
            "baseline_ratio": summary["cases"][base]["ratio"], "change": row["ratio"] / summary["cases"][base]["ratio"],
            "change_ci95": [float(np.nanpercentile(change, 2.5)), float(np.nanpercentile(change, 97.5))],
            "p_no_change": float(min(1.0, max(2 * min(below, 1 - below), 1.0 / len(change)))),
            "share_below_1": float(np.nanmean(rc < 1)), "n": row["n"], "complete": row["complete"]}
    return cases, summary


def write_outputs(a, cases, summary):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
    rs = sorted({row["r"] for row in summary["cases"].values() if row["phi"] > 0 and is_main(row)})
    colors = {1.6: "tab:green", 3.2: "tab:blue", 4.6: "tab:red"}

    def series(r, key, nres=10):
        rows = sorted([row for row in summary["cases"].values() if row["nres"] == nres and row.get("kcoh", 0) == 0
                       and (row["r"] == r or row["phi"] == 0) and key in row], key=lambda x: x["phi"])
        return rows

    # <S>/<S0> (Fig. 6b)
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for j, r in enumerate(rs):
        # complete cases joined by a line; cases in progress (from 20 avalanches) as open markers
        for done in (True, False):
            rows = [row for row in series(r, "ratio") if row["complete"] == done and (done or row["n"] >= 20)]
            if not rows:
                continue
            x = np.array([row["phi"] for row in rows]) + (j - 1) * 0.0012
            y = np.array([row["ratio"] for row in rows])
            lo = y - np.array([row["ratio_ci95"][0] for row in rows])
            hi = np.array([row["ratio_ci95"][1] for row in rows]) - y
            ax.errorbar(x, y, yerr=[lo, hi], marker="o", capsize=3, color=colors.get(r), ls="-" if done else "none",
                        mfc=None if done else "white", alpha=1.0 if done else 0.6,
                        label=f"r = {r:g}" + ("" if done else f" (in progress, {min(x['n'] for x in rows)}+ aval.)"))
    for k, row in enumerate(c for c in summary["cases"].values() if not is_main(c) and "ratio" in c):
        ci = row["ratio_ci95"] if row["phi"] > 0 else [row["ratio"]] * 2
        ax.errorbar([row["phi"] + 0.0024 * (k % 2 + 1)], [row["ratio"]],
                    yerr=[[row["ratio"] - ci[0]], [ci[1] - row["ratio"]]], marker="sD"[k % 2], color="k",
                    mfc="none" if row.get("kcoh", 0) > 0 else "k", capsize=3, ls="none",
                    label=f"{cause(row)}, r = {row['r']:g}, phi = {row['phi']:g}" if row["phi"] > 0 else
                    f"{row['nres']}-sphere clumps, phi = 0")
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set_xlabel("sphere volume fraction phi")
    ax.set_ylabel("<S>/<S0>")
    ax.set_title("Mean avalanche size (95 % CI)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "mean_avalanche.png"), dpi=130)
    plt.close(fig)

    # P(S/<S>) (Fig. 7b)
    ncol = max(1, len(rs))
    fig, axes = plt.subplots(1, ncol, figsize=(4.2 * ncol, 3.8), squeeze=False)
    for ax, r in zip(axes[0], rs or [0]):
        names = sorted([n for n, ((rr, phi, nres, kcoh), _) in cases.items()
                        if nres == 10 and kcoh == 0 and (rr == r or phi == 0)],
                       key=lambda n: cases[n][0][1])
        cmap = plt.get_cmap("viridis", max(2, len(names)))
        for k, n in enumerate(names):
            S = cases[n][1]["S"]
            if len(S) < 5:
                continue
            x = S / S.mean()
            bins = np.linspace(0, max(4.0, x.max()), 12)
            h, e = np.histogram(x, bins=bins, density=True)
            c = 0.5 * (e[1:] + e[:-1])
            ax.semilogy(c[h > 0], h[h > 0], "o", ms=4, color=cmap(k), label=f"phi = {cases[n][0][1]:g}")
        xx = np.linspace(0, 6, 50)
        ax.semilogy(xx, np.exp(-xx), "k--", lw=1, label="exp(-x)")
        ax.set_xlabel("S/<S>")
        ax.set_ylabel("P(S/<S>)")
        ax.set_title(f"r = {r:g}" if r else "phi = 0 (cylinders only)")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "distributions.png"), dpi=130)
    plt.close(fig)

    # box quantities (Fig. 8a, b)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.9))
    for r in rs:
        rows = series(r, "box_phi")
        phi = [row["phi"] for row in rows]
        axes[0].errorbar(phi, [row["box_phi"] for row in rows], yerr=[row["box_phi_ci95"] for row in rows],
                         marker="s", capsize=3, color=colors.get(r), label=f"r = {r:g}")
        rows_k = series(r, "box_k_te_ratio")
        axes[1].errorbar([row["phi"] for row in rows_k], [row["box_k_te_ratio"] for row in rows_k],
                         yerr=[row["box_k_te_ratio_ci95"] for row in rows_k], marker="D", capsize=3,
                         color=colors.get(r), label=f"k_te, r = {r:g}")
        axes[1].errorbar([row["phi"] for row in rows_k], [row["box_k_re_ratio"] for row in rows_k],
                         yerr=[row["box_k_re_ratio_ci95"] for row in rows_k], marker="o", ls="--", capsize=3,
                         color=colors.get(r), mfc="none", label=f"k_re, r = {r:g}")
        axes[2].errorbar(phi, [row["box_theta"] for row in rows], yerr=[row["box_theta_ci95"] for row in rows],
                         marker="^", capsize=3, color=colors.get(r), label=f"r = {r:g}")
    axes[0].set_ylabel("<phi_t> in the box")
    axes[1].set_ylabel("<k_te>/<k_te0>, <k_re>/<k_re0>")
    axes[2].set_ylabel("<theta> to the vertical (deg)")
    for ax in axes:
        ax.set_xlabel("sphere volume fraction phi")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "box.png"), dpi=130)
    plt.close(fig)

    # tables
    lines = ["| case | cycles | avalanches | empty | <S> (g) | 95 % CI (g) | bodies | <S>/<S0> | 95 % CI | "
             "sd/mean | KS p | tail sd/mean | tail KS p | arch bodies | first of cycle (g) | p first |",
             "|---|---:|---:|---:|---:|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|"]
    for n, row in sorted(summary["cases"].items(), key=lambda kv: (kv[1]["nres"], kv[1]["r"] if kv[1]["phi"] else 0,
                                                                    kv[1]["phi"])):
        ci = row["S_ci95_boot"]
        rc = row.get("ratio_ci95")
        lines.append(f"| {n}{'' if row['complete'] else ' (in progress)'} | {row['cycles']} | {row['n']} | {row['n_empty']} | {1e3 * row['S_mean']:.3g} | "
                     f"{1e3 * ci[0]:.3g} - {1e3 * ci[1]:.3g} | {row['bodies_mean']:.1f} | "
                     f"{row.get('ratio', float('nan')):.3f} | "
                     f"{'' if rc is None else f'{rc[0]:.3f} - {rc[1]:.3f}'} | {row['cv']:.2f} | {row['ks_p']:.3f} | "
                     f"{row['tail_cv']:.2f} | {row['tail_ks_p']:.3f} | {row['arch_removed_mean']:.1f} | "
                     f"{1e3 * row['first_S_mean']:.3g} | {row['first_vs_rest_p']:.2g} |")
    lines += ["", "| case | <phi_t> | <k_te>/<k_te0> | <k_re>/<k_re0> | <theta> (deg) |", "|---|---:|---:|---:|---:|"]
    for n, row in sorted(summary["cases"].items(), key=lambda kv: (kv[1]["nres"], kv[1]["r"] if kv[1]["phi"] else 0,
                                                                    kv[1]["phi"])):
        if "box_phi" not in row:
            continue
        lines.append(f"| {n}{'' if row['complete'] else ' (in progress)'} | {row['box_phi']:.4f} ± {row['box_phi_ci95']:.4f} | "
                     f"{row.get('box_k_te_ratio', float('nan')):.3f} ± {row.get('box_k_te_ratio_ci95', float('nan')):.3f} | "
                     f"{row.get('box_k_re_ratio', float('nan')):.3f} ± {row.get('box_k_re_ratio_ci95', float('nan')):.3f} | "
                     f"{row['box_theta']:.2f} ± {row['box_theta_ci95']:.2f} |")
    lines += ["", "| case | phi (filled) | spheres' share of the solids in the box | spheres' share of the discharged mass "
              "| cylinders per avalanche / phi = 0's | 95 % CI |",
              "|---|---:|---:|---:|---:|---|"]
    for n, row in sorted(summary["cases"].items(), key=lambda kv: (kv[1]["nres"], kv[1]["r"] if kv[1]["phi"] else 0,
                                                                    kv[1]["phi"])):
        if row["phi"] == 0 or "box_sphere_share" not in row:
            continue
        lines.append(f"| {n}{'' if row['complete'] else ' (in progress)'} | {row['phi']:g} | "
                     f"{row['box_sphere_share']:.4f} ± {row['box_sphere_share_ci95']:.4f} | "
                     f"{row.get('discharge_sphere_mass_share', float('nan')):.4f} | "
                     f"{row.get('cyl_ratio', float('nan')):.3f} | "
                     + (f"{row['cyl_ratio_ci95'][0]:.3f} - {row['cyl_ratio_ci95'][1]:.3f} |" if "cyl_ratio_ci95" in row
                        else " |"))
    lines += ["", "| r | phi at the minimum | <S>/<S0> there | 95 % CI | p (below phi = 0) | p (below the last phi) "
              "| phi values | p (all phi alike) |",
              "|---|---:|---:|---|---:|---:|---:|---:|"]
    for r, m in summary["minimum"].items():
        ci = m.get("ratio_min_ci95") or [float("nan")] * 2
        lines.append(f"| {r} | {m['phi_min']:g} | {m['ratio_min']:.3f} | {ci[0]:.3f} - {ci[1]:.3f} | "
                     f"{m.get('p_below_phi0', float('nan')):.2g} | {m.get('p_below_last', float('nan')):.2g} | "
                     f"{m['n_phi']} | {m['p_all_alike']:.2g} |")
    if summary["candidates"]:
        lines += ["", "| candidate cause | case | baseline | <S>/<S0> | 95 % CI | baseline's <S>/<S0> | change | "
                  "95 % CI | p (no change) | P(<S>/<S0> < 1) |", "|---|---|---|---:|---|---:|---:|---|---:|---:|"]
        for n, c in sorted(summary["candidates"].items()):
            lines.append(f"| {c['cause']} | {n}{'' if c['complete'] else ' (in progress)'} | {c['baseline']} | "
                         f"{c['ratio']:.3f} | {c['ratio_ci95'][0]:.3f} - {c['ratio_ci95'][1]:.3f} | "
                         f"{c['baseline_ratio']:.3f} | {c['change']:.3f} | {c['change_ci95'][0]:.3f} - "
                         f"{c['change_ci95'][1]:.3f} | {c['p_no_change']:.2g} | {c['share_below_1']:.2f} |")
    with open(os.path.join(a.out, "summary.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def _with_block(path, content, start, end, text):
    """`content` (of the file `path`) with the lines from the first that
    begins with `start` up to (not including) the next line for which
    `end(line)` holds replaced by `text`; exits naming the file when the
    block is not found."""
    lines = content.split("\n")
    i = next((k for k, ln in enumerate(lines) if ln.startswith(start)), None)
    j = next((k for k in range(i + 1, len(lines)) if end(lines[k])), None) if i is not None else None
    if i is None or j is None:
        raise SystemExit(f"{path}: the block beginning '{start}' was not found whole; restore the file "
                         "(git checkout) and run again")
    lines[i:j] = (text[:-1] if text.endswith("\n") else text).split("\n")
    return "\n".join(lines)


def _write_whole(path, content):
    """Write `path` as a whole: a temporary file renamed over it."""
    with open(path + ".tmp", "w") as f:
        f.write(content)
    os.replace(path + ".tmp", path)


def replace_block(path, start, end, text):
    """Replace in the file `path` the block of _with_block by `text`; the
    file is written only when whole. Exits naming the file when the block is
    not found (the file is then untouched)."""
    with open(path) as f:
        content = f.read()
    _write_whole(path, _with_block(path, content, start, end, text))


def update_docs(a):
    """The tables of doc/silo_study.md (summary.md) and the cost table of
    examples/silo_study/README.md (tools/silo_study.py status --markdown),
    from the committed results. The prose around them (status, claims, cost
    figures in sentences) is left to the author."""
    with open(os.path.join(a.out, "summary.md")) as f:
        summary_md = f.read()
    doc = os.path.join(ROOT, "doc", "silo_study.md")
    replace_block(doc, "| case | cycles | avalanches |", lambda ln: ln.startswith("Columns: `bodies`"),
                  summary_md.rstrip("\n") + "\n\n")
    readme = os.path.join(ROOT, "examples", "silo_study", "README.md")
    table, total = cost_markdown(a.data, a.complete)
    with open(readme) as f:
        text = _with_block(readme, f.read(), "| case | cycles | non-empty avalanches |", lambda ln: not ln.strip(),
                           table)
    text, n = re.subn(r"In all [0-9.]+ core-hours so far\.", f"In all {total:.2f} core-hours so far.", text)
    if n != 1:
        raise SystemExit(f"{readme}: expected one sentence 'In all ... core-hours so far.', found {n}")
    _write_whole(readme, text)
    print(f"updated the tables of {doc} and {readme}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default=os.path.join(ROOT, "examples", "silo_study", "results"))
    ap.add_argument("--out", default=os.path.join(ROOT, "doc", "images", "silo_study"))
    ap.add_argument("--keep-first", action="store_true",
                    help="keep the first avalanche of every cycle (it begins at the opened shutter)")
    ap.add_argument("--bootstrap", type=int, default=4000)
    ap.add_argument("--complete", type=int, default=100,
                    help="non-empty avalanches that complete a case; fewer: marked '(in progress)' (default 100)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--update-docs", action="store_true",
                    help="also write the tables into doc/silo_study.md and the cost table into "
                         "examples/silo_study/README.md")
    a = ap.parse_args(argv)
    cases, summary = analyse(a)
    write_outputs(a, cases, summary)
    if a.update_docs:
        update_docs(a)
    return 0


if __name__ == "__main__":
    sys.exit(main())
