#!/usr/bin/python3
"""Holds src/'s folders to the layering rules of docs/architecture.md.

  tools/check_layers.py [--root DIR]        (DIR: a checkout; default: this one)

The rules are the fenced block ```layers ...``` of DIR/docs/architecture.md, one per line:

  sph !io !solver !app !dem !fem      # folder src/sph includes nothing from these folders
  cycles none                         # no include cycle between folders
  known src/sph/sph_part.hpp io       # a violation that exists today and is to be removed
  known-cycle io solver sph           # folders that include each other today
  allow io sph/settings.hpp           # this one header of a forbidden folder is allowed

A line `known FILE FOLDER` excuses one file's includes of one folder, and `known-cycle A B C`
one group of folders that reach each other through includes (a strongly connected set), while the restructuring that removes them (issue 23) is under way. A
`known` line that no longer matches anything is itself an error, so the list only shrinks.
Exit status: 0 clean, 1 violations (each printed as file:line: what), 2 bad rules.
"""
import re
import sys
from pathlib import Path

import rule_check

INCLUDE = re.compile(r'^\s*#\s*include\s+"(([a-z_]+)/[^"]*)"')


def read_rules(doc):
    """(forbidden: {folder: set}, cycles_allowed: bool, known: set, known_cycles: set,
    allowed: set of (folder, included header))."""
    text = doc.read_text()
    m = re.search(r"```layers\n(.*?)```", text, re.S)
    if not m:
        raise ValueError(f"{doc}: no ```layers block")
    forbidden, known, known_cycles, allowed, cycles_allowed = {}, set(), set(), set(), True
    for n, raw in enumerate(m.group(1).splitlines(), 1):
        line = raw.split("#", 1)[0].split()
        if not line:
            continue
        head, rest = line[0], line[1:]
        if head == "cycles" and rest == ["none"]:
            cycles_allowed = False
        elif head == "known" and len(rest) == 2:
            known.add((rest[0], rest[1]))
        elif head == "allow" and len(rest) == 2:
            allowed.add((rest[0], rest[1]))
        elif head == "known-cycle" and len(rest) >= 2:
            known_cycles.add(tuple(sorted(rest)))
        elif rest and all(r.startswith("!") for r in rest):
            forbidden.setdefault(head, set()).update(r[1:] for r in rest)
        else:
            raise ValueError(f"{doc}: layers rule {n} not understood: {raw.strip()!r}")
    return forbidden, cycles_allowed, known, known_cycles, allowed


def includes(src):
    """[(file relative to the checkout, line, from folder, to folder, header)] of src/'s own
    includes (header: as written, relative to src/)."""
    found = []
    for path in sorted(src.rglob("*")):
        if path.suffix not in (".hpp", ".cpp", ".h", ".in") or not path.is_file():
            continue
        folder = path.relative_to(src).parts[0]
        for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            m = INCLUDE.match(line)
            if m and m.group(2) != folder and (src / m.group(2)).is_dir():
                found.append((str(path.relative_to(src.parent)), n, folder, m.group(2),
                              m.group(1)))
    return found


def cycles(edges):
    """Groups of two or more folders that reach each other through includes (the strongly
    connected sets), each as a sorted tuple."""
    graph = {}
    for a, b in edges:
        graph.setdefault(a, set()).add(b)

    def reach(start):
        seen, todo = set(), [start]
        while todo:
            for nxt in graph.get(todo.pop(), ()):
                if nxt not in seen:
                    seen.add(nxt)
                    todo.append(nxt)
        return seen

    reached = {a: reach(a) for a in graph}
    groups = {tuple(sorted({a} | {b for b in reached[a] if a in reached.get(b, ())}))
              for a in graph}
    return sorted(g for g in groups if len(g) > 1)


def check(root):
    forbidden, cycles_allowed, known, known_cycles, allowed = read_rules(
        root / "docs" / "architecture.md")
    found = includes(root / "src")
    problems, used = [], set()
    for file, line, a, b, header in found:
        if b in forbidden.get(a, ()) and (a, header) not in allowed:
            if (file, b) in known:
                used.add((file, b))
            else:
                problems.append(f"{file}:{line}: src/{a} includes src/{b}/ (docs/architecture.md: "
                                f"'{a}' must not include '{b}')")
    for file, b in sorted(known - used):
        problems.append(f"{file}: 'known {file} {b}' in docs/architecture.md no longer happens: "
                        "take the line out")
    if not cycles_allowed:
        found_cycles = cycles((a, b) for _, _, a, b, _ in found)
        for group in found_cycles:
            if group not in known_cycles:
                problems.append(f"an include cycle joins src/{', src/'.join(group)} (each reaches "
                                "the others); docs/architecture.md: cycles none (listed: "
                                f"'known-cycle {' '.join(group)}')")
        for group in sorted(known_cycles - set(found_cycles)):
            problems.append(f"'known-cycle {' '.join(group)}' no longer happens: take the line "
                            "out or put the cycle that is left")
    return problems


if __name__ == "__main__":
    sys.exit(rule_check.main(__doc__, check, "check_layers", "layering", (OSError, ValueError)))
