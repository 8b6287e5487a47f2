"""tools/liggghts_coverage.py: the LIGGGHTS 3.8 coverage table of
doc/liggghts_compatibility.md is what the tool generates from the LIGGGHTS
manual and `granary -list-styles`, and each of its checks catches what it is
meant to catch.

Skipped (exit status 77) when the LIGGGHTS manual (package liggghts-doc) is
not installed.
"""

import csv
import io
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
from contextlib import redirect_stdout
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools"))

import liggghts_coverage as lc  # noqa: E402

DOC_DIR = lc.DOC_DIR
BINARY = os.environ.get("GRANARY_BINARY") or str(REPO / "build" / "granary")


def run_tool(*args):
    """(exit status, printed text) of the tool's main()."""
    out = io.StringIO()
    with redirect_stdout(out):
        status = lc.main(["--granary", BINARY, *args])
    return status, out.getvalue()


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.reader(f))


def write_rows(path, rows):
    with open(path, "w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)


class CommittedTable(unittest.TestCase):
    def test_table_is_current_and_consistent(self):
        status, text = run_tool("--check")
        self.assertEqual(status, 0, text)
        self.assertTrue(text.startswith("ok: "), text)

    def test_every_page_of_the_manual_has_a_row(self):
        # Independent of the tool's parser: every page an index links to, and
        # every page of a command or style, is the page of some entry.
        entries = lc.liggghts_entries(DOC_DIR)
        pages = {p for ps in entries.values() for p in ps}
        linked = set()
        for index in ("Section_commands.html", "Section_gran_models.html", "Section_mesh_modules.html"):
            text = (DOC_DIR / index).read_text(errors="replace")
            linked |= set(re.findall(r'<td><a class="reference internal" href="([^"#]+)', text))
        self.assertTrue(linked, "no links found in the index pages")
        self.assertEqual(linked - pages, set())
        own = {p.name for p in DOC_DIR.glob("*.html") if not lc.NON_COMMAND_PAGES.match(p.name)}
        self.assertEqual(own - pages, set())
        # and every entry has a row in the data file
        data = lc.read_data(lc.DATA, lc.Problems())
        self.assertEqual(set(entries) - set(data), set())

    def test_counts_in_the_doc(self):
        text = lc.TARGET.read_text()
        section = lc.current_section(text, lc.BEGIN_TABLE, lc.END_TABLE)
        rows = re.findall(r"^\| [^|]+ \| `[^`]+` \| `[^|]*\.html`[^|]* \| ([a-z ]+) \|", section, re.M)
        m = re.search(r"(\d+) entries of the LIGGGHTS 3.8 manual: (\d+) supported, (\d+) supported with "
                      r"differences, (\d+) not supported", section)
        self.assertIsNotNone(m)
        total, sup, diff, nots = map(int, m.groups())
        self.assertEqual(len(rows), total)
        self.assertEqual(rows.count("supported"), sup)
        self.assertEqual(rows.count("supported with differences"), diff)
        self.assertEqual(rows.count("not supported"), nots)
        self.assertEqual(sup + diff + nots, total)


class ChecksCatchMistakes(unittest.TestCase):
    """Each check fails on a copy of the inputs broken on purpose."""

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="liggghts_coverage_test_"))
        self.data = self.tmp / "coverage.csv"
        shutil.copy(lc.DATA, self.data)
        self.target = self.tmp / "liggghts_compatibility.md"
        shutil.copy(lc.TARGET, self.target)
        self.rows = read_rows(self.data)

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def check(self, *extra):
        status, text = run_tool("--check", "--data", str(self.data), "--target", str(self.target), *extra)
        return status, text

    def edit_row(self, kind, name, verdict=None, text=None):
        for row in self.rows:
            if row[0] == kind and row[1] == name:
                if verdict is not None:
                    row[2] = verdict
                if text is not None:
                    row[3] = text
                write_rows(self.data, self.rows)
                return
        self.fail(f"no row {kind} {name}")

    def linked_docs(self):
        """A folder of links to LIGGGHTS' doc pages, to add or change pages in."""
        docs = self.tmp / "doc"
        docs.mkdir()
        for page in DOC_DIR.glob("*.html"):
            (docs / page.name).symlink_to(page)
        return docs

    def test_unchanged_copy_passes(self):
        status, text = self.check()
        self.assertEqual(status, 0, text)

    def test_entry_without_row(self):
        write_rows(self.data, [r for r in self.rows if r[:2] != ["fix", "heat/gran"]])
        status, text = self.check()
        self.assertEqual(status, 1)
        self.assertIn("fix heat/gran (fix_heat_gran_conduction.html) has no row", text)

    def test_new_page_in_the_index_without_row(self):
        docs = self.linked_docs()
        index = (DOC_DIR / "Section_commands.html").read_text(errors="replace")
        extra = '<td><a class="reference internal" href="fix_new_style.html"><em>new/style</em></a></td>'
        at = index.index('<div class="section" id="fix-styles">')
        at = index.index("<td>", at)
        (docs / "Section_commands.html").unlink()
        (docs / "Section_commands.html").write_text(index[:at] + extra + index[at:])
        (docs / "fix_new_style.html").write_text("<h1>fix new/style command</h1>")
        status, text = self.check("--doc-dir", str(docs))
        self.assertEqual(status, 1)
        self.assertIn("fix new/style (fix_new_style.html) has no row", text)

    def test_unlinked_page_without_row(self):
        docs = self.linked_docs()
        (docs / "compute_new_thing.html").write_text("<h1>compute new/thing command</h1>")
        status, text = self.check("--doc-dir", str(docs))
        self.assertEqual(status, 1)
        self.assertIn("compute new/thing (compute_new_thing.html) has no row", text)

    def test_supported_but_not_registered(self):
        self.edit_row("fix", "continuum/weighted", verdict="supported", text="")
        status, text = self.check()
        self.assertEqual(status, 1)
        self.assertIn("fix continuum/weighted is marked 'supported' but Granary does not register it", text)

    def test_registered_but_marked_not_supported(self):
        self.edit_row("fix", "nve/sphere", verdict="not supported", text="not implemented yet")
        status, text = self.check()
        self.assertEqual(status, 1)
        self.assertIn("fix nve/sphere is marked 'not supported' but Granary registers it", text)

    def test_missing_reason_and_difference(self):
        self.edit_row("fix", "continuum/weighted", text="")
        self.edit_row("fix", "move/mesh", text="")
        status, text = self.check()
        self.assertEqual(status, 1)
        self.assertIn("fix continuum/weighted is marked 'not supported' without a reason", text)
        self.assertIn("fix move/mesh is marked 'supported with differences' without saying which", text)

    def test_row_for_a_name_the_manual_does_not_have(self):
        write_rows(self.data, self.rows + [["fix", "no/such/style", "not supported", "not implemented yet"]])
        status, text = self.check()
        self.assertEqual(status, 1)
        self.assertIn("has a row for fix no/such/style, which the LIGGGHTS manual does not list", text)

    def test_supported_without_doc_page(self):
        # A registered name whose doc page does not show it: a program that
        # registers fix continuum/weighted, and a data file that says so.
        fake = self.tmp / "granary"
        listing = subprocess.run([BINARY, "-list-styles"], capture_output=True, text=True, check=True).stdout
        fake.write_text("#!/bin/sh\ncat <<'EOF'\n" + listing + "fix continuum/weighted\nEOF\n")
        fake.chmod(0o755)
        self.edit_row("fix", "continuum/weighted", verdict="supported", text="")
        out = io.StringIO()
        with redirect_stdout(out):
            status = lc.main(["--check", "--granary", str(fake), "--data", str(self.data),
                              "--target", str(self.target)])
        self.assertEqual(status, 1)
        self.assertIn("fix continuum/weighted is supported but no Granary doc page shows it", out.getvalue())

    def test_stale_table(self):
        text = self.target.read_text()
        row = re.search(r"^\| fix style \| `nve/sphere` \|.*$", text, re.M).group(0)
        self.target.write_text(text.replace(row + "\n", ""))
        status, out = self.check()
        self.assertEqual(status, 1)
        self.assertIn("the table differs from what the tool generates", out)


class TutorialSection(unittest.TestCase):
    def test_section_lists_every_tutorial_script(self):
        if not lc.TUTORIAL_DIR.is_dir():
            self.skipTest("LIGGGHTS tutorials not installed")
        status, text = run_tool("--check-tutorials")
        self.assertEqual(status, 0, text)

    def test_shorten_cuts_only_runs_and_loops(self):
        script = ("variable n equal 50000\nrun 100\nrun 20000 # long\nrun ${n}\nrun 100000 upto\n"
                  "variable a loop 8000\nfix 1 all nve/sphere\n")
        self.assertEqual(lc.shorten(script, cap=1000, loop_cap=3),
                         "variable n equal 50000\nrun 100\nrun 1000\nrun 1000\nrun 3100 upto\n"
                         "variable a loop 3\nfix 1 all nve/sphere\n")

    def test_update_keeps_the_other_rows_as_committed(self):
        # --tutorials --only X --update: the committed section read back and
        # rendered with no fresh results is the committed section; a fresh
        # result replaces its script's row only and is counted in the summary
        section = lc.current_section((REPO / "doc" / "liggghts_compatibility.md").read_text(),
                                     lc.BEGIN_TUT, lc.END_TUT)
        recorded = lc.recorded_tutorials(section)
        self.assertGreater(len(recorded), 20)
        names = lc.granary_names(lc.granary_binary(BINARY))
        usage = lc.tutorial_usage(lc.TUTORIAL_DIR) if lc.TUTORIAL_DIR.is_dir() else {}
        if usage:
            self.assertEqual(lc.render_tutorials(lc.merge_tutorials(recorded, []), usage, names), section)
        script = next(r[0] for r in recorded if r[1] is None and r[2] is None)
        fresh = [(script, (12, "fix x all nosuch", "unknown fix style 'nosuch'"), None)]
        merged = lc.merge_tutorials(recorded, fresh)
        self.assertEqual(len(merged), len(recorded))
        out = lc.render_tutorials(merged, usage, names)
        self.assertIn(f"| `{script.as_posix()}` | runs | stops at line 12: `fix x all nosuch` "
                      f"(unknown fix style 'nosuch') |", out)
        ran = sum(1 for r in recorded if r[2] is None)
        both = sum(1 for r in recorded if r[2] is None and r[1] is None)
        self.assertIn(f"LIGGGHTS 3.8 runs {ran} of them to their end, Granary {both - 1} of those", out)
        others = [line for line in out.splitlines() if line.startswith("| `") and script.as_posix() not in line]
        self.assertEqual(others, [line for line in section.splitlines()
                                  if line.startswith("| `") and script.as_posix() not in line])


if __name__ == "__main__":
    if not (DOC_DIR / "Section_commands.html").is_file():
        print(f"skipped: the LIGGGHTS manual is not installed ({DOC_DIR}; package liggghts-doc)")
        sys.exit(77)
    if not Path(BINARY).is_file():
        print(f"granary executable not found: {BINARY} (build it or set GRANARY_BINARY)")
        sys.exit(1)
    unittest.main()
