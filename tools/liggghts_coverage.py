#!/usr/bin/python3
"""Coverage of LIGGGHTS 3.8 by Granary, from LIGGGHTS' own manual.

The entries are read from the LIGGGHTS manual installed by the liggghts-doc
package (default /usr/share/doc/liggghts/doc):

* Section_commands.html: the commands and the compute, dump, fix, pair and
  bond styles it lists;
* the styles named on the pages of the commands that take one
  (region.html, atom_style.html, dump.html: the "style = a or b ..." line);
* Section_gran_models.html and every gran_*.html page: the contact
  sub-models of pair gran and fix wall/gran (model, tangential,
  rolling_friction, cohesion, surface);
* Section_mesh_modules.html: the mesh modules of fix mesh/surface;
* any other command page of the manual that no index links to (named after
  its title).

What Granary has comes from the program itself (`granary -list-styles`). An
entry is supported when Granary registers its kind and name; a mesh module M
when Granary registers fix mesh/surface/M. The data file
doc/liggghts_coverage.csv (kind, name, verdict, text) has a row for every
entry; its verdict must agree with the program, and its text is the
difference (supported with differences) or the reason (not supported). The
Granary doc page of a supported entry is found in doc/ (the page whose Syntax
section shows the name).

Usage:
  liggghts_coverage.py              write the table section of doc/liggghts_compatibility.md
  liggghts_coverage.py --check      exit 1 (and say why) when the table is stale or wrong
  liggghts_coverage.py --tutorials  run every tutorial script with Granary and with
                                    LIGGGHTS (the `liggghts` on PATH, or --liggghts EXE;
                                    --liggghts "" for Granary only) on copies whose runs
                                    are cut to --steps steps, and write the tutorial
                                    section (with --only PATTERN...: print, do not write;
                                    with --only PATTERN... --update: rerun those scripts and
                                    write the section with the other rows as committed)
  liggghts_coverage.py --check-tutorials
                                    exit 1 unless the tutorial section lists every script
Exit status 77: the LIGGGHTS manual (or the tutorials) is not installed.
"""

import argparse
import csv
import difflib
import html
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
# Where liggghts-doc installs the manual and the tutorials (the environment
# variables LIGGGHTS_DOC_DIR and LIGGGHTS_TUTORIAL_DIR override them).
DOC_DIR = Path(os.environ.get("LIGGGHTS_DOC_DIR", "/usr/share/doc/liggghts/doc"))
TUTORIAL_DIR = Path(os.environ.get("LIGGGHTS_TUTORIAL_DIR",
                                   "/usr/share/doc/liggghts/examples/LIGGGHTS/Tutorials_public"))
DATA = REPO / "doc" / "liggghts_coverage.csv"
TARGET = REPO / "doc" / "liggghts_compatibility.md"
SKIP = 77

BEGIN_TABLE = "<!-- BEGIN coverage table: written by tools/liggghts_coverage.py, do not edit -->"
END_TABLE = "<!-- END coverage table -->"
BEGIN_TUT = "<!-- BEGIN tutorial runs: written by tools/liggghts_coverage.py --tutorials, do not edit -->"
END_TUT = "<!-- END tutorial runs -->"

# Kinds in table order, with how the table names them.
KINDS = {
    "command": "command",
    "fix": "fix style",
    "compute": "compute style",
    "pair": "pair style",
    "bond": "bond style",
    "region": "region style",
    "atom_style": "atom style",
    "dump": "dump style",
    "model": "contact: model",
    "tangential": "contact: tangential",
    "rolling_friction": "contact: rolling_friction",
    "cohesion": "contact: cohesion",
    "surface": "contact: surface",
    "mesh_module": "mesh module",
}
# Granary-only kinds, for the list of Granary-only names.
LABELS = dict(KINDS, damping="contact: damping")
CONTACT_SLOTS = ("model", "tangential", "rolling_friction", "cohesion", "surface")
VERDICTS = ("supported", "supported with differences", "not supported")

# Section ids of Section_commands.html and the kind of the names they list.
COMMAND_SECTIONS = {
    "list-of-all-commands": "command",
    "bond-style-potentials": "bond",
    "compute-styles": "compute",
    "dump-styles": "dump",
    "fix-styles": "fix",
    "pair-style-potentials": "pair",
}
# Command pages whose "style = a or b or ..." line lists styles of a kind.
STYLE_PAGES = {"region.html": "region", "atom_style.html": "atom_style", "dump.html": "dump"}
# Pages of the manual that are not about a command or style.
NON_COMMAND_PAGES = re.compile(r"^(Section_.*|Manual|genindex|search|install_.*|liggghts_.*_tutorial)\.html$")

# An entry of an index table (the introductions link to the parent command too).
LINK = re.compile(r'<td><a class="reference internal" href="([^"#]+)(?:#[^"]*)?"><em>([^<]+)</em></a>')


class Problems(list):
    """What is wrong, one sentence each."""

    def add(self, text):
        self.append(text)


# ---------------------------------------------------------------------------
# LIGGGHTS' manual


def _sections(text):
    """(id, html) of every <div class="section" id=...>, innermost text up to the next one."""
    marks = [(m.start(), m.group(1)) for m in re.finditer(r'<div class="section" id="([^"]+)">', text)]
    for k, (start, ident) in enumerate(marks):
        end = marks[k + 1][0] if k + 1 < len(marks) else len(text)
        yield ident, text[start:end]


def _title(path):
    """The first <h1> of a page, without tags and the trailing pilcrow."""
    m = re.search(r"<h1>(.*?)</h1>", path.read_text(errors="replace"), re.S)
    if not m:
        return ""
    return html.unescape(re.sub(r"<[^>]+>", "", m.group(1))).replace("\u00b6", "").strip()


def _style_line(path):
    """The names of the "style = a or b or ..." line of a command page."""
    text = path.read_text(errors="replace")
    m = re.search(r"<li>style = (.*?)</li>", text, re.S)
    if not m:
        return []
    return [html.unescape(n) for n in re.findall(r"<em>([^<]+)</em>", m.group(1))]


def liggghts_entries(doc_dir):
    """{(kind, name): [page, ...]} of every command and style the manual documents."""
    doc_dir = Path(doc_dir)
    entries = {}

    def add(kind, name, page):
        pages = entries.setdefault((kind, name.strip()), [])
        if page not in pages:
            pages.append(page)

    linked = set()
    text = (doc_dir / "Section_commands.html").read_text(errors="replace")
    for ident, body in _sections(text):
        kind = COMMAND_SECTIONS.get(ident)
        if kind is None:
            continue
        for page, name in LINK.findall(body):
            add(kind, html.unescape(name), page)
            linked.add(page)

    gran = (doc_dir / "Section_gran_models.html").read_text(errors="replace")
    for ident, body in _sections(gran):
        m = re.match(r"(.+)-commands$", ident)
        if not m:
            continue
        slot = m.group(1).replace("-", "_")
        for page, name in LINK.findall(body):
            add(slot, html.unescape(name), page)
            linked.add(page)
    for ident, body in _sections((doc_dir / "Section_mesh_modules.html").read_text(errors="replace")):
        if ident != "module-commands":
            continue
        for page, name in LINK.findall(body):
            add("mesh_module", html.unescape(name), page)
            linked.add(page)

    for page, kind in STYLE_PAGES.items():
        for name in _style_line(doc_dir / page):
            add(kind, name, page)
        linked.add(page)

    # Pages no index links to: contact sub-models (title "gran SLOT NAME ..."),
    # mesh modules ("mesh module NAME") and commands ("NAME command").
    for path in sorted(doc_dir.glob("*.html")):
        if path.name in linked or NON_COMMAND_PAGES.match(path.name):
            continue
        words = _title(path).split()
        if len(words) >= 3 and words[0] == "gran" and words[1] in CONTACT_SLOTS:
            add(words[1], words[2], path.name)
        elif len(words) >= 3 and words[:2] == ["mesh", "module"]:
            add("mesh_module", words[2], path.name)
        elif len(words) == 2 and words[1] == "command":
            add("command", words[0], path.name)
        elif len(words) == 3 and words[2] == "command" and words[0] in ("fix", "compute", "pair_style", "dump"):
            add({"pair_style": "pair"}.get(words[0], words[0]), words[1], path.name)
        else:
            raise ValueError(f"{path.name}: page not linked from the index, title '{_title(path)}' not understood")
    return entries


# ---------------------------------------------------------------------------
# Granary


def granary_binary(given=None):
    for candidate in (given, os.environ.get("GRANARY_BINARY"), REPO / "build" / "granary"):
        if candidate and Path(candidate).is_file():
            return str(Path(candidate).resolve())
    raise FileNotFoundError("granary executable not found (build it, or give --granary PATH)")


def granary_names(binary):
    """{(kind, name)} that `granary -list-styles` prints."""
    out = subprocess.run([binary, "-list-styles"], capture_output=True, text=True, check=True, timeout=60)
    names = set()
    for line in out.stdout.splitlines():
        parts = line.split()
        if len(parts) != 2:
            raise ValueError(f"granary -list-styles: unexpected line '{line}'")
        names.add((parts[0], parts[1]))
    if not names:
        raise ValueError("granary -list-styles printed nothing")
    return names


def registered(kind, name, names):
    """Does Granary register this LIGGGHTS entry?"""
    if kind == "mesh_module":  # a fix mesh/surface/MODULE[/MODULE...] with it
        return any(k == "fix" and n.startswith("mesh/surface/") and name in n.split("/")[2:] for k, n in names)
    return (kind, name) in names


def _syntax_lines(path):
    """The lines of the code blocks of the '## Syntax' section of a doc page."""
    lines, in_syntax, in_code = [], False, False
    for line in path.read_text().splitlines():
        if line.startswith("## "):
            in_syntax = line.strip() == "## Syntax"
            in_code = False
            continue
        if not in_syntax:
            continue
        if line.startswith("```"):
            in_code = not in_code
            continue
        if in_code:
            lines.append(line)
    return lines


def _syntax_text(path):
    text, in_syntax = [], False
    for line in path.read_text().splitlines():
        if line.startswith("## "):
            in_syntax = line.strip() == "## Syntax"
            continue
        if in_syntax:
            text.append(line)
    return "\n".join(text)


def _page_showing(folder, stem, match):
    """The doc page of a name in doc/<folder>: the first page whose Syntax code
    shows it (`match` on the words of a line; doc/<folder>/<stem>.md first),
    else <stem>.md when it names it in backticks (another name of a style)."""
    base = REPO / "doc" / folder
    preferred = base / (stem + ".md")
    pages = ([preferred] if preferred.is_file() else []) + sorted(p for p in base.glob("*.md") if p != preferred)
    for page in pages:
        if any(match(line.split()) for line in _syntax_lines(page)):
            return page.relative_to(REPO / "doc").as_posix()
    return None


def _page_naming(path, name):
    """path (relative to doc/) when the page names `name` in backticks, else None."""
    if path.is_file() and f"`{name}`" in path.read_text():
        return path.relative_to(REPO / "doc").as_posix()
    return None


def _style_on_command_page(command, name):
    """doc/commands/<command>.md when its Syntax section names the style `name`."""
    page = REPO / "doc" / "commands" / (command + ".md")
    if not page.is_file():
        return None
    if f"`{name}`" in _syntax_text(page) or any(name in line.split() for line in _syntax_lines(page)):
        return page.relative_to(REPO / "doc").as_posix()
    return None


FOLDERS = {"command": "commands", "fix": "fixes", "compute": "computes", "pair": "pairs"}


def find_doc(kind, name):
    """The Granary doc page (relative to doc/) that documents a name, or None:
    commands, fix, compute and pair styles: the page whose Syntax code shows it
    (`name ...`, `fix ID group-ID name ...`, `pair_style name ...`), else the
    page named after it that names it; region, atom and dump styles: their
    command's page; contact sub-models: the row of their slot on pairs/gran.md;
    mesh module M: the page of fix mesh/surface/M."""
    stem = name.replace("/", "_").replace("-", "_")
    if kind in FOLDERS:
        folder = FOLDERS[kind]
        if kind == "command":
            shows = lambda w: w[:1] == [name]  # noqa: E731
        elif kind == "pair":
            shows = lambda w: len(w) > 1 and w[0] == "pair_style" and w[1] == name  # noqa: E731
        else:
            shows = lambda w: len(w) > 3 and w[0] == kind and w[3] == name  # noqa: E731
        found = _page_showing(folder, stem, shows) or _page_naming(REPO / "doc" / folder / (stem + ".md"), name)
        if found is None and kind == "pair":
            found = _style_on_command_page("pair_style", name)
        return found
    if kind == "mesh_module":  # the page of a fix mesh/surface/.../MODULE
        return _page_showing("fixes", "mesh_surface_" + stem,
                             lambda w: len(w) > 3 and w[0] == "fix" and w[3].startswith("mesh/surface/") and
                             name in w[3].split("/")[2:])
    if kind in ("region", "atom_style", "dump"):
        return _style_on_command_page(kind, name)
    if kind in CONTACT_SLOTS or kind == "damping":
        page = REPO / "doc" / "pairs" / "gran.md"
        if not page.is_file():
            return None
        for line in _syntax_text(page).splitlines():
            if line.startswith(f"| `{kind}` |") and f"`{name}`" in line.split("|")[2]:
                return page.relative_to(REPO / "doc").as_posix()
        return None
    return None


# ---------------------------------------------------------------------------
# The data file


def read_data(path, problems):
    """{(kind, name): (verdict, text)}; problems for malformed or repeated rows."""
    data = {}
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames != ["kind", "name", "verdict", "text"]:
            problems.add(f"{path.name}: the header must be kind,name,verdict,text")
            return data
        for line_no, row in enumerate(reader, start=2):
            key = (row["kind"].strip(), row["name"].strip())
            verdict, text = row["verdict"].strip(), (row["text"] or "").strip()
            if key[0] not in KINDS:
                problems.add(f"{path.name}:{line_no}: unknown kind '{key[0]}'")
            if verdict not in VERDICTS:
                problems.add(f"{path.name}:{line_no}: verdict must be one of {', '.join(VERDICTS)}")
            if key in data:
                problems.add(f"{path.name}:{line_no}: second row for {key[0]} {key[1]}")
            data[key] = (verdict, text)
    return data


# ---------------------------------------------------------------------------
# The table


def kind_order(kind):
    return list(KINDS).index(kind) if kind in KINDS else len(KINDS)


def build(entries, names, data, problems):
    """Rows (kind, name, pages, verdict, doc, text) and the Granary-only names (kind, name, doc)."""
    rows = []
    for (kind, name), pages in sorted(entries.items(), key=lambda kv: (kind_order(kv[0][0]), kv[0][1])):
        what = f"{kind} {name}"
        has = registered(kind, name, names)
        derived = ("supported" if has else "not supported")
        if (kind, name) not in data:
            problems.add(f"{what} ({', '.join(pages)}) has no row in {DATA.name}")
            rows.append((kind, name, pages, derived, None, ""))
            continue
        verdict, text = data[(kind, name)]
        doc = None
        if verdict.startswith("supported") and not has:
            problems.add(f"{what} is marked '{verdict}' but Granary does not register it")
        if verdict == "not supported" and has:
            problems.add(f"{what} is marked 'not supported' but Granary registers it")
        if verdict == "not supported" and not text:
            problems.add(f"{what} is marked 'not supported' without a reason")
        if verdict == "supported with differences" and not text:
            problems.add(f"{what} is marked 'supported with differences' without saying which")
        if verdict == "supported" and text:
            problems.add(f"{what} is marked 'supported' but has a text (use 'supported with differences')")
        if has:
            doc = find_doc(kind, name)
            if doc is None:
                problems.add(f"{what} is supported but no Granary doc page shows it in its Syntax section")
            elif not (REPO / "doc" / doc).is_file():
                problems.add(f"{what}: doc page doc/{doc} is missing")
        # The table's verdict comes from the program; the data file's must agree (checked above).
        derived = ("supported with differences" if text else "supported") if has else "not supported"
        rows.append((kind, name, pages, derived, doc, text))
    for key in sorted(set(data) - set(entries), key=lambda k: (kind_order(k[0]), k[1])):
        problems.add(f"{DATA.name} has a row for {key[0]} {key[1]}, which the LIGGGHTS manual does not list")

    liggghts = set(entries)
    modules = {n for k, n in entries if k == "mesh_module"}
    # fix mesh/surface/M1[/M2...] with LIGGGHTS' mesh modules is LIGGGHTS' syntax
    liggghts |= {(k, n) for k, n in names
                 if k == "fix" and n.startswith("mesh/surface/") and set(n.split("/")[2:]) <= modules}
    only = []
    for kind, name in sorted(names - liggghts, key=lambda k: (kind_order(k[0]), k[1])):
        doc = find_doc(kind, name)
        if doc is None:
            problems.add(f"Granary-only {kind} {name} has no doc page that shows it in its Syntax section")
        only.append((kind, name, doc))
    return rows, only


def _cell(text):
    return text.replace("|", "\\|").replace("\n", " ")


def _kind_label(kind):
    return LABELS.get(kind, kind)


def render(rows, only):
    counts = {v: sum(1 for r in rows if r[3] == v) for v in VERDICTS}
    out = [BEGIN_TABLE, ""]
    out.append(f"{len(rows)} entries of the LIGGGHTS 3.8 manual: {counts['supported']} supported, "
               f"{counts['supported with differences']} supported with differences, "
               f"{counts['not supported']} not supported.")
    out.append("")
    out.append("| kind | entries | supported | with differences | not supported |")
    out.append("|---|---:|---:|---:|---:|")
    for kind in KINDS:
        sel = [r for r in rows if r[0] == kind]
        if not sel:
            continue
        c = {v: sum(1 for r in sel if r[3] == v) for v in VERDICTS}
        out.append(f"| {_kind_label(kind)} | {len(sel)} | {c['supported']} | "
                   f"{c['supported with differences']} | {c['not supported']} |")
    out.append("")
    out.append("| kind | name | LIGGGHTS page | verdict | Granary page | difference or reason |")
    out.append("|---|---|---|---|---|---|")
    for kind, name, pages, verdict, doc, text in rows:
        page = ", ".join(f"`{p}`" for p in pages)
        link = f"[{doc}]({doc})" if doc else ""
        out.append(f"| {_kind_label(kind)} | `{name}` | {page} | {verdict} | {link} | {_cell(text)} |")
    out.append("")
    out.append("### Granary-only names")
    out.append("")
    out.append("Registered by Granary (`granary -list-styles`) and not in the LIGGGHTS manual:")
    out.append("")
    out.append("| kind | name | Granary page |")
    out.append("|---|---|---|")
    for kind, name, doc in only:
        link = f"[{doc}]({doc})" if doc else ""
        out.append(f"| {_kind_label(kind)} | `{name}` | {link} |")
    out.append("")
    out.append(END_TABLE)
    return "\n".join(out)


def replace_section(text, begin, end, body):
    """text with the lines from `begin` to `end` replaced by body (which has both markers)."""
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < 0 or j < i:
        raise ValueError(f"{TARGET.name}: markers '{begin}' ... '{end}' not found")
    return text[:i] + body + text[j + len(end):]


def current_section(text, begin, end):
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < 0 or j < i:
        return None
    return text[i:j + len(end)]


def coverage(doc_dir, binary, data_path=None):
    """(generated section, problems, rows, granary-only)."""
    problems = Problems()
    entries = liggghts_entries(doc_dir)
    names = granary_names(binary)
    data = read_data(data_path or DATA, problems)
    rows, only = build(entries, names, data, problems)
    return render(rows, only), problems, rows, only


# ---------------------------------------------------------------------------
# Tutorials

RUN_CAP = 10000  # steps per run command
LOOP_CAP = 3  # passes of a loop variable


def tutorial_scripts(tutorial_dir):
    """Every input script (in.*) of the tutorials, as paths relative to the tutorial folder."""
    return sorted(p.relative_to(tutorial_dir) for p in Path(tutorial_dir).rglob("in.*") if p.is_file())


def shorten(text, cap=RUN_CAP, loop_cap=LOOP_CAP):
    """The script with every run cut to at most `cap` steps and every loop
    variable to `loop_cap` passes; nothing else changes. A run whose length is
    a variable gets `cap`; `run N upto` goes at most `cap` beyond the steps of
    the (cut) runs before it in this script."""
    out, steps = [], 0
    for line in text.splitlines():
        code = line.split("#", 1)[0]
        words = code.split()
        if len(words) >= 2 and words[0] == "run":
            upto = "upto" in words[2:]
            try:
                n = int(float(words[1]))
            except ValueError:
                n = None  # a variable
            if upto:
                target = min(n, steps + cap) if n is not None else steps + cap
                new, steps = target, max(steps, target)
            else:
                new = min(n, cap) if n is not None else cap
                steps += new
            words[1] = str(new)
            line = " ".join(words)
        elif len(words) >= 4 and words[0] == "variable" and words[2] == "loop":
            try:
                if int(words[3]) > loop_cap and (len(words) == 4 or not words[4][0].isdigit()):
                    words[3] = str(loop_cap)
                    line = " ".join(words)
            except ValueError:
                pass
        out.append(line)
    return "\n".join(out) + "\n"


def logical_lines(lines):
    """(first line number, text without comment) of every command; '&' joins lines."""
    out, buf, first = [], "", None
    for k, line in enumerate(lines, start=1):
        code = line.split("#", 1)[0].rstrip()
        if first is None:
            first = k
        if code.endswith("&"):
            buf += code[:-1] + " "
            continue
        buf += code
        if buf.strip():
            out.append((first, " ".join(buf.split())))
        buf, first = "", None
    if buf.strip():
        out.append((first, " ".join(buf.split())))
    return out


def _message(text):
    """An error message without LIGGGHTS' source location and Granary's hints."""
    text = re.sub(r"\s*\(\.?/?src/[^)]*\)\s*$", "", text.strip())
    return text.split("; ", 1)[0]  # the first clause: Granary adds hints after "; "


def granary_stop(script, rc, stderr, commands):
    """None when Granary ran the script to its end, else (line, command, message)."""
    if rc == 0:
        return None
    lines = stderr.splitlines()
    err = next((l for l in lines if l.startswith("ERROR")), f"ERROR: exit status {rc}")
    m = re.match(r"ERROR: (\S+?):(\d+): ([a-z_]+): (.*)$", err)
    if not m:
        return None, "", _message(err[len("ERROR: "):])
    where, line_no, message = m.group(1), int(m.group(2)), _message(m.group(4))
    if Path(where).name != script.name:
        # in an included file: the include line of the script, and where in the file
        inc = [re.search(r"included from (\S+?):(\d+)", l) for l in lines]
        inc = [i for i in inc if i and Path(i.group(1)).name == script.name]
        message = f"{message}, in {Path(where).name} line {line_no}"
        if not inc:
            return None, "", message
        line_no = int(inc[-1].group(2))
    text = next((t for n, t in commands if n == line_no), "")
    return line_no, text, message


def liggghts_stop(rc, screen, commands):
    """None when LIGGGHTS ran the script to its end, else (line, command, message).
    `screen` is its output with -echo screen: each command is echoed before it
    runs, so the error belongs to the last echoed command of the script."""
    lines = screen.splitlines()
    at = next((k for k, l in enumerate(lines) if l.startswith("ERROR")), None)
    if rc == 0 and at is None:
        return None
    known = {}
    for n, text in commands:
        known.setdefault(text, n)
    last = (None, "")
    for line in lines[:at]:
        norm = " ".join(line.split("#", 1)[0].split())
        if norm in known:
            last = (known[norm], norm)
    message = lines[at][len("ERROR"):].lstrip(": ") if at is not None else f"exit status {rc}"
    message = re.sub(r"^on proc \d+: ", "", message)
    return last[0], last[1], _message(message)


def run_tutorials(tutorial_dir, binary, liggghts, timeout, only=None, cap=RUN_CAP, log=print):
    """Run every tutorial script with Granary (and LIGGGHTS) on a cut copy of
    its folder, the scripts of a folder in name order (a later one may read
    the restart file of an earlier one). Returns [(script, granary, liggghts)]
    where each result is None (ran to its end), (line, command, message), or
    'not run'."""
    tutorial_dir = Path(tutorial_dir)
    programs = {"granary": str(Path(binary).resolve())}
    if liggghts:
        programs["liggghts"] = liggghts
    results = []
    scripts = [s for s in tutorial_scripts(tutorial_dir) if not only or any(o in str(s) for o in only)]
    with tempfile.TemporaryDirectory(prefix="granary_tutorials_") as tmp:
        for program in programs:
            shutil.copytree(tutorial_dir, Path(tmp) / program)
            for script in tutorial_scripts(tutorial_dir):
                copy = Path(tmp) / program / script
                copy.write_text(shorten(copy.read_text(errors="replace"), cap))
        for script in scripts:
            commands = logical_lines((tutorial_dir / script).read_text(errors="replace").splitlines())
            res = {"liggghts": "not run"}
            for program, exe in programs.items():
                cwd = Path(tmp) / program / script.parent
                cmd = [exe, "-in", script.name, "-echo", "screen", "-log", "none"]
                start = time.monotonic()
                try:
                    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, errors="replace",
                                       timeout=timeout, stdin=subprocess.DEVNULL)
                    if program == "granary":
                        res[program] = granary_stop(script, p.returncode, p.stderr, commands)
                    else:
                        res[program] = liggghts_stop(p.returncode, p.stdout + p.stderr, commands)
                except subprocess.TimeoutExpired:
                    res[program] = (None, "", f"still running after {timeout:.0f} s")
                log(f"{script} [{program}, {time.monotonic() - start:.0f} s]: {describe(res[program])}")
            results.append((script, res["granary"], res["liggghts"]))
    return results


class Recorded(str):
    """A result kept from the committed tutorial section (its cell text, as written)."""


def describe(result):
    if result is None:
        return "runs"
    if result == "not run":
        return "not run"
    if isinstance(result, Recorded):
        return str(result)
    line, command, message = result
    where = f"line {line}: `{command}`" if line else ""
    return f"stops at {where} ({message})" if where else f"stops ({message})"


def tutorial_usage(tutorial_dir):
    """{(kind, name): [script, ...]}: the commands, styles and contact sub-models the scripts use."""
    used = {}
    for script in tutorial_scripts(tutorial_dir):
        for _, text in logical_lines((Path(tutorial_dir) / script).read_text(errors="replace").splitlines()):
            w = text.split()
            found = [("command", w[0])]
            if w[0] in ("fix", "compute") and len(w) > 3:
                found.append((w[0], w[3]))
                if w[3].startswith("mesh/surface/"):
                    found += [("mesh_module", m) for m in w[3].split("/")[2:]]
            elif w[0] == "pair_style" and len(w) > 1:
                found.append(("pair", w[1]))
            elif w[0] == "region" and len(w) > 2:
                found.append(("region", w[2]))
            elif w[0] == "atom_style" and len(w) > 1:
                found.append(("atom_style", w[1]))
            elif w[0] == "dump" and len(w) > 3:
                found.append(("dump", w[3]))
            if (w[0] == "pair_style" and len(w) > 1 and w[1] == "gran") or (w[0] == "fix" and "wall/gran" in w[3:4]):
                found += [(w[k], w[k + 1]) for k in range(len(w) - 1) if w[k] in CONTACT_SLOTS]
            for key in found:
                if script.as_posix() not in used.setdefault(key, []):
                    used[key].append(script.as_posix())
    return used


def recorded_tutorials(section):
    """[(script, granary, liggghts)] from a committed tutorial section: "runs" is None,
    "not run" stays, any other cell is kept as Recorded text."""
    def result(cell):
        cell = cell.strip().replace("\\|", "|")
        if cell == "runs":
            return None
        if cell == "not run":
            return "not run"
        return Recorded(cell)
    out = []
    for m in re.finditer(r"^\| `([^`]+)` \| (.*) \| (.*) \|$", section, re.M):
        lg, g = re.split(r"(?<!\\) \| ", m.group(2) + " | " + m.group(3))[:2]
        out.append((Path(m.group(1)), result(g), result(lg)))
    return out


def merge_tutorials(recorded, fresh):
    """The recorded results with the freshly run scripts replaced (new scripts added), in script order."""
    by_script = {r[0].as_posix(): r for r in recorded}
    for r in fresh:
        by_script[r[0].as_posix()] = r
    return sorted(by_script.values(), key=lambda r: r[0])


def render_tutorials(results, usage, names, cap=RUN_CAP, loop_cap=LOOP_CAP):
    out = [BEGIN_TUT, ""]
    ran = [r for r in results if r[2] is None]
    out.append(f"{len(results)} input scripts; LIGGGHTS 3.8 runs {len(ran)} of them to their end, Granary "
               f"{sum(1 for r in ran if r[1] is None)} of those. Each script ran on a copy of its folder "
               f"with every `run` cut to at most {cap} steps and every loop variable to {loop_cap} passes "
               f"(nothing else changed), the scripts of a folder in name order.")
    out.append("")
    out.append("| script | LIGGGHTS 3.8 | Granary |")
    out.append("|---|---|---|")
    for script, g, lg in results:
        out.append(f"| `{script.as_posix()}` | {_cell(describe(lg))} | {_cell(describe(g))} |")
    out.append("")
    if any(r[2] != "not run" for r in results):
        considered = {r[0].as_posix() for r in ran}
        out.append("Names used by the scripts LIGGGHTS runs (read from the scripts' text, also after the "
                   "line where Granary stops) that Granary does not register, with the scripts that use them:")
    else:
        considered = {r[0].as_posix() for r in results}
        out.append("Names used by the scripts (read from their text, also after the line where Granary "
                   "stops) that Granary does not register, with the scripts that use them:")
    out.append("")
    for (kind, name), scripts in sorted(usage.items(), key=lambda kv: (kind_order(kv[0][0]), kv[0][1])):
        scripts = [s for s in scripts if s in considered]
        if registered(kind, name, names) or not scripts:
            continue
        out.append(f"* {_kind_label(kind)} `{name}`: {', '.join(f'`{s}`' for s in scripts)}")
    out.append("")
    out.append(END_TUT)
    return "\n".join(out)


# ---------------------------------------------------------------------------


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="check the table instead of writing it")
    ap.add_argument("--tutorials", action="store_true", help="run the tutorials and write their section")
    ap.add_argument("--check-tutorials", action="store_true",
                    help="check that the tutorial section lists every tutorial script")
    ap.add_argument("--liggghts", default=shutil.which("liggghts"), help="LIGGGHTS executable (with --tutorials)")
    ap.add_argument("--only", nargs="*", help="with --tutorials: only scripts whose path contains one of these "
                                              "(printed, not written, unless --update)")
    ap.add_argument("--update", action="store_true",
                    help="with --tutorials --only: write the section with these scripts' rows replaced and "
                         "the other rows kept as committed")
    ap.add_argument("--timeout", type=float, default=600, help="seconds per tutorial run")
    ap.add_argument("--steps", type=int, default=RUN_CAP, help="with --tutorials: most steps per run command")
    ap.add_argument("--granary", help="granary executable (default: $GRANARY_BINARY, build/granary)")
    ap.add_argument("--doc-dir", default=str(DOC_DIR), help="LIGGGHTS manual (HTML)")
    ap.add_argument("--tutorial-dir", default=str(TUTORIAL_DIR))
    ap.add_argument("--data", default=str(DATA))
    ap.add_argument("--target", default=str(TARGET))
    args = ap.parse_args(argv)
    target = Path(args.target)

    if args.tutorials or args.check_tutorials:
        if not (Path(args.tutorial_dir)).is_dir():
            print(f"skipped: LIGGGHTS tutorials not installed ({args.tutorial_dir}; package liggghts-doc)")
            return SKIP
        if args.check_tutorials:
            section = current_section(target.read_text(), BEGIN_TUT, END_TUT) or ""
            listed = set(re.findall(r"^\| `([^`]+)` \|", section, re.M))
            present = {s.as_posix() for s in tutorial_scripts(args.tutorial_dir)}
            problems = [f"tutorial {s} is not in the tutorial section" for s in sorted(present - listed)]
            problems += [f"the tutorial section lists {s}, which is not installed" for s in sorted(listed - present)]
            for p in problems:
                print(p)
            return 1 if problems else 0
        binary = granary_binary(args.granary)
        results = run_tutorials(args.tutorial_dir, binary, args.liggghts, args.timeout, args.only, args.steps)
        if args.only and not args.update:
            return 0
        if args.only:
            recorded = recorded_tutorials(current_section(target.read_text(), BEGIN_TUT, END_TUT) or "")
            results = merge_tutorials(recorded, results)
        section = render_tutorials(results, tutorial_usage(args.tutorial_dir), granary_names(binary), args.steps)
        target.write_text(replace_section(target.read_text(), BEGIN_TUT, END_TUT, section))
        print(f"wrote the tutorial section of {target}")
        return 0

    if not (Path(args.doc_dir) / "Section_commands.html").is_file():
        print(f"skipped: LIGGGHTS manual not installed ({args.doc_dir}; package liggghts-doc)")
        return SKIP
    section, problems, rows, only = coverage(args.doc_dir, granary_binary(args.granary), Path(args.data))
    text = target.read_text()
    if args.check:
        current = current_section(text, BEGIN_TABLE, END_TABLE)
        if current is None:
            problems.add(f"{target.name}: no table section (markers missing)")
        elif current != section:
            diff = difflib.unified_diff(current.splitlines(), section.splitlines(), "committed", "generated",
                                        lineterm="", n=0)
            problems.add(f"{target.name}: the table differs from what the tool generates "
                         f"(run tools/liggghts_coverage.py):\n" + "\n".join(list(diff)[:40]))
        else:
            for link in re.findall(r"\]\(([^)]+)\)", current):
                if not (REPO / "doc" / link).is_file():  # links are relative to doc/
                    problems.add(f"{target.name}: the table links to {link}, which does not exist")
        for p in problems:
            print(p)
        if not problems:
            counts = {v: sum(1 for r in rows if r[3] == v) for v in VERDICTS}
            print(f"ok: {len(rows)} entries ({counts['supported']} supported, "
                  f"{counts['supported with differences']} with differences, "
                  f"{counts['not supported']} not supported), {len(only)} Granary-only names")
        return 1 if problems else 0
    if problems:
        for p in problems:
            print(p)
        print("table not written")
        return 1
    target.write_text(replace_section(text, BEGIN_TABLE, END_TABLE, section))
    print(f"wrote the table of {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
