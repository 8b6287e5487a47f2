#!/usr/bin/python3
"""Benchmark Granary against LIGGGHTS on the same input script.

Runs LIGGGHTS and Granary one after the other on the same input script (by
default examples/bench/in.bench_spheres) on 1 and 2 MPI ranks, passing
'-var dir SCRIPT_DIR' (and '-var nsteps N' when --nsteps is given, '-var NAME VALUE'
for each --var), and prints a table with wall time,
loop time, throughput (particle-steps per second), Granary/LIGGGHTS speed
ratio, parallel speed-up and peak memory.

    /usr/bin/python3 tools/bench.py --nsteps 2000
    /usr/bin/python3 tools/bench.py --only liggghts --nsteps 2000 --json out.json
    /usr/bin/python3 tools/bench.py --granary build/granary --ranks 1,2,4

What is measured, per run (each run is started from a fresh measuring subprocess):
  wall s       wall-clock time of the whole program run (start-up, setup and
               time stepping; measured around the process)
  CPU s        user + system CPU time of all processes of the run (all ranks;
               getrusage RUSAGE_CHILDREN); on a busy machine wall time grows
               but CPU time much less, so compare the two
  loop s       the time the program itself reports for its time-stepping loop,
               from its final "Loop time of X on P procs for N steps with M
               atoms" line (summed over all such lines if a script has several
               run commands)
  particles    M from the last "Loop time" line (fallback: last thermo 'Atoms')
  steps        N summed over the "Loop time" lines
  particle-steps/s   particles * steps / loop s
  contacts     mean number of particle-particle contacts, from a thermo column
               'c_contacts' (LIGGGHTS prints 'contacts'), the sum of compute
               contact/atom (each contact counted at both ends, so halved):
               the mean over the thermo lines of each run command, weighted
               by its steps; '-' when the script has no such column
  contact updates/s  contacts * steps / loop s: contact evaluations per second
  speed G/L    Granary particle-steps/s divided by LIGGGHTS particle-steps/s at
               the same number of ranks (> 1: Granary is faster)
  speed-up     particle-steps/s at P ranks divided by the same program's value
               at 1 rank
  peak RSS MiB peak resident set size summed over all MPI ranks (each rank's
               VmHWM, sampled from /proc while it runs); the largest single
               process (getrusage RUSAGE_CHILDREN ru_maxrss) is also kept in
               the JSON output as max_rank_rss_mib
  bytes/particle     peak RSS (sum over ranks) / particles
  start-up MiB peak RSS (sum over ranks) of the same program on a script with a
               box and no particles: code, shared libraries, MPI buffers
  B/particle above start-up   (peak RSS - start-up) / particles: what the
               particles and their contacts cost
A second table gives each run's time split from the programs' own end-of-run
reports (pair, neighbour lists, communication, fixes, output, other; each the
mean over the ranks, summed over the run commands; LIGGGHTS 3.8 reports fixes
under "other"), on several ranks the load imbalance max/avg of Granary's
compute sections, and for Granary the time of fix multisphere and of the wall
fixes (wall/gran, mesh/surface) from its per-fix report.

With --mpi-times (runs on more than one rank; Open MPI's mpirun and mpicc)
each rank of each run also records the wall time it spends inside blocking
MPI calls (tools/mpi_times.c, loaded with LD_PRELOAD: the transfers and the
waits for the other ranks, in the whole run, set-up included); a third table
gives per program and rank count the mean over the ranks and the slowest
rank of the calls that took the most time, and their total.

1-rank runs start the program directly, runs on more ranks go through mpirun
(Open MPI: --allow-run-as-root is added when running as root and
--oversubscribe when there are more ranks than cores).  Each run happens in
its own temporary directory with '-log none', so no files are left behind;
the script path is passed as an absolute path.  OMP_NUM_THREADS is set to 1.

Exit status: 0 if every run succeeded, 1 if a run failed, 2 for usage errors
(for example a missing executable).  Only the Python standard library is used.
"""

import argparse
import atexit
import datetime
import functools
import json
import os
import platform
import re
import resource
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_SCRIPT = os.path.join("examples", "bench", "in.bench_spheres")
DEFAULT_GRANARY = os.path.join("build", "granary")

LOOP_RE = re.compile(r"^Loop time of\s+(\S+)\s+on\s+(\d+)\s+procs?\s+for\s+(\d+)\s+steps?"
                     r"\s+with\s+(\d+)\s+atoms")
# time split at the end of a run: LIGGGHTS 3.8 / old LAMMPS ("Pair  time (%) = 1.47 (30.2)",
# the mean over ranks) and Granary / current LAMMPS ("Pair | min | avg | max | %varavg | %total")
SPLIT_OLD_RE = re.compile(r"^(Pair|Neigh|Comm|Outpt|Modify|Other)\s+time \(%\) = (\S+) \((\S+)\)")
SPLIT_NEW_RE = re.compile(r"^(Pair|Neigh|Comm|Output|Modify|Other)\s*\|\s*(\S+)\s*\|\s*(\S+)\s*\|\s*(\S+)\s*\|")
SPLIT_KEYS = {"Pair": "pair", "Neigh": "neigh", "Comm": "comm", "Outpt": "output", "Output": "output",
              "Modify": "fixes", "Other": "other"}
SPLIT_COLUMNS = ["pair", "neigh", "comm", "fixes", "output", "other"]
# Granary's per-fix lines after the section table ("fix ms multisphere | min | avg | max | ...")
FIX_RE = re.compile(r"^fix\s+(\S+)\s+(\S+)\s*\|\s*(\S+)\s*\|\s*(\S+)\s*\|\s*(\S+)\s*\|")
FIX_COLUMNS = ["multisphere", "walls"]  # of which: fix multisphere; wall/gran and mesh/surface fixes


def fix_category(style):
    if style.startswith("multisphere"):
        return "multisphere"
    if style.startswith("wall/") or style.startswith("mesh/"):
        return "walls"
    return None


# ---------------------------------------------------------------------------
# measurement mode: run one command, measure wall time and memory, write JSON
# ---------------------------------------------------------------------------

def _proc_table():
    """pid -> (ppid, comm) for all processes, from /proc."""
    table = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                data = f.read()
        except OSError:
            continue
        # comm is in parentheses and may contain spaces
        lpar, rpar = data.find("("), data.rfind(")")
        comm = data[lpar + 1:rpar]
        rest = data[rpar + 2:].split()
        try:
            table[int(entry)] = (int(rest[1]), comm)
        except (IndexError, ValueError):
            continue
    return table


def _vmhwm_kib(pid):
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except (OSError, ValueError, IndexError):
        pass
    return None


def measure_main(argv):
    """bench.py --_measure RESULT.json PROGRAM_NAME STDOUT_FILE CWD -- cmd ..."""
    result_path, prog_name, out_path, cwd = argv[:4]
    cmd = argv[5:]
    have_proc = os.path.isdir("/proc/self")
    comm_name = os.path.basename(prog_name)[:15]  # /proc comm is cut at 15 chars
    hwm = {}  # pid -> last seen VmHWM (KiB) of processes running the program
    env = dict(os.environ, OMP_NUM_THREADS="1")
    with open(out_path, "w") as out:
        t0 = time.perf_counter()
        try:
            proc = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=subprocess.STDOUT, env=env)
        except OSError as e:
            with open(result_path, "w") as f:
                json.dump({"error": "cannot start %s: %s" % (cmd[0], e)}, f)
            return 0
        while True:
            try:
                rc = proc.wait(timeout=0.05)
                break
            except subprocess.TimeoutExpired:
                pass
            if not have_proc:
                continue
            table = _proc_table()
            children = {}
            for pid, (ppid, _) in table.items():
                children.setdefault(ppid, []).append(pid)
            stack = [proc.pid]
            while stack:
                pid = stack.pop()
                if pid in table and table[pid][1] == comm_name:
                    v = _vmhwm_kib(pid)
                    if v is not None:
                        hwm[pid] = max(hwm.get(pid, 0), v)
                stack.extend(children.get(pid, []))
        wall = time.perf_counter() - t0
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    res = {
        "returncode": rc,
        "wall_s": wall,
        "max_rank_rss_kib": ru.ru_maxrss,  # Linux: KiB, largest single descendant
        "sum_rank_hwm_kib": sum(hwm.values()) if hwm else None,
        "nprocs_seen": len(hwm),
        "user_s": ru.ru_utime,
        "sys_s": ru.ru_stime,
    }
    with open(result_path, "w") as f:
        json.dump(res, f)
    return 0


# ---------------------------------------------------------------------------
# driver
# ---------------------------------------------------------------------------

def parse_output(text):
    """Loop time lines, particle count and version line of a LIGGGHTS/Granary run."""
    loops = []
    last_atoms = None
    header = None
    contact_col = None   # index of the contact column in the current thermo header
    segment = []         # its values since the last "Loop time" line
    contact_steps = 0.0  # sum over the run commands of mean contacts (both ends) * steps
    contact_runs = 0
    split = {}
    split_max = {}
    fix_split = {}
    for line in text.splitlines():
        m = FIX_RE.match(line.strip())
        if m:
            cat = fix_category(m.group(2))
            if cat:
                fix_split[cat] = fix_split.get(cat, 0.0) + float(m.group(4))
            continue
        m = SPLIT_OLD_RE.match(line.strip())
        if m:
            key = SPLIT_KEYS[m.group(1)]
            split[key] = split.get(key, 0.0) + float(m.group(2))
            continue
        m = SPLIT_NEW_RE.match(line.strip())
        if m:
            key = SPLIT_KEYS[m.group(1)]
            split[key] = split.get(key, 0.0) + float(m.group(3))
            split_max[key] = split_max.get(key, 0.0) + float(m.group(4))
            continue
        m = LOOP_RE.match(line.strip())
        if m:
            loops.append((float(m.group(1)), int(m.group(2)), int(m.group(3)), int(m.group(4))))
            if segment:
                contact_steps += sum(segment) / len(segment) * int(m.group(3))
                contact_runs += 1
            header = None
            contact_col = None
            segment = []
            continue
        words = line.split()
        if words and words[0] == "Step":
            header = words
            contact_col = next((k for k, w in enumerate(words) if w in ("c_contacts", "contacts")), None)
            continue
        if header and len(words) == len(header) and "Atoms" in header:
            try:
                last_atoms = int(float(words[header.index("Atoms")]))
                if contact_col is not None:
                    segment.append(float(words[contact_col]))
            except ValueError:
                pass
    version = ""
    for line in text.splitlines():
        if line.strip():
            version = line.strip()
            break
    info = {"version": version}
    if split:
        info["time_split_s"] = split  # mean over ranks, summed over the runs
    if split_max:
        info["time_split_max_s"] = split_max  # each section's largest rank time
    if fix_split:
        info["fix_split_s"] = fix_split  # of the fixes: multisphere, walls (means over ranks, summed over runs)
    if loops:
        info["loop_s"] = sum(l[0] for l in loops)
        info["procs"] = loops[-1][1]
        info["steps"] = sum(l[2] for l in loops)
        info["particles"] = loops[-1][3]
        if contact_runs and info["steps"] > 0:
            info["contacts"] = contact_steps / 2.0 / info["steps"]  # each contact counted at both ends
    else:
        info["particles"] = last_atoms
    return info


def resolve_exe(path, name, hint):
    """Absolute path of an executable, or exit with a clear message."""
    cand = None
    if path:
        for base in (os.getcwd(), ROOT):
            p = os.path.join(base, path)
            if os.path.isfile(p):
                cand = os.path.abspath(p)
                break
        if cand is None and os.sep not in path:
            cand = shutil.which(path)
    if cand is None or not os.access(cand, os.X_OK):
        sys.stderr.write("error: %s executable not found%s\n  %s\n"
                         % (name, (" ('%s')" % path) if path else "", hint))
        sys.exit(2)
    return cand


@functools.lru_cache(maxsize=None)
def is_open_mpi(mpirun):
    """Whether the launcher is Open MPI's (from its --version; asked once per launcher)."""
    try:
        ver = subprocess.run([mpirun, "--version"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             universal_newlines=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        ver = ""
    return "Open MPI" in ver or "OpenRTE" in ver


def mpirun_prefix(mpirun, ranks, extra):
    cmd = [mpirun]
    if is_open_mpi(mpirun):
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            cmd.append("--allow-run-as-root")
        if ranks > (os.cpu_count() or 1):
            cmd.append("--oversubscribe")
    cmd += ["-np", str(ranks)]
    cmd += extra
    return cmd


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def loadavg():
    try:
        return "%.2f %.2f %.2f" % os.getloadavg()
    except OSError:
        return "unknown"


def _measure(cmd, exe, args, keep=None):
    """Run cmd (the program exe, maybe under mpirun) under the measuring
    subprocess; returns (result dict, screen output)."""
    with tempfile.TemporaryDirectory(prefix="bench_") as tmp:
        res_path = os.path.join(tmp, "result.json")
        out_path = os.path.join(tmp, "stdout.txt")
        workdir = os.path.join(tmp, "run")
        os.mkdir(workdir)
        runner = [sys.executable, os.path.abspath(__file__), "--_measure",
                  res_path, exe, out_path, workdir, "--"] + cmd
        try:
            subprocess.run(runner, timeout=args.timeout)
            with open(res_path) as f:
                res = json.load(f)
        except subprocess.TimeoutExpired:
            res = {"error": "timed out after %s s" % args.timeout}
        except (OSError, ValueError) as e:
            res = {"error": "measurement failed: %s" % e}
        text = ""
        if os.path.exists(out_path):
            with open(out_path, errors="replace") as f:
                text = f.read()
        if keep:
            with open(keep, "w") as f:
                f.write(text)
    return res, text


def _peak_rss_mib(res, ranks):
    if res["sum_rank_hwm_kib"]:
        return res["sum_rank_hwm_kib"] / 1024.0
    return res["max_rank_rss_kib"] / 1024.0 * ranks  # no /proc sampling: largest process times ranks


# A run with a box and no particles: the memory a program holds before it has
# any particles (its code, the shared libraries it loads, MPI's buffers).
EMPTY_SCRIPT = """atom_style granular
atom_modify map array
boundary m m m
region box block 0 1 0 1 0 1 units box
create_box 1 box
"""


def startup_rss(exe, ranks, args):
    """Peak RSS (MiB, summed over the ranks) of the program on EMPTY_SCRIPT."""
    with tempfile.TemporaryDirectory(prefix="bench_empty_") as tmp:
        script = os.path.join(tmp, "in.empty")
        with open(script, "w") as f:
            f.write(EMPTY_SCRIPT)
        cmd = [exe, "-in", script, "-log", "none"]
        if ranks > 1:
            cmd = mpirun_prefix(args.mpirun_exe, ranks, shlex.split(args.mpirun_args)) + cmd
        res, _ = _measure(cmd, exe, args)
    if "error" in res or res.get("returncode") != 0:
        return None
    if ranks == 1:  # exact; a run this short may end between two samples of /proc
        return max(res["max_rank_rss_kib"], res["sum_rank_hwm_kib"] or 0) / 1024.0
    return _peak_rss_mib(res, ranks)


def run_one(prog, exe, ranks, script, nsteps, args, outdir, rep=0):
    """One run of one program; returns its row (with "error" on failure)."""
    # the script's folder, for scripts that read files next to them (meshes, clumps)
    cmd = [exe, "-in", script, "-log", "none", "-var", "dir", os.path.dirname(script)]
    if nsteps is not None:
        cmd += ["-var", "nsteps", str(nsteps)]
    for name, value in args.var:
        cmd += ["-var", name, value]
    if ranks > 1:
        extra = shlex.split(args.mpirun_args)
        if args.mpi_times_lib:
            extra = ["-x", "LD_PRELOAD=" + args.mpi_times_lib] + extra
        cmd = mpirun_prefix(args.mpirun_exe, ranks, extra) + cmd
    load_before = loadavg()
    keep = None
    if outdir:
        keep = os.path.join(outdir, "%s_np%d%s.out" % (prog, ranks, "" if args.repeat == 1 else "_rep%d" % rep))
    res, text = _measure(cmd, exe, args, keep)
    row = {"program": prog, "ranks": ranks, "command": " ".join(shlex.quote(c) for c in cmd),
           "load_average_before": load_before}
    if "error" in res:
        row["error"] = res["error"]
    elif res["returncode"] != 0:
        row["error"] = "exit status %d" % res["returncode"]
    if "error" in row:
        row["output_tail"] = text[-2000:]
        return row
    info = parse_output(text)
    row.update(info)
    mpi = parse_mpi_times(text)
    if mpi:
        row["mpi_times"] = mpi
    row["wall_s"] = res["wall_s"]
    row["cpu_user_s"] = res["user_s"]
    row["cpu_sys_s"] = res["sys_s"]
    row["cpu_s"] = res["user_s"] + res["sys_s"]
    row["max_rank_rss_mib"] = res["max_rank_rss_kib"] / 1024.0
    row["peak_rss_mib"] = _peak_rss_mib(res, ranks)
    row["rss_ranks_seen"] = res["nprocs_seen"] if res["sum_rank_hwm_kib"] else 0
    if "steps" not in row:
        row["error"] = "no 'Loop time' line in the output"
        row["output_tail"] = text[-2000:]
        return row
    t = row.get("loop_s") or row["wall_s"]
    row["particle_steps_per_s"] = row["particles"] * row["steps"] / t if t > 0 else None
    if row.get("contacts") is not None and t > 0:
        row["contact_updates_per_s"] = row["contacts"] * row["steps"] / t
    if row["particles"]:
        row["bytes_per_particle"] = row["peak_rss_mib"] * 1048576.0 / row["particles"]
    return row


def fmt(v, spec):
    if v is None:
        return "-"
    return format(v, spec)


def write_markdown(heads, lines, out):
    """Markdown table, columns padded for reading in a terminal as well."""
    widths = [max(len(h), *(len(l[i]) for l in lines)) if lines else len(h)
              for i, h in enumerate(heads)]
    def row(cells):
        return "| " + " | ".join(c.ljust(w) if i == 0 else c.rjust(w)
                                 for i, (c, w) in enumerate(zip(cells, widths))) + " |"
    out.write(row(heads) + "\n")
    out.write("|" + "|".join("-" * (w + 1) + ":" if i else "-" * (w + 2)
                             for i, w in enumerate(widths)) + "|\n")
    for l in lines:
        out.write(row(l) + "\n")


def print_table(rows, out=sys.stdout):
    heads = ["program", "ranks", "particles", "steps", "wall s", "loop s", "CPU s", "particle-steps/s",
             "contacts", "contact updates/s", "speed G/L", "speed-up", "peak RSS MiB", "bytes/particle",
             "start-up MiB", "B/particle above start-up"]
    lines = []
    for r in rows:
        if "error" in r:
            lines.append([r["program"], str(r["ranks"]), "FAILED"] + ["-"] * 13)
            continue
        lines.append([r["program"], str(r["ranks"]), fmt(r.get("particles"), "d"),
                      fmt(r.get("steps"), "d"), fmt(r.get("wall_s"), ".2f"),
                      fmt(r.get("loop_s"), ".2f"), fmt(r.get("cpu_s"), ".2f"),
                      fmt(r.get("particle_steps_per_s"), ".4g"), fmt(r.get("contacts"), ".0f"),
                      fmt(r.get("contact_updates_per_s"), ".4g"), fmt(r.get("speed_ratio"), ".2f"), fmt(r.get("speedup"), ".2f"),
                      fmt(r.get("peak_rss_mib"), ".1f"), fmt(r.get("bytes_per_particle"), ".0f"),
                      fmt(r.get("startup_rss_mib"), ".1f"), fmt(r.get("bytes_per_particle_above_startup"), ".0f")])
    write_markdown(heads, lines, out)


def print_split(rows, out=sys.stdout):
    """Time split of each run: mean over the ranks of each section, seconds summed over the runs."""
    have = [r for r in rows if "error" not in r and r.get("time_split_s")]
    if not have:
        return
    heads = (["program", "ranks"] + ["%s s" % c for c in SPLIT_COLUMNS] + ["max/avg"] +
             ["%s s" % c for c in FIX_COLUMNS])
    lines = []
    for r in have:
        sp = r["time_split_s"]
        cells = [r["program"], str(r["ranks"])]
        for c in SPLIT_COLUMNS:
            cells.append(fmt(sp.get(c), ".2f"))
        fx = r.get("fix_split_s") or {}
        # load imbalance: the compute sections' largest rank times over their
        # means (summed; at least the slowest rank's share, so an upper bound)
        mx = r.get("time_split_max_s")
        if mx and r["ranks"] > 1:
            busy = sum(sp.get(c, 0.0) for c in ("pair", "neigh", "fixes"))
            busy_max = sum(mx.get(c, 0.0) for c in ("pair", "neigh", "fixes"))
            cells.append(fmt(busy_max / busy if busy > 0 else None, ".2f"))
        else:
            cells.append("-")
        for c in FIX_COLUMNS:
            cells.append(fmt(fx.get(c), ".2f") if fx else "-")
        lines.append(cells)
    write_markdown(heads, lines, out)


MPI_TIMES_RE = re.compile(r"^mpi_times rank (\d+):(.*)$")


def build_mpi_times():
    """Compile tools/mpi_times.c into a temporary folder (removed at exit);
    returns (path of the library, None) or (None, the reason)."""
    mpicc = shutil.which("mpicc")
    if not mpicc:
        return None, "mpicc not found (Debian: package libopenmpi-dev)"
    out = tempfile.mkdtemp(prefix="bench_mpi_times_")
    atexit.register(shutil.rmtree, out, True)
    lib = os.path.join(out, "libmpi_times.so")
    res = subprocess.run([mpicc, "-O2", "-shared", "-fPIC", os.path.join(ROOT, "tools", "mpi_times.c"), "-o", lib],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    if res.returncode != 0:
        return None, "mpicc failed:\n" + res.stdout
    return lib, None


def parse_mpi_times(text):
    """The lines of tools/mpi_times.c: {"ranks": n, "calls": {name: count summed
    over the ranks}, "mean_s": {name: mean over the ranks}, "max_s": {name:
    slowest rank}, "total_mean_s", "total_max_s"}; None without such lines."""
    per_rank = {}
    for line in text.splitlines():
        m = MPI_TIMES_RE.match(line.strip())
        if not m:
            continue
        calls = {}
        for item in m.group(2).split(";"):
            parts = item.split()
            if len(parts) == 3:
                calls[parts[0]] = (int(parts[1]), float(parts[2]))
        per_rank[int(m.group(1))] = calls
    if not per_rank:
        return None
    n = len(per_rank)
    names = sorted({k for c in per_rank.values() for k in c})
    out = {"ranks": n, "calls": {}, "mean_s": {}, "max_s": {}}
    for k in names:
        secs = [c.get(k, (0, 0.0))[1] for c in per_rank.values()]
        out["calls"][k] = sum(c.get(k, (0, 0.0))[0] for c in per_rank.values())
        out["mean_s"][k] = sum(secs) / n
        out["max_s"][k] = max(secs)
    totals = [sum(s for _, s in c.values()) for c in per_rank.values()]
    out["total_mean_s"] = sum(totals) / n
    out["total_max_s"] = max(totals)
    return out


def print_mpi_times(rows, out=sys.stdout, ncalls=4):
    """Per run: the calls that took the most time (mean over the ranks / slowest rank, s)."""
    have = [r for r in rows if "error" not in r and r.get("mpi_times")]
    if not have:
        return
    total = {}
    for r in have:
        for k, v in r["mpi_times"]["mean_s"].items():
            total[k] = total.get(k, 0.0) + v
    names = sorted(total, key=lambda k: -total[k])[:ncalls]
    heads = (["program", "ranks", "loop s"] + ["MPI_%s s (calls)" % k for k in names] +
             ["all MPI s", "all MPI / loop"])
    lines = []
    for r in have:
        m = r["mpi_times"]
        cells = [r["program"], str(r["ranks"]), fmt(r.get("loop_s"), ".2f")]
        for k in names:
            if k in m["mean_s"]:
                cells.append("%.3f / %.3f (%d)" % (m["mean_s"][k], m["max_s"][k], m["calls"][k]))
            else:
                cells.append("-")
        cells.append("%.3f / %.3f" % (m["total_mean_s"], m["total_max_s"]))
        loop = r.get("loop_s")
        cells.append(fmt(m["total_mean_s"] / loop if loop else None, ".3f"))
        lines.append(cells)
    write_markdown(heads, lines, out)


def main(argv):
    if argv and argv[0] == "--_measure":
        return measure_main(argv[1:])

    ap = argparse.ArgumentParser(
        description="Run LIGGGHTS and Granary on the same input script on 1 and 2 MPI ranks "
                    "and compare speed and memory.",
        epilog="See the module docstring (head of tools/bench.py) for what each column means.")
    ap.add_argument("script", nargs="?", default=None,
                    help="input script (default: %s)" % DEFAULT_SCRIPT)
    ap.add_argument("--nsteps", type=int, default=None,
                    help="pass '-var nsteps N' to both programs (default: the script's own value)")
    ap.add_argument("--var", nargs=2, action="append", default=[], metavar=("NAME", "VALUE"),
                    help="pass '-var NAME VALUE' to both programs (repeatable)")
    ap.add_argument("--ranks", default="1,2", help="comma-separated MPI rank counts (default: 1,2)")
    ap.add_argument("--granary", default=DEFAULT_GRANARY,
                    help="Granary executable (default: %s, relative to the current directory or "
                         "the repository root)" % DEFAULT_GRANARY)
    ap.add_argument("--liggghts", default=None,
                    help="LIGGGHTS executable (default: 'liggghts' found on PATH)")
    ap.add_argument("--only", choices=["liggghts", "granary"],
                    help="run only this program")
    ap.add_argument("--json", metavar="FILE", help="also write all results to FILE as JSON")
    ap.add_argument("--repeat", type=int, default=1,
                    help="run each case this many times, the programs taking turns, and keep "
                         "the fastest (default: 1)")
    ap.add_argument("--timeout", type=float, default=None, help="time limit per run in seconds")
    ap.add_argument("--mpirun", default="mpirun", help="MPI launcher (default: mpirun on PATH)")
    ap.add_argument("--mpirun-args", default="", help="extra launcher arguments, e.g. '--bind-to none'")
    ap.add_argument("--mpi-times", action="store_true",
                    help="record each rank's time inside blocking MPI calls (runs on more than 1 rank; "
                         "needs Open MPI's mpirun and mpicc; see tools/mpi_times.c)")
    ap.add_argument("--keep-output", metavar="DIR",
                    help="save each run's screen output in DIR as PROGRAM_npRANKS.out")
    args = ap.parse_args(argv)

    try:
        ranks_list = [int(x) for x in args.ranks.split(",") if x.strip()]
        if not ranks_list or min(ranks_list) < 1:
            raise ValueError
    except ValueError:
        ap.error("--ranks must be a comma-separated list of positive integers")
    if args.repeat < 1:
        ap.error("--repeat must be at least 1")

    script = args.script or DEFAULT_SCRIPT
    for base in (os.getcwd(), ROOT):
        if os.path.isfile(os.path.join(base, script)):
            script = os.path.abspath(os.path.join(base, script))
            break
    else:
        sys.stderr.write("error: input script not found: %s\n" % script)
        return 2

    programs = []
    if args.only != "granary":
        programs.append(("liggghts", resolve_exe(
            args.liggghts or "liggghts", "LIGGGHTS",
            "put 'liggghts' on PATH or pass --liggghts PATH")))
    if args.only != "liggghts":
        programs.append(("granary", resolve_exe(
            args.granary, "Granary",
            "build it first (cmake -B build && cmake --build build), pass --granary PATH, "
            "or run only LIGGGHTS with --only liggghts")))
    args.mpirun_exe = None
    if max(ranks_list) > 1:
        args.mpirun_exe = shutil.which(args.mpirun) or (
            args.mpirun if os.access(args.mpirun, os.X_OK) else None)
        if not args.mpirun_exe:
            sys.stderr.write("error: MPI launcher '%s' not found (needed for more than 1 rank); "
                             "pass --mpirun or use --ranks 1\n" % args.mpirun)
            return 2
    args.mpi_times_lib = None
    if args.mpi_times:
        if max(ranks_list) < 2:
            ap.error("--mpi-times needs a rank count above 1 in --ranks")
        if not is_open_mpi(args.mpirun_exe):
            sys.stderr.write("error: --mpi-times passes the library with Open MPI's 'mpirun -x'; "
                             "'%s' is not Open MPI's\n" % args.mpirun_exe)
            return 2
        args.mpi_times_lib, err = build_mpi_times()
        if not args.mpi_times_lib:
            sys.stderr.write("error: --mpi-times: %s\n" % err)
            return 2
    if args.keep_output:
        os.makedirs(args.keep_output, exist_ok=True)

    rel_script = os.path.relpath(script, ROOT) if script.startswith(ROOT + os.sep) else script
    print("script: %s%s" % (rel_script, "" if args.nsteps is None else "  (-var nsteps %d)" % args.nsteps))
    print("machine: %s, %d cores; %s; load average before: %s"
          % (cpu_model(), os.cpu_count() or 0, datetime.datetime.now().strftime("%Y-%m-%d %H:%M"),
             loadavg()))
    sys.stdout.flush()

    # With --repeat the programs take turns (LIGGGHTS, Granary, LIGGGHTS, ...),
    # so that a change of the machine's load during the runs affects both
    # alike; each case keeps its fastest run, a failed case its first failure.
    best = {}
    for rep in range(args.repeat):
        for prog, exe in programs:
            for ranks in ranks_list:
                key = (prog, ranks)
                if key in best and "error" in best[key]:
                    continue
                sys.stdout.write("running %s on %d rank%s%s ... " % (
                    prog, ranks, "" if ranks == 1 else "s",
                    "" if args.repeat == 1 else " (run %d of %d)" % (rep + 1, args.repeat)))
                sys.stdout.flush()
                r = run_one(prog, exe, ranks, script, args.nsteps, args, args.keep_output, rep)
                print("FAILED (%s)" % r["error"] if "error" in r else "%.2f s" % r["wall_s"])
                if "error" in r and r.get("output_tail"):
                    sys.stdout.flush()
                    sys.stderr.write("---- last output of %s on %d rank(s):\n%s\n----\n"
                                     % (prog, ranks, r["output_tail"].rstrip()))
                    sys.stderr.flush()
                if ("error" in r or key not in best
                        or r["particle_steps_per_s"] > best[key]["particle_steps_per_s"]):
                    best[key] = r
    rows = [best[(prog, ranks)] for prog, _ in programs for ranks in ranks_list]

    ok = [r for r in rows if "error" not in r]
    for r in ok:
        base = [b for b in ok if b["program"] == r["program"] and b["ranks"] == 1]
        if r["ranks"] > 1 and base:
            r["speedup"] = r["particle_steps_per_s"] / base[0]["particle_steps_per_s"]
        if r["program"] == "granary":
            ref = [b for b in ok if b["program"] == "liggghts" and b["ranks"] == r["ranks"]]
            if ref:
                r["speed_ratio"] = r["particle_steps_per_s"] / ref[0]["particle_steps_per_s"]
    # the memory each program holds before it has particles, and what the
    # particles add on top of it
    exes = dict(programs)
    for r in ok:
        if not r.get("particles"):
            continue
        start = startup_rss(exes[r["program"]], r["ranks"], args)
        if start is not None:
            r["startup_rss_mib"] = start
            r["bytes_per_particle_above_startup"] = (r["peak_rss_mib"] - start) * 1048576.0 / r["particles"]

    print()
    for prog, _ in programs:
        vers = [r["version"] for r in ok if r["program"] == prog and r.get("version")]
        if vers:
            print("%s: %s" % (prog, vers[0]))
    print()
    print_table(rows)
    for r in rows:
        if "error" in r:
            print("%s on %d rank(s) FAILED: %s" % (r["program"], r["ranks"], r["error"]))
    print()
    print("particle-steps/s = particles x steps / loop s; speed G/L = Granary / LIGGGHTS "
          "particle-steps/s at equal ranks;")
    print("speed-up = vs. 1 rank of the same program; CPU s = user + system time of all ranks;")
    print("peak RSS = sum of the ranks' peak resident set sizes; start-up = the same for a script with a box")
    print("and no particles; B/particle above start-up = (peak RSS - start-up) / particles.")
    if any(r.get("time_split_s") for r in ok):
        print()
        print("time split (each section's mean over the ranks, s; LIGGGHTS 3.8 counts fixes under other;")
        print("max/avg = pair + neigh + fixes, each at its slowest rank, over their means; multisphere and")
        print("walls = Granary's own per-fix times, the means over the ranks of fix multisphere and of the")
        print("wall/gran and mesh/surface fixes, in all their hooks, also those counted under neigh):")
        print_split(rows)
    if any(r.get("mpi_times") for r in ok):
        print()
        print("time inside blocking MPI calls (tools/mpi_times.c; the whole run, set-up included; mean over")
        print("the ranks / slowest rank, s; calls summed over the ranks; all MPI / loop = the mean's share of")
        print("the loop time):")
        print_mpi_times(rows)

    if args.json:
        doc = {
            "script": rel_script,
            "nsteps": args.nsteps,
            "ranks": ranks_list,
            "repeat": args.repeat,
            "machine": {"cpu": cpu_model(), "cores": os.cpu_count(), "system": platform.platform(),
                        "load_average_after": loadavg()},
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "results": rows,
        }
        with open(args.json, "w") as f:
            json.dump(doc, f, indent=2)
            f.write("\n")
        print("results written to %s" % args.json)
    return 0 if len(ok) == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
