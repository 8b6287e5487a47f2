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
The repose case hides the rolling friction of the sphere-sphere pair in the
angles of repose of heaps of three sphere sizes (two pours each); the
baseline's sliding friction is fitted along, and both must come out exactly
(choice parameters).
The null case hides nothing and must report 'no significant discrepancy'.

The null case also checks the outputs of the command: report.md (which must
say so), report.json and the PNG plot.

The extractors case checks the heap angle-of-repose extractor on synthetic
cones; the fitting case the multi-start fit, its curvature errors, the
inertness test and the cross-validation folds on analytic models; the inputs
case the data layouts and their error messages (no granary run in these three).

usage: test_discrepancy.py CASE GRANARY SOURCE_DIR   (CASE: viscoelastic,
cohesion, rolling, tangential, clumpres, repose, null, extractors, fitting, inputs)
"""
import atexit
import csv
import json
import os
import shutil
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
        "expect": "cohesion sjkr", "param_tol": 0.08, "min_gain": 3.0, "seed": 12},
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
    "repose": {
        # Angle of repose of heaps poured in a cell (examples/discrepancy/heap_cell),
        # spheres of three diameters, two pours each: the data hide the rolling
        # friction of the sphere-sphere pair; the baseline has sliding friction
        # only (mu a choice of three values, fitted along by every candidate).
        # Rolling friction and cohesion are tried at four values each (choice
        # parameters: the angle of one pour is not a smooth function of them).
        "example": "heap_cell", "condition": ("ds", "pour"),
        "levels": [(ds, pour) for ds in (1.0, 2.0, 3.0) for pour in (1, 2)],
        "hidden_set": {"rolling": "cdt"},
        "hidden_param": ("mur", 0.1, 0.1),
        "fixed": {"mu": 0.5},
        "observable": "angle_of_repose", "sigma": 0.5,
        "expect": "rolling friction cdt", "expect_also": {"mu": 0.5},
        "param_tol": 0.0, "min_gain": 3.0, "seed": 17},
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
    from discrepancy_lib import inputs, runner, synthetic
    c = CASES[case]
    model = inputs.Model(os.path.join(src, "examples", "discrepancy", c["example"], "model.json"))
    rng = np.random.default_rng(c["seed"])
    name, lo, hi = c["hidden_param"]
    true = lo if lo == hi else float(np.exp(rng.uniform(np.log(lo), np.log(hi))))
    settings = synthetic.hidden_settings(model, c["condition"], c["levels"], c["hidden_set"], name, true, c["fixed"])
    res = runner.Runner(granary, model, jobs=2).run_many(settings)
    observables = c.get("observables", {c.get("observable"): c.get("sigma")})
    with open(path, "w", newline="") as f:
        f.write(f"# synthetic: {case}, hidden {c['hidden_set']} {name} = {true:.6g}, noise sigma {observables}\n")
        w = csv.writer(f)
        multi = not isinstance(c["condition"], str)
        w.writerow(list(c["condition"] if multi else [c["condition"]]) + ["observable", "value", "uncertainty"])
        for obs, sigma in observables.items():
            key = model.key_of(obs)
            for level, r in zip(c["levels"], res):
                w.writerow([f"{lv:.6g}" for lv in (level if multi else [level])] +
                           [obs, f"{r[key] + rng.normal(0, sigma):.6g}", sigma])
    return true, model


def _write_spheres(pts, r):
    """A write_dump-like file of spheres of radius r at pts, in a temporary
    directory removed at exit; returns its path."""
    d = tempfile.mkdtemp(prefix="heap_")
    atexit.register(shutil.rmtree, d, True)
    path = os.path.join(d, "heap.txt")
    with open(path, "w") as f:
        f.write(f"ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n{len(pts)}\n"
                "ITEM: BOX BOUNDS mm mm mm\n-1 1\n-1 1\n0 1\nITEM: ATOMS id x y z radius\n")
        for k, (x, y, z) in enumerate(pts):
            f.write(f"{k + 1} {x} {y} {z} {r}\n")
    return path


def check_extractors(tools):
    """heap_angle on synthetic heaps, conical and (layout "cell") a wedge
    against a wall; the conical one: spheres of radius 1 mm filling a cone
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
        got, nring = extractors.heap_angle(_write_spheres(pts, r))
        print(f"  heap_angle: cone {angle} deg -> {got:.2f} deg ({nring} rings)")
        if not abs(got - angle) < 1.5:
            failures.append(f"heap_angle {got:.2f} for a {angle} degree cone")
    # layout "cell": a wedge against the wall x = 0 of a cell 4 mm deep (a
    # side view), flattened top at the wall, a few spheres rolled beyond the foot
    for angle in (18.0, 25.0, 32.0):
        Lh, W, r = 0.04, 0.004, 0.001
        t = np.tan(np.radians(angle))
        pts = []
        for _ in range(6000):
            x, y = rng.uniform(r, Lh), rng.uniform(0, W)
            top = min((Lh - x) * t, 0.85 * Lh * t)
            pts.append((x, y, rng.uniform(r, max(top - r, r) + 1e-12)))
        for _ in range(1500):
            x, y = rng.uniform(r, Lh), rng.uniform(0, W)
            pts.append((x, y, max(min((Lh - x) * t, 0.85 * Lh * t) - r, r)))
        for _ in range(15):
            pts.append((rng.uniform(Lh, 1.15 * Lh), rng.uniform(0, W), r))
        got, nbin = extractors.heap_angle(_write_spheres(pts, r), (0.15, 0.85), 24, layout="cell")
        print(f"  heap_angle (cell): wedge {angle} deg -> {got:.2f} deg ({nbin} slabs)")
        if not abs(got - angle) < 1.5:
            failures.append(f"heap_angle (cell) {got:.2f} for a {angle} degree wedge")
    return failures


class _AnalyticModel:
    """Stands in for a model file and its runner: y(x) from a formula of the
    -var settings, no granary run."""

    def __init__(self, formula):
        self.conditions, self.set, self.formula, self.nruns = {"x": "x"}, {}, formula, 0

    def key_of(self, observable):
        return observable

    def run_many(self, settings_list):
        self.nruns += len(settings_list)
        return [{"y": self.formula(s)} for s in settings_list]


def check_fitting(tools):
    """The fit on analytic models with Gaussian noise of known sigma:
    - a candidate whose inherited parameter (e) the baseline's misfit pulls far
      off, and whose own frequency w has many local minima from its declared
      initial value: all found together, each within 3 standard errors of the
      truth, chi2/dof within the 99 % band;
    - a parameter that changes nothing: reported inert (no error, not counted);
    - a straight line: the curvature errors equal the analytic least-squares
      errors within 2 %;
    - the repeated k-fold partitions: every row held out once per repeat,
      every fold holding both observables, repeats shuffled differently."""
    sys.path.insert(0, tools)
    from discrepancy_lib import fitting, inputs, stats
    failures = []
    rng = np.random.default_rng(7)
    x = np.linspace(0.02, 1.0, 12)
    sig = 0.01

    def formula(s):
        return s["e"] - s.get("k", 0.0) * np.exp(-s["x"] / 0.1) + 0.05 * np.sin(10 * s.get("w", 0.0) * s["x"])

    truth = {"e": 0.8, "k": 0.3, "w": 3.7}
    rows = [{"cond": (float(xi),), "observable": "y", "sigma": sig,
             "value": float(formula(dict(truth, x=xi)) + rng.normal(0, sig))} for xi in x]
    data = inputs.Data(["x"], rows, "synthetic")
    m = _AnalyticModel(formula)
    P = lambda d: inputs.Param(d, "test")  # noqa: E731
    e = P({"name": "e", "lower": 0.3, "upper": 1.0, "initial": 0.6})
    k = P({"name": "k", "lower": 0.0, "upper": 1.0})
    w = P({"name": "w", "lower": 0.5, "upper": 5.0, "initial": 1.0})
    mur = P({"name": "mur", "lower": 0.0, "upper": 0.3})
    v = fitting.Variant("cand", m, m, params=[e, k, w, mur], own=["k", "w", "mur"])
    f = fitting.fit(v, data, rows, seed=3)
    chi2_red = f["chi2"] / (len(rows) - 3)
    print(f"  fit: e, k, w, mur = {', '.join(f'{a:.4g} +- {b:.2g}' for a, b in zip(f['values'], f['errors']))}; "
          f"inert {f['inert']}; chi2/dof {chi2_red:.3g}; local fits chi2 {[round(c, 2) for c in f['local_chi2']]}; "
          f"{f['nfev']} evaluations")
    for j, name in enumerate(("e", "k", "w")):
        if not abs(f["values"][j] - truth[name]) < 3 * f["errors"][j]:
            failures.append(f"{name} = {f['values'][j]:.4g} +- {f['errors'][j]:.2g}, truth {truth[name]}")
    band = stats.chi2_summary(np.zeros(len(rows)), 3)["chi2_red_band_99"]
    if not chi2_red < band[1]:
        failures.append(f"chi2/dof {chi2_red:.3g} above the 99 % band {band[1]:.3g}")
    if f["inert"] != [False, False, False, True] or not np.isnan(f["errors"][3]):
        failures.append(f"inert flags {f['inert']} (expected only mur), mur error {f['errors'][3]}")
    # straight line: analytic errors sqrt(diag((X^T X)^-1)) sigma
    line = _AnalyticModel(lambda s: s["a"] + s["b"] * s["x"])
    rows_l = [{"cond": (float(xi),), "observable": "y", "sigma": sig,
               "value": float(0.5 + 0.2 * xi + rng.normal(0, sig))} for xi in x]
    vl = fitting.Variant("line", line, line, params=[P({"name": "a", "lower": 0, "upper": 1}),
                                                      P({"name": "b", "lower": -1, "upper": 1})])
    fl = fitting.fit(vl, inputs.Data(["x"], rows_l, "line"), rows_l, seed=1)
    X = np.vstack([np.ones_like(x), x]).T
    expect = np.sqrt(np.diag(np.linalg.inv(X.T @ X))) * sig
    print(f"  line: errors {fl['errors']}, analytic {expect.tolist()}")
    if not np.allclose(fl["errors"], expect, rtol=0.02):
        failures.append(f"line errors {fl['errors']} differ from the analytic {expect.tolist()}")
    # repeated stratified k-fold
    strata = ["a"] * 7 + ["b"] * 5
    parts = stats.kfold(12, 4, 3, seed=2, strata=strata)
    for r, folds in enumerate(parts):
        held = sorted(i for fo in folds for i in fo)
        if held != list(range(12)):
            failures.append(f"repeat {r}: rows held out {held}, expected each once")
        if any(len({strata[i] for i in fo}) < 2 for fo in folds):
            failures.append(f"repeat {r}: a fold lacks an observable: {folds}")
    if parts[0] == parts[1] or parts != stats.kfold(12, 4, 3, seed=2, strata=strata):
        failures.append("k-fold repeats not shuffled differently, or not reproducible with the seed")
    return failures


def src_examples(tools):
    return os.path.join(os.path.dirname(os.path.abspath(tools)), "examples", "discrepancy")


def check_inputs(tools):
    """Data layouts: wide CSV with a shared and with per-observable uncertainty
    columns and units in the header, the long layout, a JSON spec with an
    uncertainty column; and the error (file, line, what, how to fix) for bad
    files."""
    sys.path.insert(0, tools)
    from discrepancy_lib import inputs
    failures = []

    class M:
        conditions = {"impact_speed": "speed"}

    good = {
        "wide.csv": ("# comment\nimpact_speed [m/s],restitution,uncertainty\n0.1,0.8,0.01\n\n0.2,0.79,0.02\n",
                     [((0.1,), "restitution", 0.8, 0.01), ((0.2,), "restitution", 0.79, 0.02)]),
        "wide2.csv": ("impact_speed (m/s),restitution,restitution_uncertainty,rebound [deg],rebound_sigma\n"
                      "0.1,0.8,0.01,12,1\n0.2,0.7,0.01,,\n",
                      [((0.1,), "restitution", 0.8, 0.01), ((0.1,), "rebound", 12.0, 1.0),
                       ((0.2,), "restitution", 0.7, 0.01)]),
        "long.csv": ("impact_speed,observable,value,uncertainty\n0.1,restitution,0.8,0.01\n",
                     [((0.1,), "restitution", 0.8, 0.01)]),
    }
    bad = {
        "nounc.csv": ("impact_speed,restitution\n0.1,0.8\n", "line 1", "restitution_uncertainty"),
        "text.csv": ("impact_speed,restitution,uncertainty\n# c\n0.1,0.8,0.01\n0.2,high,0.01\n", "line 4",
                     "not a number"),
        "neg.csv": ("impact_speed,restitution,uncertainty\n0.1,0.8,0\n", "line 2", "must be > 0"),
        "fields.csv": ("impact_speed,restitution,uncertainty\n0.1,0.8\n", "line 2", "one value per column"),
        "nocond.csv": ("speed,restitution,uncertainty\n0.1,0.8,0.01\n", "line 1", "no condition column"),
        "orphan.csv": ("impact_speed,restitution,uncertainty,spin_uncertainty\n0.1,0.8,0.01,1\n", "line 1",
                       "belongs to no value column"),
    }
    with tempfile.TemporaryDirectory() as tmp:
        for name, (text, expect) in good.items():
            path = os.path.join(tmp, name)
            with open(path, "w") as f:
                f.write(text)
            try:
                d = inputs.read_data(path, M)
            except inputs.InputFileError as e:
                failures.append(f"{name}: refused: {e}")
                continue
            got = [(r["cond"], r["observable"], r["value"], r["sigma"]) for r in d.rows]
            if got != expect:
                failures.append(f"{name}: read {got}, expected {expect}")
            print(f"  {name}: {len(got)} rows, units {d.units}")
        if inputs.read_data(os.path.join(tmp, "wide.csv"), M).units != {"impact_speed": "m/s"}:
            failures.append("wide.csv: the unit of impact_speed was not read")
        for name, (text, line, words) in bad.items():
            path = os.path.join(tmp, name)
            with open(path, "w") as f:
                f.write(text)
            try:
                inputs.read_data(path, M)
                failures.append(f"{name}: accepted")
            except inputs.InputFileError as e:
                msg = str(e)
                print(f"  {name}: {msg}")
                if not (msg.startswith(path) and line in msg and words in msg):
                    failures.append(f"{name}: message lacks the file, '{line}' or '{words}': {msg}")
        # JSON spec: a per-row uncertainty column is used (found by its name)
        with open(os.path.join(tmp, "et.csv"), "w") as f:
            f.write("angle [deg],et,uncertainty\n10,0.8,0.02\n20,0.7,0.05\n")
        with open(os.path.join(tmp, "spec.json"), "w") as f:
            json.dump({"condition": "angle", "files": [{"path": "et.csv", "observable": "et"}]}, f)
        d = inputs.read_data(os.path.join(tmp, "spec.json"))
        if [r["sigma"] for r in d.rows] != [0.02, 0.05] or d.units.get("angle") != "deg":
            failures.append(f"spec.json: sigma {[r['sigma'] for r in d.rows]}, units {d.units}")
        # model files: the heap_angle extractor's options are checked
        with open(os.path.join(tmp, "in.x"), "w") as f:
            f.write("print hello\n")
        bad_models = {"layout": ({"layout": "wedge"}, "'layout' is 'wedge'"),
                      "bins": ({"bins": 2}, "'bins' must be an integer"),
                      "central": ({"central": [0.8, 0.2]}, "'central' must be two fractions")}
        for name, (opts, words) in bad_models.items():
            path = os.path.join(tmp, f"model_{name}.json")
            with open(path, "w") as f:
                json.dump({"script": "in.x", "extract": {"heap_angle": dict({"file": "h.txt"}, **opts)}}, f)
            try:
                inputs.Model(path)
                failures.append(f"model_{name}.json: accepted")
            except inputs.InputFileError as e:
                print(f"  model_{name}.json: {e}")
                if not (str(e).startswith(path) and words in str(e)):
                    failures.append(f"model_{name}.json: message lacks the file or '{words}': {e}")
        inputs.Model(os.path.join(src_examples(tools), "heap_cell", "model.json"))
    return failures


def main():
    case, granary, src = sys.argv[1], sys.argv[2], sys.argv[3]
    tools = os.path.join(src, "tools")
    if case in ("extractors", "fitting", "inputs"):
        failures = {"extractors": check_extractors, "fitting": check_fitting, "inputs": check_inputs}[case](tools)
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
            # continuous parameters tried at a few values only
            sys.path.insert(0, tools)
            from discrepancy_lib import synthetic
            cand_path = synthetic.catalogue_subset(cand_path, c["candidates"], os.path.join(tmp, "candidates.json"),
                                                   c.get("choices"))
        out = os.path.join(tmp, "report")
        cmd = ["/usr/bin/python3", os.path.join(tools, "discrepancy"), "--data", data_path,
               "--model", os.path.join(ex, "model.json"), "--candidates", cand_path,
               "--granary", granary, "--jobs", "2", "--seed", "3", "--out", out, "--quiet",
               # two repeats of the cross-validation instead of the default three, to keep
               # the suite short (a third of the refits fewer); the cause must then win both
               "--repeats", "2"]
        if not cli:
            cmd.append("--no-plots")
        if c["expect"] is None:
            # the verdict of a baseline that fits does not depend on held-out
            # errors; skipping the cross-validation saves a third of the runs
            cmd += ["--cv", "if-significant"]
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
            if best["all_chi2"]["p_value"] < 0.01:
                failures.append(f"the named extension misses its own data: chi2/dof {best['all_chi2']['chi2_red']:.3g}")
            st = v.get("stability", {})
            print(f"  stability: lowest out-of-fold error in {st.get('repeats_won')} of {st.get('repeats')} repeats, "
                  f"{st.get('folds_won')} of {st.get('folds')} folds; chi2/dof of the extension "
                  f"{best['all_chi2']['chi2_red']:.3g}")
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
                if err is not None and not abs(fitted[0]["value"] - true) < 3 * err + 1e-12 * true:
                    failures.append(f"{pname}: the true value is more than 3 standard errors ({err:.3g}) away")
            for pname, want in c.get("expect_also", {}).items():
                got = [p["value"] for p in best["params"] if p["name"] == pname]
                print(f"  {pname}: fitted {got[0] if got else None}, true {want}")
                if not got or abs(got[0] - want) > 1e-9 * abs(want):
                    failures.append(f"{pname} fitted {got[0] if got else None}, expected {want}")
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
