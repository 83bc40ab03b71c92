#!/usr/bin/env python3
"""crater verify: run the bundled verification cases and compare them with their references.

  crater verify [--quick] [--case NAME]... [--out DIR] [--json FILE] [--threads N] [--cases DIR]
  crater verify --list [--quick]

`crater verify` carries this script inside the binary (CMake embeds it at build time) and runs
it with Debian's /usr/bin/python3 (the standard library only) as
  /usr/bin/python3 crater_verify.py --crater /abs/path/to/crater --cases-dir DIR <arguments>
with DIR the installed <prefix>/share/crater/verify (else the source tree's verify/).

DIR/cases.toml lists the cases (its header documents every key): each is one scenario of DIR,
run by this crater binary as an ordinary `crater run` into OUT/<case>/, and one or more checks,
each a number measured in the run's history.csv, gauges.csv or summary.json against a reference
value from an independent solution, within a stated tolerance. --quick runs the cases marked
quick (one or more per method, under 10 minutes on 2 cores); --case runs the named ones.

Written: a table on stdout (case, quantity, measured, reference, error, tolerance, PASS/FAIL)
and OUT/verify.json (--json FILE as well): crater's version, the cases directory, every check's
figures, and "passed". OUT defaults to ./verify-out.

Exit codes: 0 every check passed; 1 a check failed or a case's run did not complete (the cases
named on stderr); 2 bad input (arguments, a malformed cases.toml, an unknown --case).
"""
import argparse
import csv
import fnmatch
import json
import math
import os
import subprocess
import sys
import time
import tomllib
from pathlib import Path

REDUCTIONS = ("final", "first", "max", "min", "mean", "at_time", "span_above", "span_below",
              "first_time_above", "final_over_first")
CASE_KEYS = {"name", "scenario", "quick", "method", "what", "source", "check"}
CHECK_KEYS = {"quantity", "unit", "file", "column", "key", "abs", "scale", "offset", "reduce",
              "time_s", "from_s", "to_s", "threshold", "power", "reference", "tolerance_rel",
              "tolerance_abs"}


class InputError(Exception):
    pass


class MeasureError(Exception):
    pass


def fail_input(msg):
    print(f"crater verify: error: {msg}", file=sys.stderr)
    sys.exit(2)


def number(check, key, where, required=False):
    v = check.get(key)
    if v is None:
        if required:
            raise InputError(f"{where}: `{key}` is required (a number)")
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InputError(f"{where}: `{key}` must be a finite number, got {v!r}")
    return float(v)


def validate(cases_file, data):
    cases = data.get("case")
    if not isinstance(cases, list) or not cases:
        raise InputError(f"{cases_file}: no [[case]] tables")
    names = set()
    for i, case in enumerate(cases):
        where = f"{cases_file}: case {i + 1}"
        unknown = set(case) - CASE_KEYS
        if unknown:
            raise InputError(f"{where}: unknown key(s) {sorted(unknown)}")
        for key in ("name", "scenario"):
            if not isinstance(case.get(key), str) or not case[key]:
                raise InputError(f"{where}: `{key}` is required (a string)")
        where = f"{cases_file}: case {case['name']!r}"
        if case["name"] in names:
            raise InputError(f"{where}: the name is used twice")
        names.add(case["name"])
        if not isinstance(case.get("quick", False), bool):
            raise InputError(f"{where}: `quick` must be true or false")
        checks = case.get("check")
        if not isinstance(checks, list) or not checks:
            raise InputError(f"{where}: no [[case.check]] tables")
        for j, c in enumerate(checks):
            cw = f"{where}, check {j + 1}"
            unknown = set(c) - CHECK_KEYS
            if unknown:
                raise InputError(f"{cw}: unknown key(s) {sorted(unknown)}")
            if not isinstance(c.get("quantity"), str):
                raise InputError(f"{cw}: `quantity` is required (a string)")
            number(c, "reference", cw, required=True)
            tols = [k for k in ("tolerance_rel", "tolerance_abs") if k in c]
            if len(tols) != 1:
                raise InputError(f"{cw}: exactly one of tolerance_rel, tolerance_abs is required")
            if number(c, tols[0], cw) < 0:
                raise InputError(f"{cw}: `{tols[0]}` must be >= 0")
            if tols[0] == "tolerance_rel" and c["reference"] == 0:
                raise InputError(f"{cw}: a reference of 0 needs tolerance_abs")
            f = c.get("file")
            if f == "summary.json":
                if not isinstance(c.get("key"), str):
                    raise InputError(f"{cw}: file summary.json needs `key` (a dotted path)")
            elif f in ("history.csv", "gauges.csv"):
                if not isinstance(c.get("column"), str):
                    raise InputError(f"{cw}: file {f} needs `column` (a name or glob)")
                r = c.get("reduce")
                if r not in REDUCTIONS:
                    raise InputError(f"{cw}: `reduce` must be one of {', '.join(REDUCTIONS)}; "
                                     f"got {r!r}")
                if r == "at_time":
                    number(c, "time_s", cw, required=True)
                if r in ("span_above", "span_below", "first_time_above"):
                    number(c, "threshold", cw, required=True)
                for k in ("scale", "offset", "power", "from_s", "to_s"):
                    number(c, k, cw)
                if ("from_s" in c or "to_s" in c) and r != "mean":
                    raise InputError(f"{cw}: from_s and to_s go with reduce = \"mean\"")
            else:
                raise InputError(f"{cw}: `file` must be history.csv, gauges.csv or summary.json;"
                                 f" got {f!r}")
    return cases


def read_csv(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        raise MeasureError(f"cannot read {path.name}: {e.strerror}")
    if not rows:
        raise MeasureError(f"{path.name} has no rows")
    return rows


def measure(run_dir, c):
    if c["file"] == "summary.json":
        try:
            value = json.loads((run_dir / "summary.json").read_text())
        except (OSError, ValueError) as e:
            raise MeasureError(f"cannot read summary.json: {e}")
        for part in c["key"].split("."):
            if not isinstance(value, dict) or part not in value:
                raise MeasureError(f"summary.json has no {c['key']}")
            value = value[part]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise MeasureError(f"summary.json's {c['key']} is not a number: {value!r}")
        return float(value)
    rows = read_csv(run_dir / c["file"])
    columns = [k for k in rows[0] if fnmatch.fnmatchcase(k, c["column"])]
    if not columns:
        raise MeasureError(f"{c['file']} has no column matching {c['column']!r}")
    t = [float(r["time_s"]) for r in rows]
    s = [sum(float(r[k]) for k in columns) / len(columns) for r in rows]
    if c.get("abs", False):
        s = [abs(v) for v in s]
    scale, offset = float(c.get("scale", 1.0)), float(c.get("offset", 0.0))
    s = [scale * v + offset for v in s]
    if any(not math.isfinite(v) for v in s):
        raise MeasureError(f"{c['file']}: {c['column']} holds a value that is not finite")
    r = c["reduce"]
    if r == "final":
        v = s[-1]
    elif r == "first":
        v = s[0]
    elif r == "max":
        v = max(s)
    elif r == "min":
        v = min(s)
    elif r == "mean":
        lo, hi = float(c.get("from_s", t[0])), float(c.get("to_s", t[-1]))
        window = [x for x, tk in zip(s, t) if lo <= tk <= hi]
        if not window:
            raise MeasureError(f"no row between {lo:g} and {hi:g} s")
        v = sum(window) / len(window)
    elif r == "final_over_first":
        if s[0] == 0:
            raise MeasureError(f"{c['column']} is 0 in the first row")
        v = s[-1] / s[0]
    elif r == "at_time":
        ts = float(c["time_s"])
        if not t[0] <= ts <= t[-1]:
            raise MeasureError(f"time_s {ts:g} is outside the rows' {t[0]:g} to {t[-1]:g} s")
        i = next(i for i in range(len(t)) if t[i] >= ts)
        if t[i] == ts or i == 0:
            v = s[i]
        else:
            w = (ts - t[i - 1]) / (t[i] - t[i - 1])
            v = (1 - w) * s[i - 1] + w * s[i]
    else:
        th = float(c["threshold"])
        if r == "span_below":
            hit = [i for i, x in enumerate(s) if x < th]
        else:
            hit = [i for i, x in enumerate(s) if x > th]
        if not hit:
            side = "below" if r == "span_below" else "above"
            raise MeasureError(f"{c['column']} is never {side} {th:g}")
        v = t[hit[0]] if r == "first_time_above" else t[hit[-1]] - t[hit[0]]
    if "power" in c:
        if v < 0:
            raise MeasureError(f"{c['column']}: {v:g} < 0 cannot be raised to a power")
        v = v ** float(c["power"])
    return v


def judge(c, measured):
    ref = float(c["reference"])
    if "tolerance_rel" in c:
        err, tol = measured / ref - 1.0, float(c["tolerance_rel"])
        return err, tol, abs(err) <= tol, f"{100 * err:+.2f} %", f"{100 * tol:g} %"
    err, tol = measured - ref, float(c["tolerance_abs"])
    return err, tol, abs(err) <= tol, f"{err:+.3g}", f"{tol:g}"


def run_case(crater, cases_dir, case, out, threads):
    run_dir = out / case["name"]
    cmd = [crater, "run", str(cases_dir / case["scenario"]), "--out", str(run_dir), "--force",
           "--quiet"]
    if threads:
        cmd += ["--threads", str(threads)]
    t0 = time.monotonic()
    proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.monotonic() - t0
    (out / f"{case['name']}.log").write_text(proc.stderr)
    return run_dir, proc.returncode, wall, proc.stderr


def fmt(v):
    return f"{v:.5g}" if v is not None else "-"


def main():
    ap = argparse.ArgumentParser(prog="crater verify", description=__doc__.split("\n")[0])
    ap.add_argument("--crater", required=True, help=argparse.SUPPRESS)
    ap.add_argument("--cases-dir", required=True, help=argparse.SUPPRESS)
    ap.add_argument("--quick", action="store_true", help="only the cases marked quick")
    ap.add_argument("--case", action="append", default=[], metavar="NAME",
                    help="run this case (repeatable; default: all, or the quick ones)")
    ap.add_argument("--cases", metavar="DIR",
                    help="another cases directory (default: the installed one)")
    ap.add_argument("--out", default="verify-out", help="where the runs go (default: "
                    "./verify-out)")
    ap.add_argument("--json", metavar="FILE", help="also write the results here")
    ap.add_argument("--threads", type=int, help="threads per run (default: crater's)")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    a = ap.parse_args()
    if a.threads is not None and a.threads < 1:
        fail_input("--threads must be at least 1")

    cases_dir = Path(a.cases or a.cases_dir).resolve()
    cases_file = cases_dir / "cases.toml"
    try:
        data = tomllib.loads(cases_file.read_text())
    except OSError as e:
        fail_input(f"cannot read {cases_file}: {e.strerror}")
    except tomllib.TOMLDecodeError as e:
        fail_input(f"{cases_file}: {e}")
    try:
        cases = validate(cases_file, data)
    except InputError as e:
        fail_input(str(e))
    known = [c["name"] for c in cases]
    for n in a.case:
        if n not in known:
            fail_input(f"--case {n}: no such case (cases: {', '.join(known)})")
    chosen = [c for c in cases if (not a.case or c["name"] in a.case)
              and (not a.quick or c.get("quick", False))]
    if not chosen:
        fail_input("no case to run (--case and --quick select none)")
    if a.list:
        for c in chosen:
            q = "quick" if c.get("quick") else "     "
            print(f"{c['name']:<22} {q} {c.get('method', ''):<4} {c.get('what', '')}")
        return 0

    version = subprocess.run([a.crater, "--version"], capture_output=True,
                             text=True).stdout.strip()
    out = Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    print(f"{version}: {len(chosen)} verification case(s) from {cases_dir} into {out}",
          file=sys.stderr)
    results, failed = [], []
    t_all = time.monotonic()
    for case in chosen:
        print(f"  {case['name']} ...", file=sys.stderr, flush=True)
        run_dir, rc, wall, err = run_case(a.crater, cases_dir, case, out, a.threads)
        entry = {"name": case["name"], "method": case.get("method", ""),
                 "what": case.get("what", ""), "source": case.get("source", ""),
                 "scenario": str(cases_dir / case["scenario"]), "run_dir": str(run_dir),
                 "exit_code": rc, "wall_s": round(wall, 2), "checks": []}
        if rc != 0:
            last = err.strip().splitlines()[-1] if err.strip() else ""
            entry["error"] = f"crater run exited with {rc}: {last}"
        for c in case["check"]:
            chk = {"quantity": c["quantity"], "unit": c.get("unit", "1"),
                   "reference": float(c["reference"]), "measured": None, "passed": False}
            if rc == 0:
                try:
                    m = measure(run_dir, c)
                    e, tol, ok, e_text, tol_text = judge(c, m)
                    chk.update(measured=m, error=e, tolerance=tol, passed=ok,
                               tolerance_kind="rel" if "tolerance_rel" in c else "abs",
                               error_text=e_text, tolerance_text=tol_text)
                except MeasureError as e:
                    chk["error_message"] = str(e)
            entry["checks"].append(chk)
        entry["passed"] = rc == 0 and all(k["passed"] for k in entry["checks"])
        if not entry["passed"]:
            failed.append(case["name"])
        results.append(entry)

    header = ("case", "quantity", "measured", "reference", "error", "tolerance", "result")
    lines = []
    for e in results:
        for k in e["checks"]:
            result = "PASS" if k["passed"] else "FAIL"
            lines.append((e["name"], k["quantity"], fmt(k["measured"]), fmt(k["reference"]),
                          k.get("error_text", "-"), k.get("tolerance_text", "-"), result))
    widths = [max(len(r[i]) for r in [header] + lines) for i in range(len(header))]
    for r in [header, tuple("-" * w for w in widths)] + lines:
        print("  ".join(x.ljust(w) for x, w in zip(r, widths)).rstrip())
    doc = {"crater_version": version, "cases_dir": str(cases_dir), "quick": a.quick,
           "wall_s": round(time.monotonic() - t_all, 2), "passed": not failed,
           "failed": failed, "cases": results}
    text = json.dumps(doc, indent=2) + "\n"
    (out / "verify.json").write_text(text)
    if a.json:
        Path(a.json).write_text(text)
    n_checks = sum(len(e["checks"]) for e in results)
    if failed:
        for e in results:
            if e["passed"]:
                continue
            why = e.get("error") or "; ".join(
                f"{k['quantity']}: " + (k.get("error_message") or
                                        f"{fmt(k['measured'])} vs {fmt(k['reference'])}")
                for k in e["checks"] if not k["passed"])
            print(f"crater verify: FAILED {e['name']}: {why}", file=sys.stderr)
        return 1
    print(f"crater verify: all {n_checks} checks of {len(results)} case(s) passed "
          f"({doc['wall_s']:.0f} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(130)
