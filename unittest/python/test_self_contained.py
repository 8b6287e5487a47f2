"""Everything a test, example or tool needs lives inside the repository.

Scans every file of the repository (the files git tracks, or every file but
build folders outside a git checkout) for paths that leave it:
  * the folder beside a developer's clone that users do not have (".." + "/shared"),
  * absolute paths outside the system folders that Debian's packages fill
    (/usr, /etc, /dev, /proc, ...): e.g. /work/..., /home/..., /root/...,
  * relative paths in machine-read files (scripts, sources, JSON, CMake) that
    climb above the repository from the file's own folder.
Also checks that the scan itself finds such paths in made-up text.
"""
import fnmatch
import os
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

# The forbidden folder, spelled so that this file does not contain it.
OUTSIDE_FOLDER = ".." + "/" + "shared"
# ... also when a path is joined from parts: os.path.join(here, "..", "..", "shared")
OUTSIDE_JOINED = re.compile(r"""\.\.["']\s*,\s*["']""" + "shared" + r"""["']""")
# First components of absolute paths that name system folders (installed
# packages, devices, kernel files, scratch) or a path a test uses as missing.
SYSTEM_ROOTS = {"usr", "etc", "dev", "proc", "sys", "bin", "sbin", "lib", "lib64", "var", "run",
                "tmp", "nonexistent"}
# "/name/" where a path can start (not inside a/b/c, $X/..., <dir>/..., */...)
ABSOLUTE = re.compile(r"(?<![\w.$}/:~\\*>-])/([A-Za-z_][\w.+-]*)/")
# a string literal appended to a folder variable: dir + "/post/x"
APPENDED = re.compile(r"(\+|<<)\s*[\"']$")
CLIMB = re.compile(r"(?<![\w./-])((?:\.\./)+)([\w.-]*)")
MACHINE_READ = re.compile(r"(\.(py|sh|cpp|h|json|txt|cmake|in|clump)|/in\.[\w.-]+|/CMakeLists\.txt|/run)$")
SKIP_DIRS = {".git", "out"}
# .gitignore: patterns anchored at the repository root, not paths; this test
# names the paths it looks for (its own cases check the scan)
SKIP_FILES = {".gitignore", "test_self_contained.py"}


def repository_files(root):
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], capture_output=True, check=True)
        names = [n for n in out.stdout.decode().split("\0") if n]
        if names:
            return names
    except (OSError, subprocess.CalledProcessError):
        pass
    # not a git checkout (or no git): every file but those .gitignore names
    ignored = []
    if os.path.exists(os.path.join(root, ".gitignore")):
        with open(os.path.join(root, ".gitignore")) as f:
            ignored = [line.strip().strip("/") for line in f if line.strip() and not line.startswith("#")]

    def is_ignored(rel):
        parts = rel.split(os.sep)
        return any(fnmatch.fnmatch(rel, pat) or any(fnmatch.fnmatch(p, pat) for p in parts) for pat in ignored)

    names = []
    for d, dirs, files in os.walk(root):
        dirs[:] = [x for x in dirs if x not in SKIP_DIRS and not is_ignored(os.path.relpath(os.path.join(d, x), root))]
        names += [r for r in (os.path.relpath(os.path.join(d, f), root) for f in files) if not is_ignored(r)]
    return names


def violations(rel, text, root=ROOT):
    """The paths of one file that leave the repository, as (line, message)."""
    found = []
    machine = bool(MACHINE_READ.search("/" + rel))
    here = os.path.dirname(os.path.join(root, rel))
    prev = ""
    for n, line in enumerate(text.splitlines(), 1):
        if OUTSIDE_FOLDER in line or OUTSIDE_JOINED.search(line):
            found.append((n, f"names the folder beside the clone ({OUTSIDE_FOLDER})"))
        for m in ABSOLUTE.finditer(line):
            before = (prev.rstrip() + " " + line[:m.start()].lstrip()).rstrip("\n")
            if m.group(1) not in SYSTEM_ROOTS and not APPENDED.search(before):
                found.append((n, f"absolute path outside the system folders: /{m.group(1)}/..."))
        if machine:
            for m in CLIMB.finditer(line):
                target = os.path.normpath(os.path.join(here, m.group(1) + m.group(2)))
                if os.path.relpath(target, root).startswith(".."):
                    found.append((n, f"relative path climbs out of the repository: {m.group(0)}"))
        prev = line
    return found


class SelfContained(unittest.TestCase):
    def test_no_file_reaches_outside(self):
        names = repository_files(ROOT)
        self.assertGreater(len(names), 100)
        bad = []
        for rel in names:
            path = os.path.join(ROOT, rel)
            if not os.path.isfile(path) or os.path.basename(rel) in SKIP_FILES:
                continue
            with open(path, "rb") as f:
                raw = f.read()
            if b"\0" in raw[:8192]:
                continue  # binary
            for n, msg in violations(rel, raw.decode("utf-8", "replace")):
                bad.append(f"{rel}:{n}: {msg}")
        self.assertEqual(bad, [], "files that need something outside the repository:\n" + "\n".join(bad))

    def test_outside_git_the_ignored_files_are_left_out(self):
        with tempfile.TemporaryDirectory() as tmp:
            with open(os.path.join(tmp, ".gitignore"), "w") as f:
                f.write("build*/\n/out/\nbuild-fuzz.log\n*.pyc\n")
            for rel in ("src/a.cpp", "build/x.o", "build-fuzz.log", "out/r.csv", "tools/t.pyc", "doc/b.md"):
                os.makedirs(os.path.dirname(os.path.join(tmp, rel)) or tmp, exist_ok=True)
                open(os.path.join(tmp, rel), "w").close()
            self.assertEqual(sorted(repository_files(tmp)), [".gitignore", "doc/b.md", "src/a.cpp"])

    def test_the_scan_finds_paths_that_leave(self):
        cases = {
            "unittest/x.cpp": 'read("' + OUTSIDE_FOLDER + '/data/a.csv");',
            "doc/x.md": "see " + OUTSIDE_FOLDER + "/data",
            "tools/x.py": "open('/" + "work/main/data/x.csv')",
            "tools/y.py": 'os.path.join(here, "..", "..", "' + 'shared")',
            "examples/a/b.json": '{"path": "../../../' + 'elsewhere/x.csv"}',
            "examples/a/in.x": "include /" + "home/someone/walls.stl",
            "unittest/y.cpp": 'std::ifstream in("/' + 'root/data/x.csv");',
        }
        for rel, text in cases.items():
            self.assertTrue(violations(rel, text), f"not found in {rel}: {text}")
        fine = {
            "examples/a/b.json": '{"path": "../../data/x.csv"}',
            "tools/x.sh": "PY=/usr/bin/python3; ls /usr/share/doc/liggghts/examples",
            "doc/x.md": "see https://example.org/a/b and 3/4/5 and $ROOT/tools/x.py",
            "unittest/z.cpp": 'read(std::string(GRANARY_SOURCE_DIR) + "/potentials/x.clump");',
        }
        for rel, text in fine.items():
            self.assertEqual(violations(rel, text), [], f"{rel}: {text}")


if __name__ == "__main__":
    unittest.main(verbosity=2)
