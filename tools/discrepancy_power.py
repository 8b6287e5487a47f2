#!/usr/bin/python3
"""How often the discrepancy workflow (tools/discrepancy) names the right cause
at a realistic difficulty: hidden-effect data with the signal at a few times
the noise and a handful of points, several mechanisms, several seeds each, and
a null case that hides nothing.

For each case and seed:
  1. the hidden parameter is drawn (log-uniform in the case's range) and the
     example's baseline with the mechanism switched on is run at `--points`
     conditions: the noise-free 'measurement';
  2. the baseline is fitted to it (the workflow's own multi-start fit); its
     residuals are the part of the effect the baseline cannot absorb (the
     signal);
  3. the uncertainties are the case's nominal ones scaled so that the signal
     is `--signal` times the noise (root mean square of the residuals over
     the points, in uncertainties; 2.5 by default); the null case keeps the
     nominal uncertainties;
  4. Gaussian noise of those uncertainties is added and the whole workflow is
     run on the data, the baseline and the example's catalogue of candidates.
Each outcome is appended to the results file as one JSON line as soon as it is
known; a second run skips the case/seed pairs already there (resumable).
`--summary` prints the rate at which each hidden mechanism was named and how
often the null case named anything.

  tools/discrepancy_power.py --granary build/granary --out results.jsonl [--seeds 5] [--points 7]
  tools/discrepancy_power.py --summary results.jsonl
  tools/discrepancy_power.py --markdown results.jsonl
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)

# name: example, condition and its range (geometric or linear), hidden
# settings and parameter (name, log-uniform range), fixed settings, nominal
# uncertainty per observable, the candidates offered (None: the example's whole
# catalogue), the cause to be named (None: nothing).
CASES = {
    "viscoelastic": {
        "example": "restitution", "condition": "speed", "range": (0.05, 5.0, "geom"),
        "hidden_set": {"damping": "viscoelastic"}, "hidden_param": ("A", 3e-6, 1.5e-5), "fixed": {},
        "sigma": {"restitution": 0.005}, "candidates": None, "expect": "viscoelastic damping"},
    "cohesion": {
        "example": "restitution", "condition": "speed", "range": (0.01, 1.0, "geom"),
        "hidden_set": {"cohesion": "sjkr"}, "hidden_param": ("kcoh", 1e5, 4e5), "fixed": {"e": 0.8},
        "sigma": {"restitution": 0.01}, "candidates": None, "expect": "cohesion sjkr"},
    "rolling": {
        "example": "rolling", "condition": "v0", "range": (0.1, 1.0, "lin"),
        "hidden_set": {"rolling": "cdt"}, "hidden_param": ("mur", 0.03, 0.08), "fixed": {},
        "sigma": {"distance": 0.002}, "candidates": None, "expect": "rolling friction cdt"},
    # Mindlin-Deresiewicz partial slip becomes tangential history as the slip
    # threshold grows, so data made with history cannot tell them apart; it is
    # left out of this case's catalogue.
    "tangential": {
        "example": "oblique_impact", "condition": "incidence_deg", "range": (5.0, 75.0, "lin"),
        "hidden_set": {"tangential": "history"}, "hidden_param": ("mu", 0.08, 0.25), "fixed": {},
        "sigma": {"et": 0.02, "omega": 15.0, "rebound": 1.0},
        "candidates": ["tangential history", "rolling friction cdt", "rolling friction epsd2",
                       "viscoelastic damping", "cohesion sjkr"],
        "expect": "tangential history"},
    "null": {
        "example": "restitution", "condition": "speed", "range": (0.05, 5.0, "geom"),
        "hidden_set": {}, "hidden_param": ("e", 0.7, 0.9), "fixed": {},
        "sigma": {"restitution": 0.005}, "candidates": None, "expect": None},
}


def levels(case, n):
    lo, hi, kind = CASES[case]["range"]
    return list(np.geomspace(lo, hi, n) if kind == "geom" else np.linspace(lo, hi, n))


def make_data(case, seed, npoints, signal, granary, jobs, path):
    """Write the data file; return what was hidden and how strongly."""
    from discrepancy_lib import fitting, inputs, runner, synthetic
    c = CASES[case]
    ex = os.path.join(ROOT, "examples", "discrepancy", c["example"])
    model = inputs.Model(os.path.join(ex, "model.json"))
    rng = np.random.default_rng([seed, sorted(CASES).index(case)])
    name, lo, hi = c["hidden_param"]
    true = float(np.exp(rng.uniform(np.log(lo), np.log(hi))))
    lv = levels(case, npoints)
    run = runner.Runner(granary, model, jobs=jobs)
    res = run.run_many(synthetic.hidden_settings(model, c["condition"], lv, c["hidden_set"], name, true, c["fixed"]))
    rows = []
    for obs, sigma in c["sigma"].items():
        key = model.key_of(obs)
        for level, r in zip(lv, res):
            rows.append({"cond": (float(level),), "observable": obs, "value": float(r[key]), "sigma": sigma})
    scale = 1.0
    largest = 0.0
    if c["expect"] is not None:
        # the part of the effect the baseline cannot absorb, in nominal uncertainties
        data = inputs.Data([c["condition"]], rows, "noise-free")
        base = fitting.Variant(model.name, model, run, params=model.params)
        fit = fitting.fit(base, data, rows, seed=seed)
        pred = base.predict(fit["values"], data, rows)
        z = fitting.normalized_residuals(pred, rows)
        largest = float(np.max(np.abs(z)))
        scale = float(np.sqrt(np.mean(z * z))) / signal
    with open(path, "w", newline="") as f:
        f.write(f"# hidden-effect data: {case}, seed {seed}, hidden {c['hidden_set']} {name} = {true:.6g}; "
                f"uncertainties {scale:.4g} x nominal (the fitted baseline's residuals {signal} of them, rms)\n")
        w = csv.writer(f)
        w.writerow([c["condition"], "observable", "value", "uncertainty"])
        for r in rows:
            sigma = r["sigma"] * scale
            w.writerow([f"{r['cond'][0]:.6g}", r["observable"], f"{r['value'] + rng.normal(0, sigma):.8g}",
                        f"{sigma:.6g}"])
    return {"true": true, "param": name, "noise_scale": scale, "largest_residual_nominal": largest}


def run_one(case, seed, args):
    c = CASES[case]
    ex = os.path.join(ROOT, "examples", "discrepancy", c["example"])
    t0 = time.time()
    with tempfile.TemporaryDirectory(prefix="discrepancy_power_") as tmp:
        data_path = os.path.join(tmp, "data.csv")
        hidden = make_data(case, seed, args.points, args.signal, args.granary, args.jobs, data_path)
        cand_path = os.path.join(ex, "candidates.json")
        if c["candidates"] is not None:
            from discrepancy_lib import synthetic
            cand_path = synthetic.catalogue_subset(cand_path, c["candidates"], os.path.join(tmp, "candidates.json"))
        out = os.path.join(tmp, "report")
        cmd = ["/usr/bin/python3", os.path.join(HERE, "discrepancy"), "--data", data_path,
               "--model", os.path.join(ex, "model.json"), "--candidates", cand_path,
               "--granary", args.granary, "--jobs", str(args.jobs), "--seed", str(seed), "--out", out,
               "--quiet", "--no-plots"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"tools/discrepancy failed on {case} seed {seed}:\n{proc.stdout}\n{proc.stderr}")
        with open(os.path.join(out, "report.json")) as f:
            rep = json.load(f)
    v = rep["verdict"]
    best = rep["candidates"][0] if rep.get("candidates") else None
    rec = {"case": case, "seed": seed, "points": args.points, "signal": args.signal,
           "expect": c["expect"], "status": v["status"], "named": v.get("cause"), "statement": v["statement"],
           "correct": (v.get("cause") == c["expect"]) if c["expect"] else v["status"] == "no significant discrepancy",
           "baseline_chi2_red": rep["baseline"]["goodness_of_fit"]["chi2_red"],
           "baseline_p": rep["baseline"]["goodness_of_fit"]["p_value"],
           "best": best["name"] if best else None,
           "gain": best["gain"]["ratio"] if best and best.get("gain") else None,
           "stability": v.get("stability"), "runs": rep["runs"], "seconds": round(time.time() - t0, 1)}
    rec.update(hidden)
    if best and c["expect"]:
        fitted = [p for p in best["params"] if p["name"] == hidden["param"]]
        if fitted and best["name"] == c["expect"]:
            rec["fitted"] = fitted[0]["value"]
            rec["fitted_error"] = fitted[0]["error"]
    return rec


def load(path):
    """The records of a results file (none if it does not exist yet)."""
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def summary(path):
    """Print and return, per case, (right, seeds run)."""
    recs = load(path)
    print(f"{'case':14s} {'seeds':>5s} {'right':>5s}  named instead / outcome")
    out = {}
    for case in CASES:
        rs = [r for r in recs if r["case"] == case]
        if not rs:
            continue
        right = sum(r["correct"] for r in rs)
        other = [r["named"] or r["status"] for r in rs if not r["correct"]]
        out[case] = (right, len(rs))
        print(f"{case:14s} {len(rs):5d} {right:5d}  {', '.join(other) if other else '-'}")
    return out


def markdown(path):
    """A table of every record, for the documentation."""
    print("| case | seed | hidden (true) | baseline chi2/dof | outcome | named | gain | fitted | runs | s |")
    print("|---|---:|---|---:|---|---|---:|---:|---:|---:|")
    for r in load(path):
        fitted = f"{r['fitted']:.4g}" if r.get("fitted") is not None else "-"
        gain = f"{r['gain']:.2f}" if r.get("gain") is not None else "-"
        print(f"| {r['case']} | {r['seed']} | {r['param']} = {r['true']:.4g} | {r['baseline_chi2_red']:.2f} | "
              f"{r['status']} | {r['named'] or '-'} | {gain} | {fitted} | {r['runs']} | {r['seconds']:.0f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--granary", default=os.path.join(ROOT, "build", "granary"))
    ap.add_argument("--out", help="results file (JSON lines), appended to")
    ap.add_argument("--cases", default=",".join(CASES), help="comma-separated, from " + ", ".join(CASES))
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--points", type=int, default=7, help="conditions per data set")
    ap.add_argument("--signal", type=float, default=2.5,
                    help="signal to noise: the fitted baseline's residuals on the noise-free data, root "
                         "mean square in uncertainties")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--summary", metavar="RESULTS", help="print the rates of a results file and exit")
    ap.add_argument("--markdown", metavar="RESULTS", help="print every record of a results file as a table")
    args = ap.parse_args()
    if args.summary:
        summary(args.summary)
        return 0
    if args.markdown:
        markdown(args.markdown)
        return 0
    if not args.out:
        ap.error("--out is needed to run")
    args.granary = os.path.abspath(args.granary)
    cases = args.cases.split(",")
    for c in cases:
        if c not in CASES:
            ap.error(f"unknown case {c!r}; cases: {', '.join(CASES)}")
    done = {(r["case"], r["seed"], r["points"], r["signal"]) for r in load(args.out)}
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        for case in cases:
            if (case, seed, args.points, args.signal) in done:
                continue
            rec = run_one(case, seed, args)
            with open(args.out, "a") as f:
                f.write(json.dumps(rec) + "\n")
            print(f"{case} seed {seed}: {rec['status']}, named {rec['named']!r} "
                  f"({'right' if rec['correct'] else 'WRONG'}), {rec['seconds']} s", flush=True)
    summary(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
