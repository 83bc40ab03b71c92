#!/usr/bin/env python3
"""Writes the libFuzzer dictionary of scenario keys from the schema reference.

    crater schema --markdown | tools/fuzz/scenario_dict.py > tests/fuzz/scenario.dict

Entries: every table header ([scenario], [[parts]], [parts.dem], ...), every key as `key = `,
every choice value as a TOML string, and a few TOML tokens (numbers at the edges of double,
inline tables and arrays, --set lines the harness understands).
"""
import re
import sys

md = sys.stdin.read()
entries = []


def add(s):
    if s not in entries:
        entries.append(s)


for m in re.finditer(r"^## `(\[\[?[a-z_.]+\]\]?)`", md, re.M):
    header = m.group(1)
    add(header)
    name = header.strip("[]")
    add(name.split(".")[-1])
for row in re.finditer(r"^\| `([a-z0-9_]+)` \|", md, re.M):
    add(row.group(1) + " = ")
    add("." + row.group(1))  # dotted keys and --set paths
for choice in re.findall(r'`"([^"`]+)"`', md):  # choices and string defaults
    add('"' + choice + '"')
for tok in ["true", "false", "inf", "-inf", "nan", "0", "-0.0", "1e308", "1e-308", "5e-324",
            "9223372036854775807", "-9223372036854775808", "0x7fffffffffffffff", "1e400",
            "[", "]", "{", "}", "[[", "]]", "=", ",", "\n", "\"\"\"", "'''", "#set ",
            "#set parts.0.", "#set scenario.dimension=3", "[0.0, 0.0]", "[0.0, 0.0, 0.0]",
            "{ type = \"box\", min_m = [0.0, 0.0], max_m = [1.0, 1.0] }",
            "{ type = \"disk\", center_m = [0.0, 0.0], radius_m = 0.1 }"]:
    add(tok)



def quote(s):
    # libFuzzer's dictionary syntax: \\ \" and \xAB escapes only.
    out = ""
    for ch in s.encode():
        c = chr(ch)
        out += "\\\\" if c == "\\" else '\\"' if c == '"' else c if 32 <= ch < 127 else "\\x%02X" % ch
    return '"' + out + '"'


for e in entries:
    print(quote(e))
