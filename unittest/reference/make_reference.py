#!/usr/bin/python3
"""Regenerate (or check) the LIGGGHTS reference data in unittest/reference/.

For every input script unittest/scripts/in.NAME this runs LIGGGHTS on one MPI
rank from the repository root,

    liggghts -in unittest/scripts/in.NAME -log unittest/reference/NAME.liggghts.log

keeps the raw log as NAME.liggghts.log and writes the thermo table to
NAME.liggghts.csv (comment lines starting with '#' record the LIGGGHTS
version, the command and the date; then a header row and one row per thermo
output, values copied verbatim from the log).

    /usr/bin/python3 unittest/reference/make_reference.py            # all scripts
    /usr/bin/python3 unittest/reference/make_reference.py pour_small # one script
    /usr/bin/python3 unittest/reference/make_reference.py --check    # rerun, compare

--check runs LIGGGHTS again in a temporary directory and compares its thermo
table with the stored CSV without changing anything (exit status 1 on a
difference).  LIGGGHTS is looked up on PATH unless --liggghts is given.
Only the Python standard library is used.
"""

import argparse
import datetime
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCRIPTS = os.path.join(ROOT, "unittest", "scripts")

# LIGGGHTS thermo header names -> thermo_style keywords
HEADER_TO_KEYWORD = {
    "Step": "step", "Atoms": "atoms", "KinEng": "ke", "Time": "time",
    "CPU": "cpu", "Volume": "vol", "Dt": "dt", "Elapsed": "elapsed",
}


def parse_thermo(text):
    """Return (columns, rows) of all thermo blocks in a LIGGGHTS/LAMMPS log.

    A block starts with a line whose first word is 'Step' and ends at the
    'Loop time' line; lines in between that do not have the right number of
    numeric fields (warnings, messages) are skipped.  A row that repeats the
    step of the previous row (the first row of a follow-up run) is dropped.
    """
    columns, rows = None, []
    ncol = 0
    inside = False
    for line in text.splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == "Step":
            names = [HEADER_TO_KEYWORD.get(w, w.lower()) for w in words]
            if columns is None:
                columns = names
            elif names != columns:
                raise ValueError("thermo columns change between runs: %s -> %s" % (columns, names))
            ncol = len(names)
            inside = True
            continue
        if words[0] == "Loop" and line.startswith("Loop time"):
            inside = False
            continue
        if not inside or len(words) != ncol:
            continue
        try:
            [float(w) for w in words]
        except ValueError:
            continue
        if rows and rows[-1][0] == words[0]:
            continue
        rows.append(words)
    if columns is None:
        raise ValueError("no thermo output found")
    return columns, rows


def find_liggghts(explicit):
    exe = explicit or shutil.which("liggghts")
    if not exe or not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
        sys.exit("error: LIGGGHTS executable not found (%s); put 'liggghts' on PATH or pass --liggghts"
                 % (explicit or "not on PATH"))
    return exe


def run_liggghts(exe, script_rel, log_path, cwd):
    cmd = [exe, "-in", script_rel, "-log", log_path]
    proc = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout[-3000:])
        sys.exit("error: LIGGGHTS failed on %s (exit status %d)" % (script_rel, proc.returncode))
    version = proc.stdout.splitlines()[0].strip() if proc.stdout else "unknown"
    return version


def write_csv(path, columns, rows, header_lines):
    with open(path, "w") as f:
        for h in header_lines:
            f.write("# %s\n" % h)
        f.write(",".join(columns) + "\n")
        for r in rows:
            f.write(",".join(r) + "\n")


def read_csv(path):
    columns, rows = None, []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            if columns is None:
                columns = line.split(",")
            else:
                rows.append(line.split(","))
    return columns, rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("names", nargs="*",
                    help="script names (NAME of unittest/scripts/in.NAME); default: all")
    ap.add_argument("--liggghts", help="LIGGGHTS executable (default: 'liggghts' on PATH)")
    ap.add_argument("--check", action="store_true",
                    help="rerun and compare with the stored CSV files, change nothing")
    args = ap.parse_args()

    exe = find_liggghts(args.liggghts)
    names = args.names or sorted(f[3:] for f in os.listdir(SCRIPTS) if f.startswith("in."))
    status = 0
    for name in names:
        script_rel = os.path.join("unittest", "scripts", "in." + name)
        if not os.path.isfile(os.path.join(ROOT, script_rel)):
            sys.exit("error: no such script: %s" % script_rel)
        csv_path = os.path.join(HERE, name + ".liggghts.csv")
        if args.check:
            with tempfile.TemporaryDirectory() as tmp:
                log = os.path.join(tmp, "log")
                run_liggghts(exe, os.path.join(ROOT, script_rel), log, tmp)
                with open(log) as f:
                    columns, rows = parse_thermo(f.read())
            if not os.path.isfile(csv_path):
                print("%s: no stored reference %s" % (name, os.path.relpath(csv_path, ROOT)))
                status = 1
                continue
            ref_cols, ref_rows = read_csv(csv_path)
            if (ref_cols, ref_rows) == (columns, rows):
                print("%s: identical (%d rows)" % (name, len(rows)))
            else:
                ndiff = sum(1 for a, b in zip(ref_rows, rows) if a != b) + abs(len(ref_rows) - len(rows))
                print("%s: DIFFERS from stored reference (%d of %d rows)" % (name, ndiff, len(ref_rows)))
                status = 1
            continue

        log_rel = os.path.join("unittest", "reference", name + ".liggghts.log")
        version = run_liggghts(exe, script_rel, log_rel, ROOT)
        with open(os.path.join(ROOT, log_rel)) as f:
            columns, rows = parse_thermo(f.read())
        now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
        write_csv(csv_path, columns, rows, [
            "LIGGGHTS reference thermo output for unittest/scripts/in.%s" % name,
            "version: %s" % version,
            "command (from the repository root, 1 MPI rank): liggghts -in %s -log %s" % (script_rel, log_rel),
            "date: %s" % now,
            "columns: thermo_style custom keywords; ke = translational kinetic energy [J],",
            "  rke = c_rke = compute erotate/sphere [J]; thermo_modify norm no (totals, not per atom)",
        ])
        print("%s: %d rows -> %s" % (name, len(rows), os.path.relpath(csv_path, ROOT)))
    return status


if __name__ == "__main__":
    sys.exit(main())
