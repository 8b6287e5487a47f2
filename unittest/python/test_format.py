"""Every C++ file of src/ and unittest/ is formatted as .clang-format says.

Runs `clang-format --dry-run --Werror` on each .cpp and .h file (clang-format
from Debian's clang-format package, installed by tools/setup.sh) and fails
naming the files that differ; `clang-format -i FILE` formats one. Also checks
that a badly formatted made-up file is caught. Skipped (exit status 77) where
clang-format is not installed.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CLANG_FORMAT = shutil.which("clang-format")


def cpp_files():
    for top in ("src", "unittest"):
        for dirpath, _, names in os.walk(os.path.join(ROOT, top)):
            for name in sorted(names):
                if name.endswith((".cpp", ".h")):
                    yield os.path.join(dirpath, name)


def unformatted(paths):
    bad = []
    for path in paths:
        r = subprocess.run([CLANG_FORMAT, "--dry-run", "--Werror", "--style=file:" + os.path.join(ROOT, ".clang-format"),
                            path], capture_output=True, text=True)
        if r.returncode != 0:
            bad.append(os.path.relpath(path, ROOT))
    return bad


class Format(unittest.TestCase):
    def test_sources_are_formatted(self):
        files = list(cpp_files())
        self.assertGreater(len(files), 100)
        bad = unformatted(files)
        self.assertEqual(bad, [], "not formatted as .clang-format says (run clang-format -i on them): " +
                         " ".join(bad))

    def test_a_badly_formatted_file_is_caught(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "bad.cpp")
            with open(path, "w") as f:
                f.write("int  f( int a ){return a;}\n")
            self.assertEqual(unformatted([path]), [os.path.relpath(path, ROOT)])


if __name__ == "__main__":
    if CLANG_FORMAT is None:
        print("skipped: clang-format is not installed (Debian package clang-format; tools/setup.sh installs it)")
        sys.exit(77)
    unittest.main()
