#!/usr/bin/python3
"""Holds src/ to the size limits of docs/architecture.md: lines per file and per function.

  tools/check_sizes.py [--root DIR]        (DIR: a checkout; default: this one)

The limits are the fenced block ```sizes ...``` of DIR/docs/architecture.md, one per line:

  file-lines 800                        # no file in src/ longer than this
  function-lines 120                    # no function (definition, body included) longer
  except src/io/scenario/scenario_schema.cpp   # a table: exempt from both limits
  known-file src/dem/dem_part.cpp       # too long today, to be split
  known-function src/solver/simulation.cpp run   # likewise one function (by name)

Functions are found by Universal Ctags (kind f, C++, with their end lines): member functions,
free functions and constructors; a lambda counts towards the function that holds it. A
`known-...` line that no longer matches anything is itself an error, so the list only shrinks.
Exit status: 0 clean, 1 over a limit, 2 bad rules or no ctags.
"""
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import rule_check


def read_rules(doc):
    text = doc.read_text()
    m = re.search(r"```sizes\n(.*?)```", text, re.S)
    if not m:
        raise ValueError(f"{doc}: no ```sizes block")
    limits, excepted, known_files, known_functions = {}, set(), set(), set()
    for n, raw in enumerate(m.group(1).splitlines(), 1):
        line = raw.split("#", 1)[0].split()
        if not line:
            continue
        head, rest = line[0], line[1:]
        if head in ("file-lines", "function-lines") and len(rest) == 1 and rest[0].isdigit():
            limits[head] = int(rest[0])
        elif head == "except" and len(rest) == 1:
            excepted.add(rest[0])
        elif head == "known-file" and len(rest) == 1:
            known_files.add(rest[0])
        elif head == "known-function" and len(rest) == 2:
            known_functions.add((rest[0], rest[1]))
        else:
            raise ValueError(f"{doc}: sizes rule {n} not understood: {raw.strip()!r}")
    if set(limits) != {"file-lines", "function-lines"}:
        raise ValueError(f"{doc}: the sizes block needs file-lines and function-lines")
    return limits, excepted, known_files, known_functions


def sources(root):
    return sorted(p for p in (root / "src").rglob("*")
                  if p.is_file() and p.suffix in (".hpp", ".cpp", ".h", ".in"))


def functions(root, files):
    """[(file relative to root, name, first line, lines)] of every function definition."""
    ctags = shutil.which("ctags-universal") or shutil.which("ctags")
    if not ctags:
        raise ValueError("Universal Ctags not found (Debian package universal-ctags)")
    proc = subprocess.run([ctags, "--output-format=json", "--fields=+ne", "--kinds-C++=f",
                           "--language-force=C++", "-o", "-"] + [str(f) for f in files],
                          capture_output=True, text=True, check=True, cwd=root)
    found = []
    for line in proc.stdout.splitlines():
        tag = json.loads(line)
        if tag.get("_type") == "tag" and "end" in tag:
            path = str(Path(tag["path"]).resolve().relative_to(root.resolve()))
            found.append((path, tag["name"], tag["line"], tag["end"] - tag["line"] + 1))
    return found


def check(root):
    limits, excepted, known_files, known_functions = read_rules(
        root / "docs" / "architecture.md")
    files = sources(root)
    problems, used_files, used_functions = [], set(), set()
    for f in files:
        rel = str(f.relative_to(root))
        n = len(f.read_text(errors="replace").splitlines())
        if rel in excepted or n <= limits["file-lines"]:
            continue
        if rel in known_files:
            used_files.add(rel)
        else:
            problems.append(f"{rel}: {n} lines, over {limits['file-lines']} (docs/architecture.md)")
    for rel, name, line, n in functions(root, files):
        if rel in excepted or n <= limits["function-lines"]:
            continue
        if (rel, name) in known_functions:
            used_functions.add((rel, name))
        else:
            problems.append(f"{rel}:{line}: function {name} is {n} lines, over "
                            f"{limits['function-lines']} (docs/architecture.md)")
    for rel in sorted(known_files - used_files):
        problems.append(f"'known-file {rel}' in docs/architecture.md no longer applies: take the "
                        "line out")
    for rel, name in sorted(known_functions - used_functions):
        problems.append(f"'known-function {rel} {name}' in docs/architecture.md no longer "
                        "applies: take the line out")
    for rel in sorted(excepted):
        if not (root / rel).is_file():
            problems.append(f"'except {rel}' in docs/architecture.md names no file")
    return problems


if __name__ == "__main__":
    sys.exit(rule_check.main(__doc__, check, "check_sizes", "size", (OSError, ValueError, subprocess.CalledProcessError)))
