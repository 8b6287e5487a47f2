#!/usr/bin/python3
"""Soak test: a silo campaign interrupted again and again must give the results of an uninterrupted one.

Runs a small case of the silo study (tools/silo_study.py, a tiny silo or the demo's)
once without interruption (the reference), then again in rounds, each round in
fresh folders, interrupting it at random moments until the case is complete:

  SIGKILL  to the driver, mpirun and every rank at once (a node that dies, a
           job killed without warning); the driver is started again, the cycle
           that was running runs again from its start (or from where a
           stopped cycle had stopped)
  SIGTERM  to the rank(s) (SIGUSR1 to mpirun, which passes it on): a batch
           system's time limit; granary finishes the step, writes
           stop.restart and exits with status 75, the driver records where the
           cycle stopped, and the next start continues it from there

Each completed round must give the reference's avalanche log byte for byte,
the same cycles (steps, bodies passed and deleted, avalanches), box averages
that are the reference's rows (a window cut by a SIGTERM stop is not written),
no file under a final name that cannot be read (every CSV parses, the last
restart file is read by granary), and it reports the temporary files that a
SIGKILL left while a file was being written (hidden `.NAME.tmp-*` files,
harmless). Rounds are run until --kills interruptions have happened.

    /usr/bin/python3 tools/soak.py [--kills 50] [--np 2] [--seed 1] [--out DIR] [--size tiny|demo]
                     [--granary EXE] [--case r3.2_phi0.05] [--min-avalanches 8] [--max-cycles 3]

Exit status 0 when every round matched the reference, 1 otherwise. Not part of
the test suite (it takes tens of minutes); its figures are in doc/clusters.md.
"""
import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import silo_study as st  # noqa: E402

GEOMETRY = {
    # the driver test's silo (unittest/python/test_silo_study.py): 7 x 2 dc, cycles of seconds
    "tiny": ["-var", "W", "7", "-var", "D", "2", "-var", "H", "11", "-var", "s", "2.3", "-var", "fill", "7",
             "-var", "stop", "4.5", "-var", "column_w", "3", "-var", "box_w", "4", "-var", "box_h", "1.5",
             "-var", "box_z", "1", "-var", "settle", "0.12", "-var", "box_every", "500"],
    # the demo's (tools/demo.sh): 8 x 4 dc, cycles of minutes
    "demo": ["-var", "W", "8", "-var", "D", "4", "-var", "H", "16", "-var", "s", "2.0", "-var", "fill", "12",
             "-var", "stop", "8", "-var", "column_w", "3", "-var", "box_w", "4", "-var", "box_h", "3",
             "-var", "box_z", "2.5", "-var", "settle", "0.15", "-var", "box_every", "500"]}
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")


def driver(a, base):
    return [sys.executable, os.path.join(ROOT, "tools", "silo_study.py"), "run", "--case", a.case, "--np", str(a.np),
            "--granary", a.granary, "--data", os.path.join(base, "data"), "--work", os.path.join(base, "work"),
            "--min-avalanches", str(a.min_avalanches), "--max-cycles", str(a.max_cycles)] + GEOMETRY[a.size]


def descendants(pid):
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        for task in os.listdir(f"/proc/{p}/task") if os.path.isdir(f"/proc/{p}/task") else []:
            try:
                with open(f"/proc/{p}/task/{task}/children") as f:
                    kids = [int(w) for w in f.read().split()]
            except OSError:
                kids = []
            out += kids
            todo += kids
    return out


def kill_all(pid):
    """SIGKILL to a driver and everything it started (granary runs in sessions of their own)."""
    for q in [pid] + descendants(pid):
        try:
            os.kill(q, signal.SIGKILL)
        except ProcessLookupError:
            pass


def process_name(pid):
    try:
        with open(f"/proc/{pid}/comm") as f:
            return f.read().strip()
    except OSError:
        return ""


def term_ranks(driver_pid, np_):
    """SIGTERM to granary (1 rank) or SIGUSR1 to mpirun. Returns whether a process got it."""
    for p in descendants(driver_pid):
        name = process_name(p)
        if np_ > 1 and name in ("mpirun", "orterun", "mpiexec"):
            os.kill(p, signal.SIGUSR1)
            return True
        if np_ == 1 and name.startswith("granary"):
            os.kill(p, signal.SIGTERM)
            return True
    return False


def compare(a, ref, base, sigterms):
    """Problems of a completed round against the reference ([] = identical)."""
    problems = []
    d, r = os.path.join(base, "data", a.case), os.path.join(ref, "data", a.case)
    with open(os.path.join(d, "avalanches.csv")) as f, open(os.path.join(r, "avalanches.csv")) as g:
        if f.read() != g.read():
            problems.append("avalanches.csv differs from the uninterrupted run's")
    _, h, rows = st.read_rows(os.path.join(d, "cycles.csv"))
    _, _, ref_rows = st.read_rows(os.path.join(r, "cycles.csv"))
    keys = [h.index(k) for k in ("cycle", "steps", "passed", "deleted", "avalanches")]
    if [[x[k] for k in keys] for x in rows] != [[x[k] for k in keys] for x in ref_rows]:
        problems.append("cycles.csv differs (cycle, steps, passed, deleted, avalanches)")
    _, _, box = st.read_rows(os.path.join(d, "box.csv"))
    _, _, ref_box = st.read_rows(os.path.join(r, "box.csv"))
    if not all(row in ref_box for row in box):
        problems.append("box.csv has rows the uninterrupted run does not have")
    if len(box) < len(ref_box) - sigterms:
        problems.append(f"box.csv misses {len(ref_box) - len(box)} rows after {sigterms} SIGTERM stops")
    last = os.path.join(base, "work", a.case, f"restart_{len(rows) - 1}.restart")
    check = os.path.join(base, "check.in")
    with open(check, "w") as f:
        f.write(f"atom_style granular\nread_restart {last}\n")
    rc = subprocess.run([a.granary, "-in", check, "-log", "none", "-screen", "none"], env=ENV).returncode
    if rc != 0:
        problems.append(f"the last restart file {last} cannot be read (exit {rc})")
    return problems


def temporaries(base):
    return [os.path.join(dp, f) for dp, _, fs in os.walk(base) for f in fs if ".tmp" in f]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--kills", type=int, default=50, help="interruptions in all (default 50)")
    ap.add_argument("--np", type=int, default=2, help="MPI ranks (default 2)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the random moments and kinds")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "soak"))
    ap.add_argument("--granary", default=os.path.join(ROOT, "build", "granary"))
    ap.add_argument("--case", default="r3.2_phi0.05")
    ap.add_argument("--size", choices=sorted(GEOMETRY), default="tiny", help="silo size (default tiny)")
    ap.add_argument("--min-avalanches", type=int, default=8)
    ap.add_argument("--max-cycles", type=int, default=3)
    a = ap.parse_args(argv)
    a.granary = os.path.abspath(a.granary)
    rng = random.Random(a.seed)
    if os.path.isdir(a.out):
        shutil.rmtree(a.out)
    ref = os.path.join(a.out, "reference")
    t0 = time.time()
    r = subprocess.run(driver(a, ref), env=ENV, capture_output=True, text=True)
    t_ref = time.time() - t0
    if r.returncode != 0:
        print(r.stdout + r.stderr)
        print("soak: the uninterrupted run failed", file=sys.stderr)
        return 1
    n_cycles = len(st.read_rows(os.path.join(ref, "data", a.case, "cycles.csv"))[2])
    print(f"soak: reference {a.case} on {a.np} rank(s): {n_cycles} cycles, "
          f"{st.nonempty_avalanches(os.path.join(ref, 'data', a.case))} non-empty avalanches, {t_ref:.0f} s",
          flush=True)
    # interrupt within a cycle's length, often enough to land in fills, discharges and hand-overs
    longest = t_ref / max(n_cycles, 1)
    totals = {"SIGKILL": 0, "SIGTERM": 0, "rounds": 0, "starts": 0, "temporaries": 0}
    failures = []
    while totals["SIGKILL"] + totals["SIGTERM"] < a.kills:
        totals["rounds"] += 1
        base = os.path.join(a.out, f"round_{totals['rounds']}")
        sigterms = 0
        while True:
            totals["starts"] += 1
            p = subprocess.Popen(driver(a, base), env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                 start_new_session=True)
            left = a.kills - totals["SIGKILL"] - totals["SIGTERM"]
            wait = rng.uniform(0.3, 1.2 * longest) if left > 0 else None
            try:
                p.wait(timeout=wait)
            except subprocess.TimeoutExpired:
                if rng.random() < 0.5:
                    kill_all(p.pid)
                    totals["SIGKILL"] += 1
                elif term_ranks(p.pid, a.np):
                    totals["SIGTERM"] += 1
                    sigterms += 1
                else:  # between two granary runs: nothing to signal, kill instead
                    kill_all(p.pid)
                    totals["SIGKILL"] += 1
                try:  # after a SIGTERM the driver ends once its run has stopped
                    p.wait(timeout=300)
                except subprocess.TimeoutExpired:
                    kill_all(p.pid)
                    p.wait()
                continue
            if p.returncode == 0:
                break
            if p.returncode != st.STOP_STATUS:
                failures.append(f"round {totals['rounds']}: the driver failed (exit {p.returncode})")
                break
        # the machine's load changes: interrupt within the cycle length of the round just done
        _, h, rows = st.read_rows(os.path.join(base, "data", a.case, "cycles.csv"))
        if rows:
            longest = max(1.0, max(float(x[h.index("wall_s")]) for x in rows))
        problems = compare(a, ref, base, sigterms)
        tmp = temporaries(base)
        totals["temporaries"] += len(tmp)
        print(f"soak: round {totals['rounds']}: {'identical' if not problems else '; '.join(problems)}; "
              f"interruptions so far {totals['SIGKILL']} SIGKILL, {totals['SIGTERM']} SIGTERM; "
              f"temporary files left {len(tmp)}", flush=True)
        failures += [f"round {totals['rounds']}: {x}" for x in problems]
    summary = dict(totals, case=a.case, size=a.size, ranks=a.np, seed=a.seed, reference_s=round(t_ref, 1),
                   wall_s=round(time.time() - t0, 1), failures=failures)
    with open(os.path.join(a.out, "soak.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print(f"soak: {totals['SIGKILL'] + totals['SIGTERM']} interruptions ({totals['SIGKILL']} SIGKILL, "
          f"{totals['SIGTERM']} SIGTERM) in {totals['rounds']} rounds, {totals['starts']} driver starts, "
          f"{summary['wall_s']:.0f} s; results {'identical to' if not failures else 'DIFFERENT from'} the "
          f"uninterrupted run; temporary files left by SIGKILL: {totals['temporaries']}")
    for x in failures:
        print("  " + x)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
