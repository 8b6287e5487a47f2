#!/usr/bin/python3
"""Granary against LIGGGHTS on one silo script: ensembles of fills and discharges.

Runs examples/silo_liggghts/in.silo_both (a script both programs run
unchanged) for several insertion seeds with each configuration, then compares
the fills (packing of the settled bed), the discharges (mass passed, flow
rate, clogs) and, with arch removal, the avalanche sizes.

    /usr/bin/python3 tools/silo_compare.py run --out DIR [--configs granary,liggghts,liggghts_beads]
                     [--seeds 8] [--slit 3.5] [--jobs 2] [-var NAME VALUE ...]
    /usr/bin/python3 tools/silo_compare.py export DIR TO [--window T0,T1] [--until T]
    /usr/bin/python3 tools/silo_compare.py report DIR|TO [--json FILE] [--window T0,T1] [--until T]
    /usr/bin/python3 tools/silo_compare.py merge TO1 TO2 ... --to POOLED

Configurations (the script's variable nve_all says which particles fix
nve/sphere integrates):
  granary          build/granary, nve_all 1 (nve/sphere on all; Granary leaves clump spheres to fix multisphere)
  granary_beads    build/granary, nve_all 0 (nve/sphere on the beads only)
  liggghts         liggghts, nve_all 1 (LIGGGHTS 3.8 integrates clump spheres twice: multisphere and nve/sphere)
  liggghts_beads   liggghts, nve_all 0 (each particle integrated once)

`run` is resumable: a run whose log ends with its END line is kept; others
are (re)started from scratch. Runs go to DIR/<config>/s<slit>/seed<seed>/.
`report` prints, per slit width and configuration, mean, standard deviation
and 95 % confidence interval of each observable over the seeds, and for each
pair of configurations Welch's t-test, Levene's test (spread) and the
Mann-Whitney test; with several slit widths a Beverloo fit of the flow rate;
with arch removal the avalanche sizes (pooled) with a two-sample
Kolmogorov-Smirnov test. `export` writes the finished runs of DIR as compact
files (runs.csv, avalanches.csv, settings.json) that `report` reads in place
of the logs; `merge` pools exported folders of one ensemble into one, every
run (configuration, slit, seed) once: a seed run again must reproduce its
first run to every digit and is kept once, anything else stops it. The flow rate is the mass passed over the 0.01 s chunks in which
something passed, within a window of discharge time (--window; default from
0.05 s, the start of the flow left out, to the end). With --until T every
observable is taken over the first T seconds of discharge only, and a run
that was stopped after T counts as finished (runs cut short by a time limit).
Needs numpy and scipy (Debian's python3-numpy, python3-scipy).
"""
import argparse
import concurrent.futures
import json
import math
import os
import re
import shutil
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SCRIPT = os.path.join(ROOT, "examples", "silo_liggghts", "in.silo_both")
DC = 3.2e-3
RHO_C, RHO_B = 1190.0, 2500.0
# solid volume of the 10-sphere clump (potentials/cylinder_ellipse_10.clump header): the
# mass both programs give it from their Monte Carlo volume (LIGGGHTS 1.6351e-5 kg, Granary 1.6328e-5 kg)
CLUMP_VOLUME = {10: 13.7164e-9, 20: None, 50: None, 100: None}
CONFIGS = {
    "granary": ("granary", 1),
    "granary_beads": ("granary", 0),
    "liggghts": ("liggghts", 1),
    "liggghts_beads": ("liggghts", 0),
}
DEFAULTS = {"W": 15.0, "D": 6.0, "H": 30.0, "s": 3.5, "phi": 0.05, "r": 3.2, "nres": 10, "tmax": 0.6,
            "arch": 1}


def primes_from(start, n):
    """n primes > start (LIGGGHTS wants prime seeds above 10000)."""
    out, k = [], start + 1
    while len(out) < n:
        if k > 1 and all(k % d for d in range(2, int(math.isqrt(k)) + 1)):
            out.append(k)
        k += 1
    return out


def executable(program, granary):
    if program == "granary":
        return granary
    exe = shutil.which("liggghts")
    if not exe:
        raise SystemExit("silo_compare: liggghts not found (Debian package liggghts)")
    return exe


def run_dir(out, config, slit, seed):
    return os.path.join(out, config, f"s{slit:g}", f"seed{seed}")


def finished(d):
    log = os.path.join(d, "log")
    if not os.path.exists(log):
        return False
    with open(log, errors="replace") as f:
        return any(line.startswith("END t ") for line in f)


def one_run(exe, nve_all, d, slit, variables):
    """Write the meshes and run the script in folder d; returns (d, rc, seconds)."""
    import time
    os.makedirs(d, exist_ok=True)
    for name in os.listdir(d):
        p = os.path.join(d, name)
        if os.path.isfile(p):
            os.remove(p)
    v = dict(variables)
    subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "tools", "make_silo_stl.py"), "--W", str(v["W"]),
                    "--D", str(v["D"]), "--H", str(v["H"]), "--slit", str(slit), "--out", d], check=True,
                   capture_output=True)
    v["s"] = slit
    args = [exe, "-in", SCRIPT, "-log", "log", "-var", "potdir", os.path.join(ROOT, "potentials"),
            "-var", "nve_all", str(nve_all)]
    for k, val in v.items():
        args += ["-var", k, str(val)]
    env = dict(os.environ, OMP_NUM_THREADS="1")
    t0 = time.time()
    with open(os.path.join(d, "screen"), "w") as scr:
        rc = subprocess.run(args, cwd=d, stdout=scr, stderr=subprocess.STDOUT, env=env).returncode
    return d, rc, time.time() - t0


def cmd_run(a):
    variables = dict(DEFAULTS)
    for name, value in a.var or []:
        variables[name] = value
    granary = os.path.abspath(a.granary)
    configs = a.configs.split(",")
    for c in configs:
        if c not in CONFIGS:
            raise SystemExit(f"silo_compare: unknown configuration '{c}' (one of {', '.join(CONFIGS)})")
    slits = [float(x) for x in a.slit.split(",")]
    seeds = primes_from(a.seed_base, a.seeds)
    todo = []
    for slit in slits:
        for seed in seeds:
            for c in configs:
                d = run_dir(a.out, c, slit, seed)
                if finished(d):
                    continue
                program, nve_all = CONFIGS[c]
                todo.append((executable(program, granary), nve_all, d, slit, dict(variables, seed=seed)))
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "settings.json"), "w") as f:
        json.dump({"variables": variables, "slits": slits, "seeds": seeds, "configs": configs}, f, indent=1)
    print(f"silo_compare: {len(todo)} runs to do in {a.out} ({a.jobs} at a time)", flush=True)
    failed = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for d, rc, sec in pool.map(lambda t: one_run(*t), todo):
            ok = rc == 0 and finished(d)
            failed += not ok
            print(f"  {'done' if ok else 'FAILED'} {os.path.relpath(d, a.out)} ({sec:.0f} s)", flush=True)
    return 1 if failed else 0


# ---------------------------------------------------------------- analysis

LINE = re.compile(r"^(FILLED|BED|FLOW|CLOG|ARCH|END)\b(.*)$")


def parse_log(path):
    rec = {"flow": [], "clog": [], "arch": []}
    with open(path, errors="replace") as f:
        for line in f:
            m = LINE.match(line)
            if not m:
                continue
            kind, rest = m.group(1), m.group(2).split()
            if kind == "FILLED":
                rec["filled"] = (float(rest[1]), int(float(rest[3])), int(float(rest[5])))
            elif kind == "BED":
                rec["bed"] = (float(rest[1]), float(rest[3]), float(rest[5]))
            elif kind == "FLOW":
                rec["flow"].append((float(rest[0]), int(float(rest[1])), int(float(rest[2]))))
            elif kind == "CLOG":
                rec["clog"].append(float(rest[0]))
            elif kind == "ARCH":
                rec["arch"].append((float(rest[0]), int(float(rest[1])), int(float(rest[2]))))
            elif kind == "END":
                rec["end"] = float(rest[1])
    return rec


def masses(nres, r):
    vc = CLUMP_VOLUME.get(int(nres))
    if vc is None:
        raise SystemExit(f"silo_compare: no clump volume known for nres {nres}")
    db = DC / float(r)
    return RHO_C * vc, RHO_B * math.pi / 6 * db ** 3, vc, math.pi / 6 * db ** 3


DEFAULT_WINDOW = (0.05, math.inf)


def parse_window(text):
    """'T0,T1' (seconds of discharge; T1 may be 'end') -> (T0, T1)."""
    try:
        a, b = text.split(",")
        w = (float(a), math.inf if b.strip() == "end" else float(b))
    except ValueError:
        raise SystemExit(f"silo_compare: --window takes T0,T1 in seconds of discharge (e.g. 0.05,0.25), got '{text}'")
    if not 0 <= w[0] < w[1]:
        raise SystemExit(f"silo_compare: --window {text}: needs 0 <= T0 < T1")
    return w


def discharge_start(rec):
    """The time the discharge started: one chunk before the first FLOW line."""
    f = rec["flow"]
    return f[0][0] - (f[1][0] - f[0][0]) if len(f) > 1 else rec["filled"][0]


def reached(rec, until):
    """Does a parsed log reach `until` seconds of discharge?"""
    return "filled" in rec and "bed" in rec and bool(rec["flow"]) and \
        rec["flow"][-1][0] - discharge_start(rec) >= until - 1e-9


def parse_until(text):
    """'T' (seconds of discharge) or None -> T (infinity when None)."""
    if not text:
        return math.inf
    try:
        t = float(text)
    except ValueError:
        raise SystemExit(f"silo_compare: --until takes seconds of discharge (e.g. 0.3), got '{text}'")
    if not t > 0:
        raise SystemExit(f"silo_compare: --until {text}: needs a positive time")
    return t


def observables(rec, v, window=DEFAULT_WINDOW, until=math.inf):
    """Per-run numbers from a parsed log (over the first `until` seconds of discharge)."""
    nres = int(float(v["nres"]))
    mc, mb, vc, vb = masses(nres, v["r"])
    t_fill, n1_0, n2_0 = rec["filled"]
    out = {}
    slab_v, s1, s2 = rec["bed"]
    out["bed_phi"] = (s1 / nres * vc + s2 * vb) / slab_v
    out["bed_bodies"] = n1_0 / nres + n2_0
    # passed mass vs time; arch deletions are not passage
    t0 = discharge_start(rec)
    if not math.isinf(until):
        rec = dict(rec, flow=[e for e in rec["flow"] if e[0] - t0 <= until + 1e-9],
                   clog=[t for t in rec["clog"] if t - t0 <= until + 1e-9],
                   arch=[e for e in rec["arch"] if e[0] - t0 <= until + 1e-9])
    deleted1 = deleted2 = 0
    prev = (n1_0, n2_0)
    series = [(t0, 0.0)]
    arches = list(rec["arch"])
    events = sorted([(t, "F", a, b) for t, a, b in rec["flow"]] + [(t, "A", a, b) for t, a, b in arches],
                    key=lambda e: (e[0], e[1] == "F"))
    avalanches, av_start = [], 0.0
    passed = 0.0
    for t, kind, a, b in events:
        if kind == "A":
            deleted1 += prev[0] - a
            deleted2 += prev[1] - b
            avalanches.append(passed - av_start)
            av_start = passed
        else:
            passed = ((n1_0 - a - deleted1) / nres) * mc + (n2_0 - b - deleted2) * mb
            series.append((t, passed))
        prev = (a, b)
    out["mass_passed"] = series[-1][1]
    out["clogs"] = len(rec["clog"])
    out["first_clog"] = (rec["clog"][0] - t0) if rec["clog"] else float("nan")
    # flow rate while flowing: passed mass over the chunks in which something passed,
    # chunks inside the window of discharge time (default: from 0.05 s, the start of the
    # flow left out, to the end)
    dm = dt = 0.0
    for (ta, ma), (tb, mb_) in zip(series, series[1:]):
        if ta - t0 >= window[0] - 1e-9 and tb - t0 <= window[1] + 1e-9 and mb_ > ma:
            dm += mb_ - ma
            dt += tb - ta
    out["flow_rate"] = dm / dt if dt > 0 else float("nan")
    out["avalanches"] = avalanches
    out["series"] = series
    return out


def ci95(x):
    """(mean, sd, half-width of the 95 % t interval) of the finite values of x."""
    import numpy as np
    from avalanche_stats import mean_ci_t
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    m, se, lo, hi = mean_ci_t(x)
    return m, (float(x.std(ddof=1)) if len(x) > 1 else float("nan")), (hi - m) if len(x) > 1 else float("nan")


def compare(x, y):
    import numpy as np
    from scipy import stats
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    x, y = x[np.isfinite(x)], y[np.isfinite(y)]
    if len(x) < 2 or len(y) < 2:
        return {}
    return {"welch_p": float(stats.ttest_ind(x, y, equal_var=False).pvalue),
            "levene_p": float(stats.levene(x, y).pvalue),
            "mannwhitney_p": float(stats.mannwhitneyu(x, y, alternative="two-sided").pvalue)}


RUN_KEYS = ["bed_phi", "bed_bodies", "mass_passed", "flow_rate", "clogs", "first_clog"]


def runs_by_config(d, slit, v, window=DEFAULT_WINDOW, until=math.inf):
    """{configuration: [observables of each finished run]} at one slit width, from the
    run folders of `run` or, where d holds runs.csv and avalanches.csv, from those (`export`)."""
    per = {}
    if os.path.exists(os.path.join(d, "runs.csv")):
        import csv
        sizes = {}
        with open(os.path.join(d, "avalanches.csv")) as f:
            for row in csv.DictReader(line for line in f if not line.startswith("#")):
                key = (row["config"], float(row["slit"]), int(row["seed"]))
                sizes.setdefault(key, []).append(float(row["mass_kg"]))
        with open(os.path.join(d, "runs.csv")) as f:
            for row in csv.DictReader(line for line in f if not line.startswith("#")):
                if float(row["slit"]) != float(slit):
                    continue
                r = {k: float(row[k]) for k in RUN_KEYS}
                r["clogs"] = int(r["clogs"])
                r["avalanches"] = sizes.get((row["config"], float(row["slit"]), int(row["seed"])), [])
                per.setdefault(row["config"], []).append(r)
        return dict(sorted(per.items()))
    for c, _, rd in finished_runs(d, slit, until):
        per.setdefault(c, []).append(observables(parse_log(os.path.join(rd, "log")), v, window, until))
    return per


def finished_runs(d, slit, until=math.inf):
    """(configuration, seed, folder) of every finished run at one slit width of the run folder d
    (with `until`: also every run whose log reaches that many seconds of discharge)."""
    for c in sorted(os.listdir(d)):
        base = os.path.join(d, c, f"s{slit:g}")
        if c not in CONFIGS or not os.path.isdir(base):
            continue
        for seed_dir in sorted(os.listdir(base)):
            rd = os.path.join(base, seed_dir)
            if finished(rd) or (not math.isinf(until) and os.path.exists(os.path.join(rd, "log")) and
                                reached(parse_log(os.path.join(rd, "log")), until)):
                yield c, int(seed_dir.replace("seed", "")), rd


def cmd_export(a):
    """The finished runs of a.dir as compact CSV files in a.to: runs.csv (one row per run),
    avalanches.csv (the avalanche sizes, in order) and settings.json; `report` reads them."""
    with open(os.path.join(a.dir, "settings.json")) as f:
        settings = json.load(f)
    v = settings["variables"]
    window = parse_window(a.window)
    settings["flow_window"] = a.window
    until = parse_until(a.until)
    if a.until:
        settings["until"] = a.until
    os.makedirs(a.to, exist_ok=True)
    runs_rows, av_rows = [], []
    for slit in settings["slits"]:
        for c, seed, rd in finished_runs(a.dir, slit, until):
            r = observables(parse_log(os.path.join(rd, "log")), v, window, until)
            runs_rows.append([c, f"{slit:g}", str(seed)] + [repr(r[k]) for k in RUN_KEYS])
            for k, m in enumerate(r["avalanches"]):
                av_rows.append([c, f"{slit:g}", str(seed), str(k), repr(m)])
    head = f"# tools/silo_compare.py export of {os.path.basename(os.path.normpath(a.dir))}: variables {json.dumps(v)}\n"
    with open(os.path.join(a.to, "runs.csv"), "w") as f:
        f.write(head + "config,slit,seed," + ",".join(RUN_KEYS) + "\n")
        f.writelines(",".join(r) + "\n" for r in runs_rows)
    with open(os.path.join(a.to, "avalanches.csv"), "w") as f:
        f.write(head + "config,slit,seed,index,mass_kg\n")
        f.writelines(",".join(r) + "\n" for r in av_rows)
    with open(os.path.join(a.to, "settings.json"), "w") as f:
        json.dump(settings, f, indent=1)
    print(f"silo_compare: {len(runs_rows)} runs, {len(av_rows)} avalanches -> {a.to}")
    return 0


def read_export(d):
    """(settings, header comment, runs rows, avalanche rows) of an exported folder."""
    import csv
    with open(os.path.join(d, "settings.json")) as f:
        settings = json.load(f)
    rows = {}
    for name in ("runs.csv", "avalanches.csv"):
        with open(os.path.join(d, name)) as f:
            rows[name] = list(csv.reader(line for line in f if not line.startswith("#")))
    return settings, rows["runs.csv"], rows["avalanches.csv"]


def cmd_merge(a):
    """Exported folders pooled into one (that `report` reads): every run, i.e. every
    (configuration, slit, seed), once. The folders must hold the same physics (variables
    other than the run length tmax), flow-rate window and duration (--until); a run found
    in several folders must be the same in each (a rerun of a seed reproduces it), and is
    kept once; anything else is an error, never a run counted twice."""
    merged, first = None, None
    runs, avalanches, origin = {}, {}, {}
    for d in a.dirs:
        if not os.path.exists(os.path.join(d, "runs.csv")):
            raise SystemExit(f"silo_compare: {d} is not an export (no runs.csv); export the run folder first")
        settings, run_rows, av_rows = read_export(d)
        def value(x):  # -var values are strings, defaults numbers: 1 and "1" are one value
            try:
                return float(x)
            except (TypeError, ValueError):
                return str(x)

        physics = {k: value(v) for k, v in settings["variables"].items() if k != "tmax"}
        same = ("flow_window", "until")
        if merged is None:
            merged, first = dict(settings), d
            merged["variables"] = dict(settings["variables"])
            merged["merged_from"] = []
            ref = physics
        else:
            if physics != ref:
                diff = sorted(k for k in set(physics) | set(ref) if physics.get(k) != ref.get(k))
                raise SystemExit(f"silo_compare: {d} and {first} differ in {', '.join(diff)}: not one ensemble")
            for k in same:
                if settings.get(k) != merged.get(k):
                    raise SystemExit(f"silo_compare: {d} has {k} {settings.get(k)}, {first} {merged.get(k)}; "
                                     f"export them alike")
            merged["slits"] = sorted(set(merged["slits"]) | set(settings["slits"]))
            merged["variables"]["tmax"] = "various"
        merged["merged_from"].append(os.path.basename(os.path.normpath(d)))
        header, body = run_rows[0], run_rows[1:]
        per_run_av = {}
        for row in av_rows[1:]:
            per_run_av.setdefault(tuple(row[:3]), []).append(row)
        for row in body:
            key = tuple(row[:3])
            if key in runs:
                if runs[key] != row or avalanches.get(key, []) != per_run_av.get(key, []):
                    raise SystemExit(f"silo_compare: run {'/'.join(key)} is in {origin[key]} and {d} with "
                                     f"different results: not a rerun of one seed")
                print(f"silo_compare: run {'/'.join(key)} of {d} repeats that of {origin[key]} "
                      f"(the same to every digit): kept once")
                continue
            runs[key], origin[key] = row, d
            avalanches[key] = per_run_av.get(key, [])
    os.makedirs(a.to, exist_ok=True)
    head = f"# tools/silo_compare.py merge of {', '.join(merged['merged_from'])}: variables " \
           f"{json.dumps(merged['variables'])}\n"
    with open(os.path.join(a.to, "runs.csv"), "w") as f:
        f.write(head + ",".join(header) + "\n")
        f.writelines(",".join(r) + "\n" for r in runs.values())
    with open(os.path.join(a.to, "avalanches.csv"), "w") as f:
        f.write(head + "config,slit,seed,index,mass_kg\n")
        f.writelines(",".join(r) + "\n" for rows in avalanches.values() for r in rows)
    with open(os.path.join(a.to, "settings.json"), "w") as f:
        json.dump(merged, f, indent=1)
    print(f"silo_compare: {len(runs)} runs from {len(a.dirs)} folders -> {a.to}")
    return 0


def cmd_report(a):
    import numpy as np
    from scipy import optimize, stats
    with open(os.path.join(a.dir, "settings.json")) as f:
        settings = json.load(f)
    v = settings["variables"]
    # the flow-rate window: from the logs as asked; exported files hold the rates of
    # the window they were exported with
    stored = settings.get("flow_window")
    if os.path.exists(os.path.join(a.dir, "runs.csv")) and a.window and a.window != stored:
        raise SystemExit(f"silo_compare: {a.dir} holds flow rates of the window {stored or '0.05,end'}; "
                         f"export the run folder again with --window {a.window}")
    window = parse_window(a.window or stored or "0.05,end")
    stored_until = settings.get("until")
    if os.path.exists(os.path.join(a.dir, "runs.csv")) and a.until and a.until != stored_until:
        raise SystemExit(f"silo_compare: {a.dir} holds observables over "
                         f"{'the whole discharge' if not stored_until else stored_until + ' s of discharge'}; "
                         f"export the run folder again with --until {a.until}")
    until = parse_until(a.until or stored_until)
    print(f"flow rate over {window[0]:g} to {'the end' if math.isinf(window[1]) else f'{window[1]:g} s'} "
          f"of discharge" + ("" if math.isinf(until) else f"; every observable over the first {until:g} s"))
    result = {"settings": settings, "cases": {}}
    keys = RUN_KEYS
    flows = {}
    for slit in settings["slits"]:
        print(f"== slit {slit:g} dc (W {v['W']}, D {v['D']}, phi {v['phi']}, r {v['r']}, nres {v['nres']}, "
              f"tmax {v['tmax']} s, arch removal {v['arch']})")
        per = runs_by_config(a.dir, slit, v, window, until)
        case = {}
        print(f"  {'configuration':16s} {'n':>3s} " + " ".join(f"{k:>30s}" for k in keys))
        for c, runs in per.items():
            row = {k: ci95([r[k] for r in runs]) for k in keys}
            row["n"] = len(runs)
            row["clogged_runs"] = sum(r["clogs"] > 0 for r in runs)
            row["mass_passed_each"] = [r["mass_passed"] for r in runs]
            av = [s for r in runs for s in r["avalanches"]]
            row["avalanches"] = av
            case[c] = row
            cells = " ".join(f"{m:.4g} ± {h:.2g} (sd {sd:.2g})".rjust(30) for m, sd, h in (row[k] for k in keys))
            print(f"  {c:16s} {len(runs):3d} {cells}")
            flows.setdefault(c, []).append((slit, [r["flow_rate"] for r in runs]))
        names = list(per)
        for i in range(len(names)):
            for j in range(i + 1, len(names)):
                p, q = names[i], names[j]
                cmp = {k: compare([r[k] for r in per[p]], [r[k] for r in per[q]])
                       for k in ("bed_phi", "mass_passed", "flow_rate", "clogs")}
                case.setdefault("tests", {})[f"{p} vs {q}"] = cmp
                print(f"  {p} vs {q}: " + "; ".join(
                    f"{k} Welch p {t['welch_p']:.3g}, Levene p {t['levene_p']:.3g}, MW p {t['mannwhitney_p']:.3g}"
                    for k, t in cmp.items() if t))
                ap = [s for r in per[p] for s in r["avalanches"]]
                aq = [s for r in per[q] for s in r["avalanches"]]
                if len(ap) >= 5 and len(aq) >= 5:
                    ks = stats.ks_2samp(ap, aq)
                    mw = stats.mannwhitneyu(ap, aq, alternative="two-sided")
                    print(f"    avalanches: {p} {len(ap)}, mean {np.mean(ap):.4g} kg ±{ci95(ap)[2]:.2g}; "
                          f"{q} {len(aq)}, mean {np.mean(aq):.4g} kg ±{ci95(aq)[2]:.2g}; KS p {ks.pvalue:.3g}, "
                          f"MW p {mw.pvalue:.3g}")
                    case["tests"][f"{p} vs {q}"]["avalanches"] = {"ks_p": float(ks.pvalue),
                                                                  "mannwhitney_p": float(mw.pvalue)}
        result["cases"][f"{slit:g}"] = case
    # Beverloo for a slit of length D: W = C rho_b sqrt(g) D (s - k dc)^(3/2)
    if len(settings["slits"]) >= 3:
        for c, pts in flows.items():
            s = np.array([p[0] for p in pts]) * DC
            w = np.array([np.nanmean(p[1]) for p in pts])
            e = np.array([np.nanstd(p[1], ddof=1) / math.sqrt(max(1, np.isfinite(p[1]).sum())) for p in pts])
            depth = float(v["D"]) * DC

            def bev(s_, c_, k_):
                return c_ * math.sqrt(9.81) * depth * np.clip(s_ - k_ * DC, 0, None) ** 1.5

            try:
                weighted = bool(np.all(e > 0))
                popt, pcov = optimize.curve_fit(bev, s, w, p0=(600.0, 1.0), sigma=e if weighted else None,
                                                absolute_sigma=weighted)
                perr = np.sqrt(np.diag(pcov))
                print(f"  Beverloo {c}: C rho_b = {popt[0]:.4g} ± {perr[0]:.2g} kg/m^3, k = {popt[1]:.3g} ± "
                      f"{perr[1]:.2g}")
                result.setdefault("beverloo", {})[c] = {"C_rho": float(popt[0]), "C_rho_err": float(perr[0]),
                                                         "k": float(popt[1]), "k_err": float(perr[1])}
            except (RuntimeError, ValueError) as err:
                print(f"  Beverloo {c}: fit failed ({err})")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=1)
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run the ensembles (resumable)")
    r.add_argument("--out", required=True)
    r.add_argument("--configs", default="granary,liggghts,liggghts_beads")
    r.add_argument("--seeds", type=int, default=8)
    r.add_argument("--seed-base", type=int, default=32452843, help="seeds: the primes above this")
    r.add_argument("--slit", default="3.5", help="slit widths in dc, comma-separated")
    r.add_argument("--jobs", type=int, default=2)
    r.add_argument("--granary", default=os.path.join(ROOT, "build", "granary"))
    r.add_argument("-var", nargs=2, action="append", metavar=("NAME", "VALUE"))
    x = sub.add_parser("export", help="the finished runs as compact CSV files (report reads them)")
    x.add_argument("dir")
    x.add_argument("to")
    x.add_argument("--window", default="0.05,end",
                   help="seconds of discharge over which the flow rate is taken (default 0.05,end)")
    x.add_argument("--until", help="take every observable over the first T seconds of discharge; runs stopped "
                                   "after T count as finished")
    p = sub.add_parser("report", help="statistics of the finished runs")
    p.add_argument("dir")
    p.add_argument("--json")
    p.add_argument("--window", help="seconds of discharge over which the flow rate is taken, T0,T1 (T1 may be "
                                    "'end'; default 0.05,end or that of an export)")
    p.add_argument("--until", help="take every observable over the first T seconds of discharge (default: the "
                                   "whole discharge, or that of an export)")
    m = sub.add_parser("merge", help="pool exported folders into one, each run once")
    m.add_argument("dirs", nargs="+")
    m.add_argument("--to", required=True)
    a = ap.parse_args(argv)
    return {"run": cmd_run, "export": cmd_export, "report": cmd_report, "merge": cmd_merge}[a.cmd](a)


if __name__ == "__main__":
    sys.exit(main())
