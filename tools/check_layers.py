#!/usr/bin/python3
"""Check that the includes of src/ follow the layers of doc/architecture.md.

    /usr/bin/python3 tools/check_layers.py [--root DIR]

The table after the marker "<!-- layers" in doc/architecture.md gives each room
(folder of src/) a layer. A file may include headers of its own room and of
rooms in lower layers. core (layer 0) is the hub: every room may include it;
core headers may include only core and layer-1 rooms, core sources anything.
Every room of src/ must be in the table and every row must name a room.
Prints each violation (file:line: include) and exits 1 if there is one.
"""
import argparse
import re
import sys
from pathlib import Path

INCLUDE = re.compile(r'^\s*#\s*include\s+"([A-Za-z0-9_]+)/[^"]+"')


def read_layers(doc):
    text = doc.read_text(encoding="utf-8")
    at = text.find("<!-- layers")
    if at < 0:
        raise SystemExit(f"{doc}: no '<!-- layers' marker before the layer table")
    layers = {}
    for line in text[at:].splitlines()[1:]:
        line = line.strip()
        if not line.startswith("|"):
            if layers:
                break
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        if len(cells) < 2 or not re.fullmatch(r"\d+", cells[0]):
            continue  # header or separator row
        layers[cells[1]] = int(cells[0])
    if not layers:
        raise SystemExit(f"{doc}: the layer table after the marker is empty")
    return layers


def check(root):
    src = root / "src"
    layers = read_layers(root / "doc" / "architecture.md")
    problems = []
    rooms = sorted(p.name for p in src.iterdir() if p.is_dir())
    for room in rooms:
        if room not in layers:
            problems.append(f"src/{room}/: room missing from the layer table of doc/architecture.md")
    for room in layers:
        if room not in rooms:
            problems.append(f"doc/architecture.md: layer table names '{room}', which is not a folder of src/")
    for path in sorted(src.rglob("*")):
        if path.suffix not in (".h", ".cpp") or path.parent == src:
            continue
        room = path.relative_to(src).parts[0]
        if room not in layers:
            continue
        mine = layers[room]
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m or m.group(1) not in layers or m.group(1) == room:
                continue
            other = m.group(1)
            theirs = layers[other]
            if other == "core":
                ok = True
            elif room == "core":
                ok = path.suffix == ".cpp" or theirs <= 1
            else:
                ok = theirs <= mine
            if not ok:
                problems.append(f"{path.relative_to(root)}:{n}: {room} (layer {mine}) includes "
                                f"{other} (layer {theirs}): {line.strip()}")
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=str(Path(__file__).resolve().parent.parent))
    args = ap.parse_args()
    problems = check(Path(args.root))
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} include(s) against the layers of doc/architecture.md")
        return 1
    print("includes follow the layers of doc/architecture.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
