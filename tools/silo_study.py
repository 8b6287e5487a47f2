#!/usr/bin/python3
"""Drive the silo clogging study: fill-discharge-refill cycles per case, resumable.

Each case (sphere fraction phi, size ratio r, spheres per clump nres) is a chain
of cycles of examples/silo_study/in.cycle, one granary run per cycle: cycle 0
fills the silo, every later cycle reads the restart file of the one before,
tops the bed up and discharges it down to the stop height, avalanche after
avalanche. A case is done when its completed cycles hold --min-avalanches
non-empty avalanches that began at an arch removal (the first avalanche of a
cycle begins at the opened shutter, from a freshly settled bed, and is
counted only with --count-first), or --max-cycles cycles.

    /usr/bin/python3 tools/silo_study.py run [--case NAME ...] [--jobs J] [--np N]
                     [--data DIR] [--work DIR] [--min-avalanches 100] [--max-cycles 60]
                     [-var NAME VALUE ...]
    /usr/bin/python3 tools/silo_study.py status [--data DIR]
    /usr/bin/python3 tools/silo_study.py picture --case NAME --out PNG [--data DIR] [--work DIR]
    /usr/bin/python3 tools/silo_study.py list [--candidates]

Cases are named r<r>_phi<phi>[_n<nres>][_coh<kcoh>] (e.g. r3.2_phi0.05, r1.6_phi0,
r3.2_phi0_n50, r4.6_phi0.075_coh10000: cohesion sjkr of energy density kcoh J/m^3 on every
contact of a sphere); without --case, every case of the study (`list`) is run, in order, J at a
time. `list --candidates` gives the cases that test the candidate causes of the paper's r = 4.6
discrepancy (run them with --case).

Results (compact, meant to be committed) go to DATA/<case>/:
  avalanches.csv  every avalanche of the completed cycles (the rows of fix
                  clog-detect with the cycle number in front)
  box.csv         the box averages of the completed cycles (fix ave/time rows,
                  cycle number in front, 5 significant digits)
  cycles.csv      one row per completed cycle: wall time, ranks, steps,
                  particles, bodies passed and deleted, particle-steps
  case.json       the parameters, the granary command, its version
The work files (logs, restart files) go to WORK/<case>/ and are not needed
afterwards except the last restart file, from which the chain continues.

`picture` runs one more cycle of a case from its last restart file (with the
variables of its case.json) that ends at its first clog and leaves the arch
in place (-var final no -var clog_dump 1), in WORK/<case>/picture/ (the
results are not touched), and draws that clog with ParaView
(tools/render.py, under xvfb-run when there is no display).

Resuming: a cycle counts only once its granary run has finished and written its
restart file; its rows are then added to the results, and its line in
cycles.csv is written last. Rows of a cycle that has no line in cycles.csv
(an interrupted hand-over) are dropped before the cycle is run again, so no
avalanche is lost or counted twice. A killed run is simply run again. When the
restart file of the last completed cycle is not there (the results were
copied to another machine), the next cycle fills a new silo and the case goes
on from there (cycles.csv says which cycles started a new fill).
"""
import argparse
import concurrent.futures
import csv
import io
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SCRIPT = os.path.join(ROOT, "examples", "silo_study", "in.cycle")
DATA = os.path.join(ROOT, "examples", "silo_study", "results")
WORK = os.path.join(ROOT, "out", "silo_study")
STOP_STATUS = 75  # granary stopped by SIGTERM or SIGUSR1 (doc/clusters.md)

# The study: phi x r, phi = 0 shared by the three size ratios, and one case at
# 50-sphere clumps.
PHIS = [0.01, 0.02, 0.03, 0.05, 0.075, 0.1]
RS = [1.6, 3.2, 4.6]


def case_name(phi, r, nres=10, kcoh=0):
    name = f"r{r:g}_phi{phi:g}" if phi > 0 else "r0_phi0"
    return name + (f"_n{nres}" if nres != 10 else "") + (f"_coh{kcoh:g}" if kcoh > 0 else "")


def study_cases():
    cases = [case_name(0, 0)]
    for r in RS:
        cases += [case_name(phi, r) for phi in PHIS]
    cases.append(case_name(0, 0, 50))
    return cases


def candidate_cases():
    """The candidate causes of the paper's r = 4.6 discrepancy (its sustained minimum of <S>/<S0>
    in the experiments), each at the phi where the study's r = 4.6 curve lies furthest above it
    (doc/silo_study.md, "The candidate causes at r = 4.6"): the cylinders' sharp edges (50-sphere
    clumps, with their own <S0> from r0_phi0_n50) and cohesion of the small beads (cohesion sjkr on
    every contact of a sphere, KCOH J/m^3; <S0> unchanged, as phi = 0 has no sphere)."""
    return [case_name(0.075, 4.6, 50), case_name(0.075, 4.6, 10, KCOH)]


# the cohesion energy density of the cohesion candidate [J/m^3]: an unloaded bead-bead contact
# (r = 4.6, Y = 1 MPa) sits at an overlap of 0.28 % of the radius, where the cohesive pull is 2.5
# times the bead's weight (twice as much, 2e4, makes beads chatter under cdt rolling friction and
# the clogs wait for them: doc/silo_study.md)
KCOH = 1e4


# r<r>_phi<phi>[_n<nres>][_coh<kcoh>] (also read by tools/silo_study_analysis.py)
CASE_NAME = re.compile(r"r([0-9.]+)_phi([0-9.]+)(?:_n(\d+))?(?:_coh([0-9.]+(?:e[+-]?[0-9]+)?))?")


def parse_case(name):
    m = CASE_NAME.fullmatch(name)
    if not m:
        raise ValueError(f"case name '{name}' is not r<r>_phi<phi>[_n<nres>][_coh<kcoh>]")
    r, phi, nres = float(m.group(1)), float(m.group(2)), int(m.group(3) or 10)
    kcoh = float(m.group(4) or 0)
    if phi > 0 and r <= 0:
        raise ValueError(f"case '{name}': spheres (phi > 0) need a size ratio r > 0")
    if kcoh > 0 and phi <= 0:
        raise ValueError(f"case '{name}': cohesion of the spheres (_coh) needs spheres (phi > 0)")
    p = {"phi": phi, "r": r if r > 0 else 3.2, "nres": nres}
    if kcoh > 0:
        p["kcoh"] = kcoh
    return p


# ------------------------------------------------------------------ files

def read_rows(path):
    """(comment lines, header, rows) of a CSV with '#' comments; ([], None, []) if missing."""
    if not os.path.exists(path):
        return [], None, []
    comments, header, rows = [], None, []
    with open(path, newline="") as f:
        for line in f:
            if not line.strip():
                continue
            if line.startswith("#"):
                comments.append(line.rstrip("\n"))
            elif header is None:
                header = line.strip().split(",")
            else:
                rows.append(line.strip().split(","))
    return comments, header, rows


def write_atomic(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def write_rows(path, comments, header, rows):
    out = io.StringIO()
    for c in comments:
        out.write(c + "\n")
    out.write(",".join(header) + "\n")
    for r in rows:
        out.write(",".join(r) + "\n")
    write_atomic(path, out.getvalue())


def completed_cycles(data_dir):
    _, _, rows = read_rows(os.path.join(data_dir, "cycles.csv"))
    return len(rows)


def nonempty_avalanches(data_dir, first=False):
    """Non-empty avalanches of the completed cycles; without `first`, not counting the first
    avalanche of each cycle (it starts from the opened shutter, not from an arch removal)."""
    _, header, rows = read_rows(os.path.join(data_dir, "avalanches.csv"))
    if not header:
        return 0
    k, a = header.index("bodies"), header.index("avalanche")
    return sum(1 for r in rows if int(float(r[k])) > 0 and (first or int(r[a]) > 1))


def drop_uncommitted(data_dir):
    """Remove rows of cycles that have no line in cycles.csv (an interrupted hand-over)."""
    n = completed_cycles(data_dir)
    for name in ("avalanches.csv", "box.csv"):
        path = os.path.join(data_dir, name)
        comments, header, rows = read_rows(path)
        if header and any(int(r[0]) >= n for r in rows):
            write_rows(path, comments, header, [r for r in rows if int(r[0]) < n])


def granary_version(granary):
    try:
        out = subprocess.run([granary, "-in", os.devnull, "-log", "none"], capture_output=True, text=True,
                             timeout=60).stdout
    except OSError:
        out = ""
    try:
        rev = subprocess.run(["git", "-C", ROOT, "describe", "--always", "--dirty"], capture_output=True,
                             text=True, timeout=30).stdout.strip()
    except OSError:
        rev = ""
    m = re.search(r"Granary (\S+)", out)
    # a frozen copy of the executable for a campaign carries the commit in its name
    return (m.group(1) if m else "unknown") + f" ({os.path.basename(granary)}; source tree git {rev or '?'})"


# ------------------------------------------------------------------ one cycle

def cycle_command(a, case, k, fresh, variables, resume=None, script=SCRIPT):
    """The granary command of cycle k (paths absolute: it runs in the cycle's folder or a part's).
    resume: (restart file of a stopped discharge, bodies when that discharge began); script: the
    input script to run (a copy of in.cycle, see private_script)."""
    p = parse_case(case)
    work = os.path.join(a.work, case)
    args = []
    if a.np > 1:
        args += ["mpirun", "-np", str(a.np)]
        if os.geteuid() == 0:
            args += ["--allow-run-as-root"]
        if a.np > (os.cpu_count() or 1):
            args += ["--oversubscribe"]
    args += [a.granary, "-in", script, "-log", "log", "-screen", "none",
             "-var", "cycle", str(k), "-var", "restart_out", f"restart_{k}.restart",
             "-var", "restart_in", "none" if fresh else os.path.join(work, f"restart_{k - 1}.restart"),
             "-var", "phi", f"{p['phi']:g}", "-var", "r", f"{p['r']:g}", "-var", "nres", str(p["nres"]),
             "-var", "potdir", os.path.join(ROOT, "potentials"), "-var", "meshdir", work,
             "-var", "seed", str(variables.get("seed", 15485863))]
    if p.get("kcoh"):
        args += ["-var", "kcoh", f"{p['kcoh']:g}"]
    if resume:
        args += ["-var", "resume", resume[0], "-var", "resume_n0", str(resume[1])]
    for name, value in variables.items():
        if name != "seed":
            args += ["-var", name, str(value)]
    return args


def geometry(variables):
    g = {"W": 12, "D": 6, "H": 22, "s": 2.0}
    for k in g:
        if k in variables:
            g[k] = float(variables[k])
    return g


def deadline_passed(a):
    return a.deadline_at is not None and time.time() >= a.deadline_at


def run_granary(a, cmd, cwd):
    """Run one granary process in cwd. At the deadline it is asked to stop (SIGTERM; SIGUSR1 to
    mpirun, which passes it on to every rank): it finishes the step, writes stop.restart and exits
    with status 75. Returns (exit status, wall seconds)."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    t0 = time.time()
    with open(os.path.join(cwd, "stderr"), "w") as err:
        p = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=err, start_new_session=True)
        t_signal = None
        while True:
            try:
                p.wait(timeout=0.5)
                break
            except subprocess.TimeoutExpired:
                if t_signal is None and deadline_passed(a):
                    p.send_signal(signal.SIGUSR1 if a.np > 1 else signal.SIGTERM)
                    t_signal = time.time()
                elif t_signal is not None and time.time() - t_signal > a.grace:
                    os.killpg(p.pid, signal.SIGKILL)
    return p.returncode, time.time() - t0, t_signal is not None


def load_partial(cdir, k):
    """The state of cycle k stopped in its discharge (partial.json), or None."""
    path = os.path.join(cdir, "partial.json")
    try:
        with open(path) as f:
            state = json.load(f)
    except (OSError, ValueError):
        return None
    if state.get("cycle") != k or not os.path.exists(os.path.join(cdir, state.get("restart", "?"))):
        return None
    return state


def renumber_own_state(work, data, k):
    """A merge (merge_case) numbers another chain's cycles on from the case's last completed
    cycle, also over the number of a cycle of the case's own chain that was stopped in its
    discharge, or after the cycle whose restart file its next cycle starts from. The work folder
    holds that chain's state only: its latest stopped cycle j < k (cycle_j with partial.json) or,
    without one, its latest restart_j.restart (j < k - 1), become cycle k's (the partial cycle
    continues as cycle k, the restart file starts cycle k), so that the chain goes on where it
    stopped instead of filling a new silo; only when every cycle from j (from j + 1 after a
    restart file) to k - 1 is a merged one (the '# merged:' lines of data's cycles.csv), so that
    nothing of the chain's own completed cycles runs again (a hand-over cut between the
    cycles.csv line and the restart file leaves such files behind: that chain fills a new
    silo). Nothing of the results changes. Returns a message, or None when there was nothing to
    renumber."""
    if k == 0 or load_partial(os.path.join(work, f"cycle_{k}"), k) is not None or \
            os.path.exists(os.path.join(work, f"restart_{k - 1}.restart")):
        return None
    merged = set()
    for c in read_rows(os.path.join(data, "cycles.csv"))[0]:
        mm = MERGED.match(c)
        if mm:
            merged.update(range(int(mm.group(4)), int(mm.group(5)) + 1))
    stopped = []
    for name in os.listdir(work):
        m = re.fullmatch(r"cycle_(\d+)", name)
        j = int(m.group(1)) if m else k
        if j < k and load_partial(os.path.join(work, name), j) is not None and merged >= set(range(j, k)):
            stopped.append(j)
    if stopped:
        j = max(stopped)
        src, dst = os.path.join(work, f"cycle_{j}"), os.path.join(work, f"cycle_{k}")
        if os.path.isdir(dst):
            shutil.rmtree(dst)
        os.rename(src, dst)
        state = load_partial(dst, j)
        state["cycle"] = k
        state["renumbered_from"] = j
        write_atomic(os.path.join(dst, "partial.json"), json.dumps(state, indent=1) + "\n")
        before = os.path.join(work, f"restart_{j - 1}.restart")
        if os.path.exists(before):
            os.replace(before, os.path.join(work, f"restart_{k - 1}.restart"))
        return f"the chain's cycle {j}, stopped in its discharge, was numbered over by a merge; it continues " \
               f"as cycle {k}"
    done = [int(m.group(1)) for m in (re.fullmatch(r"restart_(\d+)\.restart", n) for n in os.listdir(work))
            if m and int(m.group(1)) < k - 1 and merged >= set(range(int(m.group(1)) + 1, k))]
    if not done:
        return None
    j = max(done)
    os.replace(os.path.join(work, f"restart_{j}.restart"), os.path.join(work, f"restart_{k - 1}.restart"))
    return f"the chain's last cycle is {j} (a merge numbered other cycles after it); cycle {k} continues from it"


def private_script(folder):
    """A copy of in.cycle in `folder` for one run to read. granary reads its input script as it
    goes (as LAMMPS does), and `jump` reads it again: an in.cycle edited in the source tree while a
    cycle runs would otherwise be read from the middle of a command, and the run fail or differ."""
    path = os.path.join(folder, "in.cycle")
    shutil.copyfile(SCRIPT, path)
    return path


def run_cycle(a, case, k, fresh, variables):
    """Run cycle k of the case (fresh: fill a new silo instead of continuing from the restart file
    of cycle k - 1), or continue it where its discharge was stopped (partial.json in its folder).
    On completion hand its rows over to the results. Returns a message."""
    data = os.path.join(a.data, case)
    work = os.path.join(a.work, case)
    cdir = os.path.join(work, f"cycle_{k}")
    state = load_partial(cdir, k)
    if state is None:
        if os.path.isdir(cdir):
            shutil.rmtree(cdir)
        os.makedirs(cdir)
        state = {"cycle": k, "fresh": fresh, "n0": None, "parts": [], "restart": None}
    fresh = state["fresh"]
    g = geometry(variables)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_silo_stl.py"), "--W", f"{g['W']:g}",
                    "--D", f"{g['D']:g}", "--H", f"{g['H']:g}", "--slit", f"{g['s']:g}", "--out", work],
                   check=True, capture_output=True)
    # part 0 runs in the cycle's folder, a continuation j in part_j/
    j = len(state["parts"])
    part = "." if j == 0 else f"part_{j}"
    pdir = os.path.normpath(os.path.join(cdir, part))
    if j > 0:
        if os.path.isdir(pdir):
            shutil.rmtree(pdir)
        os.makedirs(pdir)
    resume = (os.path.join(cdir, state["restart"]), state["n0"]) if j > 0 else None
    cmd = cycle_command(a, case, k, fresh, variables, resume, private_script(pdir))
    rc, wall, signalled = run_granary(a, cmd, pdir)
    log = os.path.join(pdir, "log")
    text = open(log, errors="replace").read() if os.path.exists(log) else ""
    if signalled and rc not in (0, STOP_STATUS):
        # the signal ended the run before it could stop cleanly (it came while granary was starting,
        # before its handlers were in place, or the grace ran out): nothing of this run is kept
        if j == 0:
            shutil.rmtree(cdir)
            return f"{case} cycle {k}: STOPPED at the deadline before the run could stop cleanly (exit {rc}); " \
                   "it runs again from its start"
        shutil.rmtree(pdir)
        return f"{case} cycle {k}: STOPPED at the deadline before the run could stop cleanly (exit {rc}); " \
               f"it continues from {os.path.join(cdir, state['restart'])}"
    if rc == STOP_STATUS:
        stop = os.path.join(pdir, "stop.restart")
        filled = re.search(r"^FILLED cycle \d+ time \S+ bodies (\S+)", text, re.M)
        if not os.path.exists(stop) or (j == 0 and not filled):
            # stopped before the discharge began: the cycle runs again from its start
            shutil.rmtree(cdir)
            return f"{case} cycle {k}: STOPPED at the deadline before its discharge; it runs again from its start"
        if j == 0:
            state["n0"] = int(float(filled.group(1)))
        old = state["restart"]
        state["parts"].append({"dir": part, "wall_s": round(wall, 1)})
        state["restart"] = os.path.relpath(stop, cdir)
        write_atomic(os.path.join(cdir, "partial.json"), json.dumps(state, indent=1) + "\n")
        if old and os.path.exists(os.path.join(cdir, old)):
            os.remove(os.path.join(cdir, old))
        return f"{case} cycle {k}: STOPPED at the deadline in its discharge; continues from {stop}"
    m = re.search(r"^CYCLE (\d+) avalanches (\S+) passed (\S+) deleted (\S+) remaining (\S+) initial (\S+) "
                  r"finished (\S+) time (\S+) steps (\S+) atoms (\S+)", text, re.M)
    restart = os.path.join(pdir, f"restart_{k}.restart")
    if rc != 0 or not m or not os.path.exists(restart):
        err = [line for line in text.splitlines() if line.startswith("ERROR")]
        return f"{case} cycle {k}: FAILED (exit {rc}){': ' + err[-1] if err else ''}; see {log}"
    finished = float(m.group(7)) == 1
    parts = [p["dir"] for p in state["parts"]] + [part]
    wall += sum(p["wall_s"] for p in state["parts"])
    # particle-steps of the cycle's runs (their "Loop time" lines), over all its parts
    psteps = 0
    for d in parts:
        with open(os.path.join(cdir, d, "log"), errors="replace") as f:
            psteps += sum(int(n) * int(m) for n, m in
                          re.findall(r"Loop time of \S+ on \d+ procs for (\d+) steps with (\d+) atoms", f.read()))
    # ---- hand over: results rows first, the cycles.csv line last
    os.makedirs(data, exist_ok=True)
    drop_uncommitted(data)
    # the last part's avalanche log holds the whole cycle (fix clog-detect keeps it in the restart file)
    av_c, av_h, av_rows = read_rows(os.path.join(pdir, "avalanches.csv"))
    if av_h is None:
        return f"{case} cycle {k}: FAILED (no avalanche file); see {log}"
    path = os.path.join(data, "avalanches.csv")
    comments, header, rows = read_rows(path)
    if header is None:
        comments = [f"# silo study case {case}: avalanches of fix clog-detect per cycle (tools/silo_study.py)",
                    "# units: SI (times s, masses kg, heights m, flow_rate kg/s); avalanche: index within its cycle"]
        comments += [c for c in av_c if c.startswith("# settings") or c.startswith("# types")]
        header = ["cycle"] + av_h
    rows += [[str(k)] + r for r in av_rows]
    write_rows(path, comments, header, rows)
    box_lines = []
    for d in parts:
        with open(os.path.join(cdir, d, "box.dat")) as f:
            box_lines += [line.split() for line in f if line.strip() and line[0] != "#"]
    path = os.path.join(data, "box.csv")
    comments, header, rows = read_rows(path)
    if header is None:
        comments = [f"# silo study case {case}: box averages (fix ave/time of in.cycle) per cycle",
                    "# box: see examples/silo_study/README.md; SI units, theta in rad; state 0 flowing"]
        header = ["cycle", "step", "time", "phi", "phi_c", "phi_s", "ke_c", "erot_c", "n_c", "ke_s", "erot_s",
                  "n_s", "theta", "state"]
    rows += [[str(k)] + [f"{float(x):.5g}" for x in line] for line in box_lines]
    write_rows(path, comments, header, rows)
    path = os.path.join(data, "cycles.csv")
    comments, header, rows = read_rows(path)
    if header is None:
        comments = [f"# silo study case {case}: completed cycles (wall time of the granary run, ranks, "
                    "particle-steps of its runs)"]
        header = ["cycle", "new_fill", "wall_s", "ranks", "steps", "sim_time_s", "atoms", "bodies_initial", "passed",
                  "deleted", "avalanches", "finished", "particle_steps"]
    rows.append([str(k), "1" if fresh else "0", f"{wall:.1f}", str(a.np), m.group(9), m.group(8), m.group(10),
                 m.group(6), m.group(3), m.group(4), m.group(2), "1" if finished else "0", str(psteps)])
    write_rows(path, comments, header, rows)
    # keep only this cycle's restart file (the chain continues from it)
    os.replace(restart, os.path.join(work, f"restart_{k}.restart"))
    old = os.path.join(work, f"restart_{k - 1}.restart")
    if k > 0 and os.path.exists(old) and not a.keep_restarts:
        os.remove(old)
    if not a.keep_work:
        shutil.rmtree(cdir)
    elif os.path.exists(os.path.join(cdir, "partial.json")):
        os.remove(os.path.join(cdir, "partial.json"))
    resumed = f" in {len(parts)} runs" if len(parts) > 1 else ""
    return (f"{case} cycle {k}: {m.group(2)} avalanches, {m.group(3)} bodies passed, {m.group(4)} deleted, "
            f"{wall:.0f} s{resumed}")


def run_case(a, case, variables):
    data = os.path.join(a.data, case)
    work = os.path.join(a.work, case)
    os.makedirs(data, exist_ok=True)
    os.makedirs(work, exist_ok=True)
    drop_uncommitted(data)
    info = {"case": case, **parse_case(case), "variables": variables, "script": os.path.relpath(SCRIPT, ROOT),
            "granary": granary_version(a.granary), "ranks": a.np,
            "command": " ".join(["tools/silo_study.py", "run", "--case", case, "--np", str(a.np)] +
                                [f"-var {k} {v}" for k, v in variables.items()])}
    case_json = os.path.join(data, "case.json")
    if os.path.exists(case_json):
        old = json.load(open(case_json))
        if old.get("variables") != variables or old.get("phi") != info["phi"]:
            return f"{case}: REFUSED: its results were made with other variables {old.get('variables')}; " \
                   f"use another --data folder"
        info["granary_versions"] = sorted(set(old.get("granary_versions", [old.get("granary")]) + [info["granary"]]))
        if "merged_chains" in old:  # the record of the merges (cycles.csv's '# merged:' lines decide)
            info["merged_chains"] = old["merged_chains"]
    else:
        info["granary_versions"] = [info["granary"]]
    write_atomic(case_json, json.dumps(info, indent=1) + "\n")
    messages = []
    while True:
        k = completed_cycles(data)
        n = nonempty_avalanches(data, a.count_first)
        if n >= a.min_avalanches:
            messages.append(f"{case}: done, {n} non-empty avalanches in {k} cycles")
            break
        if k >= a.max_cycles:
            messages.append(f"{case}: stopped at --max-cycles {a.max_cycles} with {n} non-empty avalanches")
            break
        if deadline_passed(a):
            messages.append(f"{case}: STOPPED at the deadline with {n} non-empty avalanches in {k} cycles")
            break
        moved = renumber_own_state(work, data, k)
        if moved:
            print(f"  {case} cycle {k}: {moved}", flush=True)
        fresh = k == 0 or not os.path.exists(os.path.join(work, f"restart_{k - 1}.restart"))
        if fresh and k > 0 and load_partial(os.path.join(work, f"cycle_{k}"), k) is None:
            # the chain's restart file stayed on another machine (it is not part of the results):
            # cycle k fills a new silo, with the seeds of cycle k
            print(f"  {case} cycle {k}: restart_{k - 1}.restart is not in {work}; this cycle fills a new silo",
                  flush=True)
        msg = run_cycle(a, case, k, fresh, variables)
        print("  " + msg, flush=True)
        if "FAILED" in msg or "STOPPED" in msg:
            messages.append(msg)
            break
    return "; ".join(messages)


def cmd_run(a):
    variables = {}
    for name, value in a.var or []:
        variables[name] = value
    cases = a.case or study_cases()
    for c in cases:
        parse_case(c)
    print(f"silo_study: {len(cases)} case(s), {a.jobs} at a time, {a.np} rank(s) each; data {a.data}", flush=True)
    a.deadline_at = time.time() + a.deadline if a.deadline else None
    bad = stopped = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for msg in pool.map(lambda c: run_case(a, c, variables), cases):
            print(msg, flush=True)
            bad += ("FAILED" in msg) or ("REFUSED" in msg) or ("cannot continue" in msg)
            stopped += "STOPPED" in msg
    return 1 if bad else STOP_STATUS if stopped else 0


MERGED = re.compile(r"^# merged: chain seed (\S+), its cycles (\d+)-(\d+) as cycles (\d+)-(\d+)")


def merge_case(src, dst):
    """Append the completed cycles of another chain of the same case (src: its data folder, run with
    another -var seed) to the case's results in dst, numbered on from dst's last cycle. A chain's
    cycles already merged (the '# merged:' lines of cycles.csv) are not merged again, so merging
    the same chain after it ran further adds only its new cycles. Returns a message."""
    case = os.path.basename(os.path.normpath(dst))
    try:
        with open(os.path.join(src, "case.json")) as f:
            sinfo = json.load(f)
    except (OSError, ValueError) as e:
        return f"{case}: REFUSED: no readable case.json in {src} ({e})"
    svars = dict(sinfo.get("variables", {}))
    seed = str(svars.pop("seed", "15485863"))
    _, sh, scycles = read_rows(os.path.join(src, "cycles.csv"))
    if not scycles:
        return f"{case}: nothing to merge from {src} (no completed cycle)"
    os.makedirs(dst, exist_ok=True)
    dinfo_path = os.path.join(dst, "case.json")
    if os.path.exists(dinfo_path):
        with open(dinfo_path) as f:
            dinfo = json.load(f)
        dvars = dict(dinfo.get("variables", {}))
        dseed = str(dvars.pop("seed", "15485863"))
        if dvars != svars or dinfo.get("phi") != sinfo.get("phi") or dinfo.get("r") != sinfo.get("r") or \
                dinfo.get("nres") != sinfo.get("nres") or dinfo.get("kcoh") != sinfo.get("kcoh"):
            return f"{case}: REFUSED: {src} was made with other parameters ({sinfo.get('variables')} against " \
                   f"{dinfo.get('variables')})"
        if dseed == seed:
            return f"{case}: REFUSED: {src} has the seed of the case's own chain ({seed}): the same avalanches"
    else:
        dinfo = dict(sinfo, variables={k: v for k, v in sinfo.get("variables", {}).items() if k != "seed"})
    drop_uncommitted(dst)
    comments, header, rows = read_rows(os.path.join(dst, "cycles.csv"))
    done = 0
    for c in comments:
        mm = MERGED.match(c)
        if mm and mm.group(1) == seed:
            done = max(done, int(mm.group(3)) + 1)
    new = scycles[done:]
    if not new:
        return f"{case}: chain seed {seed}: its {len(scycles)} cycles are merged already"
    n = len(rows)
    renumber = {int(r[0]): n + i for i, r in enumerate(new)}
    for name in ("avalanches.csv", "box.csv"):
        sc, shh, srows = read_rows(os.path.join(src, name))
        dc, dh, drows = read_rows(os.path.join(dst, name))
        if dh is None:
            dc, dh = sc, shh
        if shh != dh:
            return f"{case}: REFUSED: the columns of {name} differ between {src} and {dst}"
        drows += [[str(renumber[int(r[0])])] + r[1:] for r in srows if int(r[0]) in renumber]
        write_rows(os.path.join(dst, name), dc, dh, drows)
    if header is None:
        comments, header = [f"# silo study case {case}: completed cycles (wall time of the granary run, ranks, "
                            "particle-steps of its runs)"], sh
    first, last = int(new[0][0]), int(new[-1][0])
    comments.append(f"# merged: chain seed {seed}, its cycles {first}-{last} as cycles {n}-{n + len(new) - 1} "
                    f"(new_fill 0: continued from the chain's cycle before)")
    rows += [[str(renumber[int(r[0])])] + r[1:] for r in new]
    write_rows(os.path.join(dst, "cycles.csv"), comments, header, rows)
    versions = set(dinfo.get("granary_versions", [])) | set(sinfo.get("granary_versions", []))
    dinfo["granary_versions"] = sorted(versions)
    chains = dinfo.setdefault("merged_chains", {})
    chains[seed] = {"cycles": last + 1, "command": sinfo.get("command")}
    write_atomic(dinfo_path, json.dumps(dinfo, indent=1) + "\n")
    return f"{case}: chain seed {seed}: cycles {first}-{last} merged as {n}-{n + len(new) - 1}"


def cmd_merge(a):
    cases = a.case or sorted(d for d in os.listdir(a.source) if os.path.isdir(os.path.join(a.source, d)))
    bad = 0
    for c in cases:
        parse_case(c)
        msg = merge_case(os.path.join(a.source, c), os.path.join(a.data, c))
        print(msg, flush=True)
        bad += "REFUSED" in msg
    return 1 if bad else 0


def render_command():
    """The command that runs tools/render.py with ParaView, or (None, reason)."""
    if not shutil.which("pvbatch"):
        return None, "no pvbatch (Debian packages paraview, python3-paraview)"
    if os.environ.get("DISPLAY"):
        return ["pvbatch"], None
    if not shutil.which("xvfb-run"):
        return None, "no display and no xvfb-run (Debian package xvfb)"
    return ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24 -noreset", "pvbatch"], None


def cmd_picture(a):
    data = os.path.join(a.data, a.case)
    work = os.path.join(a.work, a.case)
    case_json = os.path.join(data, "case.json")
    if not os.path.exists(case_json):
        print(f"silo_study: no results of case {a.case} in {a.data}", file=sys.stderr)
        return 1
    with open(case_json) as f:
        variables = json.load(f)["variables"]
    k = completed_cycles(data)
    restart = os.path.join(work, f"restart_{k - 1}.restart")
    if k == 0 or not os.path.exists(restart):
        print(f"silo_study: case {a.case} has no restart file of its last cycle in {work}", file=sys.stderr)
        return 1
    pdir = os.path.join(work, "picture")
    if os.path.isdir(pdir):
        shutil.rmtree(pdir)
    os.makedirs(pdir)
    a.np = 1
    v = dict(variables, final="no", clog_dump="1", stop="1000", restart_out="picture.restart")
    cmd = cycle_command(a, a.case, k, False, v, script=private_script(pdir))
    cmd[cmd.index("restart_in") + 1] = os.path.abspath(restart)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    rc = subprocess.run(cmd, cwd=pdir, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                        text=True).returncode
    if rc != 0 or not os.path.exists(os.path.join(pdir, "clog_particles.vtp")):
        print(f"silo_study: the picture run failed (exit {rc}); see {os.path.join(pdir, 'log')}", file=sys.stderr)
        return 1
    render, why = render_command()
    if render is None:
        print(f"silo_study: picture skipped: {why}; the clog is in {pdir}/clog_*.vtp")
        return 0
    out = os.path.abspath(a.out)
    r = subprocess.run(render + [os.path.join(ROOT, "tools", "render.py"), pdir, "--out", out], capture_output=True,
                       text=True)
    if r.returncode != 0:
        print(f"silo_study: tools/render.py failed (exit {r.returncode}): {r.stderr.strip()[-400:]}", file=sys.stderr)
        return 1
    print(f"silo_study: picture of a clog of {a.case}: {out}")
    return 0


def case_costs(data):
    """Per case (sorted by name): (case, cycles, avalanches, non-empty
    avalanches, core-seconds, particle-steps) from its cycles.csv and
    avalanches.csv."""
    out = []
    for case in sorted(os.listdir(data)) if os.path.isdir(data) else []:
        d = os.path.join(data, case)
        if not os.path.isdir(d):
            continue
        _, h, rows = read_rows(os.path.join(d, "cycles.csv"))
        core_s = sum(float(r[h.index("wall_s")]) * int(r[h.index("ranks")]) for r in rows) if h else 0.0
        ps = sum(int(r[h.index("particle_steps")]) for r in rows) if h else 0
        _, _, arows = read_rows(os.path.join(d, "avalanches.csv"))
        out.append((case, len(rows), len(arows), nonempty_avalanches(d), core_s, ps))
    return out


def cost_markdown(data, complete=100):
    """The cost table of examples/silo_study/README.md (a case short of
    `complete` non-empty avalanches is marked "(in progress)") and the total
    core-hours."""
    costs = case_costs(data)
    lines = ["| case | cycles | non-empty avalanches | core-hours (wall x ranks) | particle-steps |",
             "|---|---:|---:|---:|---:|"]
    for case, ncyc, _, nonempty, core_s, ps in costs:
        name = case + (" (in progress)" if nonempty < complete else "")
        lines.append(f"| {name} | {ncyc} | {nonempty} | {core_s / 3600:.2f} | {ps:.2e} |")
    return "\n".join(lines), sum(c[4] for c in costs) / 3600


def cmd_status(a):
    if a.markdown:
        table, total = cost_markdown(a.data)
        print(f"{table}\n\nIn all {total:.2f} core-hours so far.")
        return 0
    print(f"{'case':18s} {'cycles':>6s} {'aval.':>6s} {'non-empty':>9s} {'core-h':>7s} {'particle-steps':>15s}"
          "   (non-empty: after an arch removal)")
    costs = case_costs(a.data)
    for case, ncyc, naval, nonempty, core_s, ps in costs:
        print(f"{case:18s} {ncyc:6d} {naval:6d} {nonempty:9d} {core_s / 3600:7.2f} {ps:15.3e}")
    print(f"total core-hours {sum(c[4] for c in costs) / 3600:.2f}")
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run (or continue) cases")
    r.add_argument("--case", action="append", help="case name (repeatable); default: the whole study")
    r.add_argument("--jobs", type=int, default=1, help="cases at a time")
    r.add_argument("--np", type=int, default=1, help="MPI ranks per case")
    r.add_argument("--data", default=DATA)
    r.add_argument("--work", default=WORK)
    r.add_argument("--granary", default=os.path.join(ROOT, "build", "granary"))
    r.add_argument("--min-avalanches", type=int, default=100,
                   help="non-empty avalanches that start at an arch removal (default 100)")
    r.add_argument("--count-first", action="store_true",
                   help="count the first avalanche of each cycle too (it starts from the opened shutter)")
    r.add_argument("--max-cycles", type=int, default=60)
    r.add_argument("--keep-work", action="store_true", help="keep each cycle's folder (logs)")
    r.add_argument("--keep-restarts", action="store_true")
    r.add_argument("--deadline", type=float, metavar="SECONDS",
                   help="stop after this many seconds: running cycles are stopped (SIGTERM) and continue "
                        "where they stopped at the next run; exit status 75")
    r.add_argument("--grace", type=float, default=120.0, metavar="SECONDS",
                   help="after the stop signal, wait this long for the restart file, then kill (default 120)")
    r.add_argument("-var", nargs=2, action="append", metavar=("NAME", "VALUE"))
    s = sub.add_parser("status", help="cycles, avalanches and cost per case")
    s.add_argument("--data", default=DATA)
    s.add_argument("--markdown", action="store_true",
                   help="print the cost table of examples/silo_study/README.md instead")
    pc = sub.add_parser("picture", help="a ParaView picture of a clog of a case")
    pc.add_argument("--case", required=True)
    pc.add_argument("--out", required=True, help="PNG to write")
    pc.add_argument("--data", default=DATA)
    pc.add_argument("--work", default=WORK)
    pc.add_argument("--granary", default=os.path.join(ROOT, "build", "granary"))
    mg = sub.add_parser("merge", help="append the completed cycles of other chains (another -var seed)")
    mg.add_argument("--from", dest="source", required=True, help="data folder of the other chains")
    mg.add_argument("--case", action="append", help="case name (repeatable); default: every case in --from")
    mg.add_argument("--data", default=DATA)
    ls = sub.add_parser("list", help="the cases of the study")
    ls.add_argument("--candidates", action="store_true",
                    help="the cases of the candidate causes of the r = 4.6 discrepancy instead")
    a = ap.parse_args(argv)
    if a.cmd == "run":
        a.granary = os.path.abspath(a.granary)
        a.data = os.path.abspath(a.data)
        a.work = os.path.abspath(a.work)
        return cmd_run(a)
    if a.cmd == "status":
        return cmd_status(a)
    if a.cmd == "merge":
        return cmd_merge(a)
    if a.cmd == "picture":
        # the picture run works in its own folder: every path absolute
        a.granary = os.path.abspath(a.granary)
        a.data = os.path.abspath(a.data)
        a.work = os.path.abspath(a.work)
        return cmd_picture(a)
    print("\n".join(candidate_cases() if a.candidates else study_cases()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
