#!/usr/bin/python3
"""Hidden-effect tests of the discrepancy workflow (tools/discrepancy).

Each case makes 'measured' data with Granary itself: the baseline model of an
example under examples/discrepancy with one mechanism switched on whose
parameter is drawn from a seeded generator, plus Gaussian noise of the stated
uncertainty (experimental scatter). The workflow gets only the data, the
baseline and the catalogue of candidates, and must
  - name the hidden mechanism,
  - recover its parameter within the stated relative tolerance,
  - report a held-out gain (baseline error / extended model error) above the
    stated factor.
The null case hides nothing and must report 'no significant discrepancy'.

The null case also checks the outputs of the command: report.md (which must
say so), report.json and the PNG plot.

The extractors case checks the heap angle-of-repose extractor on synthetic
cones (no granary run).

usage: test_discrepancy.py CASE GRANARY SOURCE_DIR   (CASE: viscoelastic,
cohesion, rolling, tangential, clumpres, null, extractors)
"""
import csv
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

CASES = {
    # name: example directory, hidden settings, hidden parameter (name, var,
    # log-uniform range), conditions, noise, candidate expected, tolerances
    "viscoelastic": {
        "example": "restitution", "condition": "speed",
        "levels": list(np.geomspace(0.05, 5.0, 12)),
        "hidden_set": {"damping": "viscoelastic"},
        "hidden_param": ("A", 3e-6, 1.5e-5),
        "fixed": {},
        "observable": "restitution", "sigma": 0.005,
        "expect": "viscoelastic damping", "param_tol": 0.15, "min_gain": 3.0, "seed": 11},
    "cohesion": {
        "example": "restitution", "condition": "speed",
        "levels": list(np.geomspace(0.01, 1.0, 12)),
        "hidden_set": {"cohesion": "sjkr"},
        "hidden_param": ("kcoh", 1e5, 4e5),
        "fixed": {"e": 0.8},
        "observable": "restitution", "sigma": 0.01,
        "expect": "cohesion sjkr", "param_tol": 0.15, "min_gain": 3.0, "seed": 12},
    "rolling": {
        "example": "rolling", "condition": "v0",
        "levels": list(np.linspace(0.1, 1.0, 10)),
        "hidden_set": {"rolling": "cdt"},
        "hidden_param": ("mur", 0.03, 0.08),
        "fixed": {},
        "observable": "distance", "sigma": 0.002,
        "expect": "rolling friction cdt", "param_tol": 0.10, "min_gain": 3.0, "seed": 13},
    "tangential": {
        "example": "oblique_impact", "condition": "incidence_deg",
        "levels": [5.0, 10.0, 17.0, 25.0, 35.0, 45.0, 60.0, 75.0],
        "hidden_set": {"tangential": "history"},
        "hidden_param": ("mu", 0.08, 0.25),
        "fixed": {},
        "observables": {"et": 0.02, "omega": 15.0, "rebound": 1.0},
        "candidates": ["tangential history", "rolling friction cdt", "viscoelastic damping"],
        "expect": "tangential history", "param_tol": 0.10, "min_gain": 3.0, "seed": 15},
    "clumpres": {
        # Bed of cylinder clumps: the data come from clumps of 50 spheres, the
        # baseline has 10; the candidate changes the clump file among the four
        # that exist (a choice parameter), and must find 50 exactly.
        "example": "clump_bed", "condition": "mu",
        "levels": list(np.linspace(0.2, 1.0, 6)),
        "hidden_set": {},
        "hidden_param": ("nres", 50.0, 50.0),
        "fixed": {},
        "observable": "bed_height", "sigma": 0.05,
        # the example's rolling friction has a continuous mur, whose fit costs
        # 20-40 runs per training condition; here it is tried at four values
        "candidates": ["clump shape resolution", "rolling friction cdt"],
        "choices": {"mur": [0.05, 0.1, 0.2, 0.3]},
        "expect": "clump shape resolution", "param_tol": 0.0, "min_gain": 5.0, "seed": 16},
    "null": {
        "example": "restitution", "condition": "speed",
        "levels": list(np.geomspace(0.05, 5.0, 12)),
        "hidden_set": {},
        "hidden_param": ("e", 0.7, 0.9),
        "fixed": {},
        "observable": "restitution", "sigma": 0.005,
        "expect": None, "seed": 14},
}


def make_data(case, tools, granary, src, path):
    sys.path.insert(0, tools)
    from discrepancy_lib import inputs, runner
    c = CASES[case]
    model = inputs.Model(os.path.join(src, "examples", "discrepancy", c["example"], "model.json"))
    rng = np.random.default_rng(c["seed"])
    name, lo, hi = c["hidden_param"]
    true = lo if lo == hi else float(np.exp(rng.uniform(np.log(lo), np.log(hi))))
    settings = []
    cvar = model.conditions[c["condition"]]
    for level in c["levels"]:
        s = dict(model.set)
        s.update(c["fixed"])
        s.update(c["hidden_set"])
        s[name] = true
        s[cvar] = float(level)
        settings.append(s)
    res = runner.Runner(granary, model, jobs=2).run_many(settings)
    observables = c.get("observables", {c.get("observable"): c.get("sigma")})
    with open(path, "w", newline="") as f:
        f.write(f"# synthetic: {case}, hidden {c['hidden_set']} {name} = {true:.6g}, noise sigma {observables}\n")
        w = csv.writer(f)
        w.writerow([c["condition"], "observable", "value", "uncertainty"])
        for obs, sigma in observables.items():
            key = model.key_of(obs)
            for level, r in zip(c["levels"], res):
                w.writerow([f"{level:.6g}", obs, f"{r[key] + rng.normal(0, sigma):.6g}", sigma])
    return true, model


def check_extractors(tools):
    """heap_angle on a synthetic heap: spheres of radius 1 mm filling a cone
    of known slope on z = 0 (a hexagonal-ish random fill), plus a rounded apex
    and a spread-out foot that the central-region fit must ignore. The fitted
    angle must be within 1.5 degrees of the cone's (sphere tops follow the
    surface to within a radius, which over the fitted span of ~10 radii is
    about a degree)."""
    sys.path.insert(0, tools)
    from discrepancy_lib import extractors
    rng = np.random.default_rng(5)
    failures = []
    for angle in (20.0, 30.0, 35.0):
        R, r = 0.03, 0.001
        t = np.tan(np.radians(angle))
        pts = []
        for _ in range(40000):
            x, y = rng.uniform(-R, R, 2)
            rho = np.hypot(x, y)
            if rho > R:
                continue
            top = (R - rho) * t
            top = min(top, 0.8 * R * t)  # flattened apex
            z = rng.uniform(r, max(top - r, r) + 1e-12)
            pts.append((x, y, z))
        # the free surface layer: spheres touching the cone surface
        for _ in range(4000):
            rho, phi = rng.uniform(0, R), rng.uniform(0, 2 * np.pi)
            top = min((R - rho) * t, 0.8 * R * t)
            pts.append((rho * np.cos(phi), rho * np.sin(phi), max(top - r, r)))
        # a few spheres rolled away beyond the foot
        for _ in range(50):
            rho, phi = rng.uniform(R, 1.15 * R), rng.uniform(0, 2 * np.pi)
            pts.append((rho * np.cos(phi), rho * np.sin(phi), r))
        with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
            f.write(f"ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n{len(pts)}\n"
                    "ITEM: BOX BOUNDS mm mm mm\n-1 1\n-1 1\n0 1\nITEM: ATOMS id x y z radius\n")
            for k, (x, y, z) in enumerate(pts):
                f.write(f"{k + 1} {x} {y} {z} {r}\n")
            path = f.name
        got, nring = extractors.heap_angle(path)
        os.unlink(path)
        print(f"  heap_angle: cone {angle} deg -> {got:.2f} deg ({nring} rings)")
        if not abs(got - angle) < 1.5:
            failures.append(f"heap_angle {got:.2f} for a {angle} degree cone")
    return failures


def main():
    case, granary, src = sys.argv[1], sys.argv[2], sys.argv[3]
    tools = os.path.join(src, "tools")
    if case == "extractors":
        failures = check_extractors(tools)
        for msg in failures:
            print("FAIL:", msg)
        return 1 if failures else 0
    cli = case == "null"
    c = CASES[case]
    failures = []
    with tempfile.TemporaryDirectory(prefix="test_discrepancy_") as tmp:
        data_path = os.path.join(tmp, "data.csv")
        true, model = make_data(case, tools, granary, src, data_path)
        ex = os.path.join(src, "examples", "discrepancy", c["example"])
        cand_path = os.path.join(ex, "candidates.json")
        if "candidates" in c:  # a subset of the example's catalogue, to keep the test short
            with open(cand_path) as f:
                cat = json.load(f)
            cat["candidates"] = [k for k in cat["candidates"] if k["name"] in c["candidates"]]
            for k in cat["candidates"]:  # continuous parameters tried at a few values only
                for prm in k.get("params", []):
                    if prm["name"] in c.get("choices", {}):
                        for key in ("lower", "upper", "scale", "initial"):
                            prm.pop(key, None)
                        prm["choices"] = c["choices"][prm["name"]]
            cand_path = os.path.join(tmp, "candidates.json")
            with open(cand_path, "w") as f:
                json.dump(cat, f)
        out = os.path.join(tmp, "report")
        cmd = ["/usr/bin/python3", os.path.join(tools, "discrepancy"), "--data", data_path,
               "--model", os.path.join(ex, "model.json"), "--candidates", cand_path,
               "--granary", granary, "--jobs", "2", "--seed", "3", "--out", out, "--quiet"]
        if not cli:
            cmd.append("--no-plots")
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            print(proc.stdout, proc.stderr)
            print("FAIL: tools/discrepancy exited with", proc.returncode)
            return 1
        with open(os.path.join(out, "report.json")) as f:
            rep = json.load(f)
        v = rep["verdict"]
        g = rep["baseline"]["goodness_of_fit"]
        print(f"case {case}: hidden {c['hidden_set']} {c['hidden_param'][0]} = {true:.5g}")
        print(f"  baseline chi2/dof {g['chi2_red']:.3g}, p = {g['p_value']:.3g}")
        print(f"  verdict: {v['status']}: {v['statement']}")
        if c["expect"] is None:
            if v["status"] != "no significant discrepancy":
                failures.append("null case: expected 'no significant discrepancy', got " + v["status"])
        else:
            if v.get("cause") != c["expect"]:
                failures.append(f"named {v.get('cause')!r}, expected {c['expect']!r}")
            best = rep["candidates"][0]
            pname = c["hidden_param"][0]
            fitted = [p for p in best["params"] if p["name"] == pname]
            if not fitted:
                failures.append(f"best candidate has no parameter {pname}")
            else:
                rel = abs(fitted[0]["value"] - true) / true
                err = fitted[0]["error"]  # None for a choice parameter
                prof = fitted[0].get("profile_chi2")
                print(f"  {pname}: fitted {fitted[0]['value']:.5g}" + (f" +- {err:.2g}" if err is not None else "") +
                      f", true {true:.5g}, relative error {rel:.3f} (tolerance {c['param_tol']})" +
                      (" training chi2 by choice: " + ", ".join(f"{x:g}: {y:.3g}" for x, y in prof) if prof else ""))
                if rel > c["param_tol"]:
                    failures.append(f"{pname} off by {rel:.3f} > {c['param_tol']}")
            gain = best["gain"]["ratio"]
            print(f"  gain {gain:.3g} (68% CI {best['gain']['ci68'][0]:.3g}-{best['gain']['ci68'][1]:.3g}),"
                  f" required > {c['min_gain']}")
            if gain < c["min_gain"]:
                failures.append(f"gain {gain:.3g} < {c['min_gain']}")
        if cli:
            for name in ("report.md", "report.json", "restitution.png"):
                if not os.path.exists(os.path.join(out, name)):
                    failures.append(f"missing output {name}")
            with open(os.path.join(out, "report.md")) as f:
                if "no significant discrepancy" not in f.read().lower():
                    failures.append("report.md does not say 'no significant discrepancy'")
        print(f"  {rep['runs']} granary runs, {rep['wall_time_s']:.1f} s")
    for msg in failures:
        print("FAIL:", msg)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
