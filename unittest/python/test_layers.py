"""The includes of src/ follow the layers of doc/architecture.md (tools/check_layers.py).

The repository itself must pass; made-up trees with an upward include, a room
missing from the table and a table row without a room must fail, each with a
message naming the file or room.
"""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.join(ROOT, "tools", "check_layers.py")

TABLE = """# map

<!-- layers -->
| layer | room | holds |
|---:|---|---|
| 0 | core | hub |
| 1 | particles | data |
| 3 | pair | pair styles |
| 5 | fix | fixes |
"""


def run(root):
    return subprocess.run([sys.executable, TOOL, "--root", root], capture_output=True, text=True)


def tree(files, table=TABLE):
    d = tempfile.mkdtemp(prefix="granary_layers_")
    os.makedirs(os.path.join(d, "doc"))
    with open(os.path.join(d, "doc", "architecture.md"), "w") as f:
        f.write(table)
    for path, text in files.items():
        full = os.path.join(d, "src", path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w") as f:
            f.write(text)
    return d


GOOD = {
    "core/engine.h": '#include "particles/particles.h"\n',
    "core/engine.cpp": '#include "fix/fix.h"\n#include "pair/pair.h"\n',
    "particles/particles.h": '#include "core/vec3.h"\n',
    "pair/pair.cpp": '#include "particles/particles.h"\n#include "core/engine.h"\n',
    "fix/fix.cpp": '#include "pair/pair.h"\n#include "fix/fix.h"\n',
}


class Layers(unittest.TestCase):
    def test_repository(self):
        r = run(ROOT)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)

    def test_made_up_tree_passes(self):
        r = run(tree(GOOD))
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)

    def test_upward_include_fails(self):
        files = dict(GOOD)
        files["pair/pair.cpp"] = '#include "fix/fix.h"\n'
        r = run(tree(files))
        self.assertEqual(r.returncode, 1)
        self.assertIn("src/pair/pair.cpp:1: pair (layer 3) includes fix (layer 5)", r.stdout)

    def test_core_header_may_not_include_high_layers(self):
        files = dict(GOOD)
        files["core/engine.h"] = '#include "pair/pair.h"\n'
        r = run(tree(files))
        self.assertEqual(r.returncode, 1)
        self.assertIn("src/core/engine.h:1: core (layer 0) includes pair (layer 3)", r.stdout)

    def test_rooms_and_table_must_match(self):
        files = dict(GOOD)
        files["geometry/mesh.h"] = "\n"
        del files["fix/fix.cpp"]
        r = run(tree(files))
        self.assertEqual(r.returncode, 1)
        self.assertIn("src/geometry/: room missing from the layer table", r.stdout)
        self.assertIn("layer table names 'fix', which is not a folder of src/", r.stdout)


if __name__ == "__main__":
    unittest.main()
