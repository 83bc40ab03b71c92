#!/usr/bin/env python3
"""crater sweep: run one scenario over a grid or a Latin hypercube of parameter values.

  crater sweep SCENARIO --vary KEY=v1,v2,... [--vary KEY=...]... [--level L] [--set KEY=VALUE]...
               [--samples N [--seed S]] [--jobs N] [--threads-per-job T] [--out DIR]
               [--metrics m1,m2,...]
  crater sweep --resume DIR [--jobs N] [--threads-per-job T]
  crater report DIR                      (DIR holding a sweep.json: the sweep's report)

`crater sweep` and `crater report` carry this script inside the binary (CMake embeds it at
build time) and run it with Debian's /usr/bin/python3 (python3-numpy, python3-matplotlib) as
  /usr/bin/python3 crater_sweep.py --crater /abs/path/to/crater <the user's arguments>
  /usr/bin/python3 crater_sweep.py --crater /abs/path/to/crater --report DIR [--out OUT]
Every case is an ordinary `crater run` of that binary, a process of its own.

SCENARIO is a scenario file or a bundled name (a file is recorded by its absolute path and the
SHA-256 of its text). Each --vary KEY=v1,v2,... names a dotted scenario key (as crater's --set:
parts.plate.region.thickness_m, time.safety_factor, parts.0.spacing_m) and its values (TOML
scalars: numbers, true/false, bare words); several --vary give every combination (the first key
slowest). With --samples N every --vary is a range KEY=lo:hi instead and N cases are drawn by a
Latin hypercube (each key's range cut into N equal strata, one value in each, the strata paired
at random; numpy's default Generator seeded with --seed, default 1; integer bounds give
integers). --level and the --set values go to every case, then the case's own values as further
--set. --jobs N cases run at once (default 1), each with --threads T (--threads-per-job,
default 1).

Before anything runs, `crater check` validates every case that is not completed yet (--jobs at
a time): one failing case stops the sweep (exit 2), naming its values and crater's message.

Written into DIR (--out, default ./sweep):
  sweep.json       the plan: scenario, level, sets, the varied keys, the cases with their
                   values, the crater binary's --version (written atomically, before any run);
  cases/case_0001/ ... one `crater run` directory per case;
  sweep.csv        one row per case: case, each varied key, status (completed, failed,
                   interrupted, running, not run), exit_code, wall_s, then every scalar of the
                   case's summary.json metrics (nested objects as a.b), energy.balance_error and
                   each part's mass and diagnostics (parts.<part>.<name>), sorted by name (rewritten atomically after every finished case);
  sweep.log        each case's stderr, every line prefixed with the case;
  charts/<metric>.png  at the end: each charted metric (--metrics, default every numeric metric
                   that varies over the completed cases, at most 12) over the varied keys: a line
                   for one key, filled contours for two, a scatter per key for more; failed cases
                   marked with a red x and not interpolated through.
`--report DIR [--out OUT]` redraws the charts and writes OUT/report.md (default DIR/report/).

Resuming: the same command again (or `crater sweep --resume DIR`) skips the completed cases
(summary.json "status": "completed"), continues a case that has a checkpoint with
`crater run --resume` (afresh if crater refuses it with exit 2) and runs any other case afresh
(--force). A DIR whose sweep.json holds a different plan is refused. SIGINT/SIGTERM: passed on to
the running cases (crater writes a checkpoint and exits 130), waited for, then exit 130.

Exit codes: 0 every case completed; 1 some case failed (the others still ran; the failed ones
are listed at the end), or another error (the crater binary cannot be run, missing Python
modules); 2 bad input (arguments, a case crater check rejects, a DIR holding another sweep, no
sweep.json for --report); 130 interrupted.
"""
import argparse
import csv
import hashlib
import io
import itertools
import json
import math
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
import warnings
from datetime import datetime, timezone
from pathlib import Path

EXIT_OK, EXIT_FAILED, EXIT_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130
CRATER_EXIT_INPUT, CRATER_EXIT_INTERRUPTED = 2, 130
DEBIAN_PACKAGES = "python3-numpy python3-matplotlib"

PLAN_FILE = "sweep.json"
CSV_FILE = "sweep.csv"
LOG_FILE = "sweep.log"
PARTS_PREFIX = "parts."  # sweep.csv's columns of the parts' masses and diagnostics
LOCK_FILE = ".sweep.lock"
CASES_DIR = "cases"
CHARTS_DIR = "charts"
STDERR_DIR = ".running"   # a running case's stderr, until it is appended to sweep.log
REPORT_FILE = "report.md"
PLAN_FORMAT = "crater-sweep/1"
# What makes two sweeps the same plan; sweep.json's other fields (jobs, threads, metrics, the
# crater version, when it was made) may change between sessions.
PLAN_IDENTITY = ("format", "scenario", "scenario_sha256", "level", "sets", "vary", "samples",
                 "seed", "cases")

DEFAULT_OUT = "sweep"
DEFAULT_SEED = 1
MAX_DEFAULT_METRICS = 12
MAX_LISTED_REJECTED = 5  # cases crater check rejects, listed with their messages
FIXED_COLUMNS = ("case",)  # then the varied keys, then STATUS_COLUMNS
STATUS_COLUMNS = ("status", "exit_code", "wall_s")
ENERGY_COLUMN = "energy.balance_error"
LOCK_WAIT_S = 60.0  # an earlier sweep's crater runs finishing their checkpoints
POLL_S = 0.1
DPI = 100

KEY_RE = re.compile(r"[A-Za-z0-9_-]+(?:\.[A-Za-z0-9_-]+)*\Z")
INT_RE = re.compile(r"[+-]?\d(?:_?\d)*\Z")
FLOAT_RE = re.compile(r"[+-]?(?:\d(?:_?\d)*)(?:\.\d(?:_?\d)*)?(?:[eE][+-]?\d(?:_?\d)*)?\Z")


class InputError(Exception):
    """Bad input (exit 2): the message says what and where."""


class ToolError(Exception):
    """Not the user's input (exit 1): the crater binary cannot be run, a module is missing."""


def say(msg):
    print(f"crater sweep: {msg}", file=sys.stderr, flush=True)


def warn(msg):
    say(f"warning: {msg}")


# ---------------------------------------------------------------------------------------------
# Arguments and the plan
# ---------------------------------------------------------------------------------------------

def parse_args(argv):
    ap = argparse.ArgumentParser(
        prog="crater sweep", allow_abbrev=False,
        description="Run a scenario over a grid (or a Latin hypercube) of scenario values.")
    ap.add_argument("--crater", help=argparse.SUPPRESS)
    ap.add_argument("scenario", nargs="?", metavar="SCENARIO",
                    help="scenario file or bundled scenario name")
    ap.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...",
                    help="a dotted scenario key and its values (with --samples: KEY=LO:HI)")
    ap.add_argument("--level", help="resolution level, passed to every case")
    ap.add_argument("--set", action="append", default=[], dest="sets", metavar="KEY=VALUE",
                    help="a scenario override passed to every case (before the varied values)")
    ap.add_argument("--samples", type=int, metavar="N",
                    help="N cases from a Latin hypercube over the --vary ranges")
    ap.add_argument("--seed", type=int, metavar="S",
                    help=f"seed of the Latin hypercube (default {DEFAULT_SEED})")
    ap.add_argument("--jobs", type=int, metavar="N", help="cases run at once (default 1)")
    ap.add_argument("--threads-per-job", type=int, metavar="T",
                    help="crater run --threads of each case (default 1)")
    ap.add_argument("--out", metavar="DIR", help=f"sweep directory (default {DEFAULT_OUT})")
    ap.add_argument("--metrics", metavar="M1,M2,...", help="the metrics to chart")
    ap.add_argument("--resume", metavar="DIR", help="continue the sweep in DIR (its sweep.json)")
    ap.add_argument("--report", metavar="DIR", help="charts and report.md of the sweep in DIR")
    return ap.parse_args(argv)


def split_list(text):
    """Splits v1,v2,... at the commas outside brackets and quotes."""
    items, depth, quote, cur = [], 0, None, []
    for ch in text:
        if quote:
            cur.append(ch)
            if ch == quote:
                quote = None
        elif ch in "\"'":
            quote = ch
            cur.append(ch)
        elif ch in "[{":
            depth += 1
            cur.append(ch)
        elif ch in "]}":
            depth -= 1
            cur.append(ch)
        elif ch == "," and depth == 0:
            items.append("".join(cur).strip())
            cur = []
        else:
            cur.append(ch)
    items.append("".join(cur).strip())
    return items


def split_key(item, option):
    if "=" not in item:
        raise InputError(f"{option} '{item}': expected KEY=" +
                         ("VALUES" if option == "--vary" else "VALUE"))
    key, value = item.split("=", 1)
    key = key.strip()
    if not KEY_RE.match(key):
        raise InputError(f"{option} '{item}': '{key}' is not a dotted scenario key "
                         "(e.g. time.safety_factor or parts.0.spacing_m)")
    return key, value.strip()


def parse_number(text):
    """A TOML number as a float; None if text is not one."""
    t = text.strip()
    if t in ("inf", "+inf", "-inf", "nan", "+nan", "-nan"):
        return float(t)
    if FLOAT_RE.match(t):
        return float(t.replace("_", ""))
    return None


def parse_vary(item, sampled):
    key, rhs = split_key(item, "--vary")
    if sampled:
        if ":" not in rhs or "," in rhs:
            raise InputError(f"--vary '{item}': with --samples every --vary is a range KEY=LO:HI")
        lo_s, hi_s = (s.strip() for s in rhs.split(":", 1))
        lo, hi = parse_number(lo_s), parse_number(hi_s)
        if lo is None or hi is None or not (math.isfinite(lo) and math.isfinite(hi)):
            raise InputError(f"--vary '{item}': LO and HI must be finite numbers")
        if lo >= hi:
            raise InputError(f"--vary '{item}': LO must be below HI")
        return {"key": key, "range": [lo_s, hi_s]}
    if rhs == "":
        raise InputError(f"--vary '{item}': no values (give KEY=V1,V2,...)")
    values = split_list(rhs)
    if any(v == "" for v in values):
        raise InputError(f"--vary '{item}': an empty value in the list")
    if len(values) == 1 and re.fullmatch(r"[^:\[\]\"']+:[^:\[\]\"']+", values[0]):
        raise InputError(f"--vary '{item}': a range LO:HI needs --samples N "
                         "(without it, list the values: KEY=V1,V2,...)")
    seen = {}
    for v in values:
        canon = parse_number(v)
        canon = v if canon is None else canon
        if canon in seen:
            raise InputError(f"--vary '{item}': the value {v} is given twice")
        seen[canon] = v
    return {"key": key, "values": values}


def format_sample(x, integer):
    if integer:
        return str(int(x))
    s = f"{x:.8g}"
    return s if any(c in s for c in ".en") else s + ".0"


def latin_hypercube(vary, n, seed):
    """n cases: for each key (in order) a permutation of the n strata and a uniform offset in
    each, from numpy's default Generator seeded with seed."""
    np = import_numpy()
    rng = np.random.default_rng(seed)
    columns = []
    for v in vary:
        lo_s, hi_s = v["range"]
        integer = bool(INT_RE.match(lo_s) and INT_RE.match(hi_s))
        lo, hi = parse_number(lo_s), parse_number(hi_s)
        strata = rng.permutation(n)
        u = rng.random(n)
        if integer:
            x = np.floor(lo + (hi - lo + 1) * (strata + u) / n)
            x = np.minimum(x, hi)
        else:
            x = lo + (hi - lo) * (strata + u) / n
        columns.append([format_sample(float(xi), integer) for xi in x])
    return [tuple(col[i] for col in columns) for i in range(n)]


def case_id(i, n):
    return f"case_{i + 1:0{max(4, len(str(n)))}d}"


def scenario_identity(scenario):
    """(what is passed to crater, the file's SHA-256 or None): a file by its absolute path."""
    p = Path(scenario)
    if p.is_file():
        try:
            digest = hashlib.sha256(p.read_bytes()).hexdigest()
        except OSError as e:
            raise InputError(f"{scenario}: cannot read the scenario file ({e})") from None
        return str(p.resolve()), digest
    return scenario, None


def build_plan(args):
    if not args.scenario:
        raise InputError("no SCENARIO (give a scenario file or a bundled name, or --resume DIR)")
    if not args.vary:
        raise InputError("no --vary: give at least one --vary KEY=V1,V2,...")
    sampled = args.samples is not None
    if sampled and args.samples < 2:
        raise InputError(f"--samples {args.samples}: at least 2")
    if args.seed is not None and not sampled:
        raise InputError("--seed is for --samples (a Latin hypercube)")
    if args.seed is not None and args.seed < 0:
        raise InputError(f"--seed {args.seed}: a non-negative integer")
    sets = []
    for s in args.sets:
        key, value = split_key(s, "--set")
        if value == "":
            raise InputError(f"--set '{s}': no value")
        sets.append(f"{key}={value}")
    vary = [parse_vary(v, sampled) for v in args.vary]
    keys = [v["key"] for v in vary]
    for k in keys:
        if keys.count(k) > 1:
            raise InputError(f"--vary: the key {k} is given twice")
    if sampled:
        seed = DEFAULT_SEED if args.seed is None else args.seed
        combos = latin_hypercube(vary, args.samples, seed)
    else:
        seed = None
        combos = list(itertools.product(*(v["values"] for v in vary)))
    scenario, digest = scenario_identity(args.scenario)
    cases = [{"id": case_id(i, len(combos)), "values": dict(zip(keys, combo))}
             for i, combo in enumerate(combos)]
    return {"format": PLAN_FORMAT, "scenario": scenario, "scenario_sha256": digest,
            "level": args.level or "", "sets": sets, "vary": vary,
            "samples": args.samples if sampled else None, "seed": seed, "cases": cases}


def plan_keys(plan):
    return [v["key"] for v in plan["vary"]]


def plan_difference(old, new):
    """'' if the plans are the same sweep, else what differs, in words."""
    for field in PLAN_IDENTITY:
        a, b = old.get(field), new.get(field)
        if a == b:
            continue
        if field == "scenario_sha256":
            return "the scenario file changed since the sweep started"
        if field == "cases":
            return f"its {len(a or [])} cases are not these {len(b or [])}"
        if field == "vary":
            return f"it varies {describe_vary(a)}, not {describe_vary(b)}"
        what = {"scenario": "scenario", "level": "--level", "sets": "--set values",
                "samples": "--samples", "seed": "--seed", "format": "format"}.get(field, field)
        return f"its {what}: {json.dumps(a)}, not {json.dumps(b)}"
    return ""


def describe_vary(vary):
    out = []
    for v in vary or []:
        if "range" in v:
            out.append(f"{v['key']}={v['range'][0]}:{v['range'][1]}")
        else:
            out.append(f"{v['key']}={','.join(v['values'])}")
    return " ".join(out) if out else "nothing"


def load_plan(sweep_dir):
    path = Path(sweep_dir) / PLAN_FILE
    if not path.is_file():
        raise InputError(f"{sweep_dir}: no {PLAN_FILE}; not the directory of a crater sweep")
    try:
        plan = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise InputError(f"{path}: not readable as JSON ({e})") from None
    ok = (isinstance(plan, dict) and plan.get("format") == PLAN_FORMAT
          and isinstance(plan.get("cases"), list) and isinstance(plan.get("vary"), list)
          and all(isinstance(c, dict) and isinstance(c.get("values"), dict)
                  and isinstance(c.get("id"), str) for c in plan["cases"]))
    if not ok:
        raise InputError(f"{path}: not a plan of crater sweep (format {PLAN_FORMAT})")
    return plan


def write_atomic(path, text):
    """Writes text to path through a temporary file in the same directory and os.replace: a
    reader (or a killed writer) sees the old file or the new one, never half of one."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", newline="") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def save_plan(sweep_dir, plan):
    write_atomic(Path(sweep_dir) / PLAN_FILE, json.dumps(plan, indent=2) + "\n")


def values_text(plan, case):
    return ", ".join(f"{k}={case['values'][k]}" for k in plan_keys(plan))


def case_sets(plan, case):
    return [*plan["sets"], *(f"{k}={case['values'][k]}" for k in plan_keys(plan))]


def level_args(plan):
    return ["--level", plan["level"]] if plan.get("level") else []


# ---------------------------------------------------------------------------------------------
# Processes
# ---------------------------------------------------------------------------------------------

class Stop:
    """SIGINT/SIGTERM: counted here, acted upon by the loops that wait for crater."""

    def __init__(self):
        self.count = 0
        self.old = {}

    def __call__(self, signum, frame):
        self.count += 1

    def install(self):
        for s in (signal.SIGINT, signal.SIGTERM):
            self.old[s] = signal.signal(s, self)

    def restore(self):
        for s, h in self.old.items():
            signal.signal(s, h)
        self.old = {}


def child_setup():
    """preexec_fn of every crater process: SIGTERM when this script dies (even by kill -9), so
    that a run does not go on unattended; crater then writes a checkpoint and exits."""
    parent = PARENT_PID
    if PRCTL is not None:
        PRCTL(1, signal.SIGTERM, 0, 0, 0)  # PR_SET_PDEATHSIG
    if os.getppid() != parent:  # the parent died before prctl took effect
        os.kill(os.getpid(), signal.SIGTERM)


def load_prctl():
    try:
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl
    except (OSError, AttributeError, ImportError):
        return None


PRCTL = None
PARENT_PID = os.getpid()


def crater_version(crater):
    try:
        p = subprocess.run([crater, "--version"], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError) as e:
        raise ToolError(f"cannot run the crater binary {crater} ({e})") from None
    if p.returncode != 0:
        raise ToolError(f"{crater} --version exited {p.returncode}: {p.stderr.strip()}")
    return p.stdout.strip()


def last_message(text):
    """The line of crater's stderr that says what went wrong: the last 'error:' line, else the
    last non-empty one."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("error:") or " error: " in ln]
    if errors:
        return errors[-1]
    return lines[-1] if lines else ""


def check_cases(crater, plan, cases, jobs, stop):
    """`crater check` of each case, jobs at a time; [(case, exit code, stderr)] of those that
    failed. Returns None if interrupted."""
    pending, running, failed = list(cases), [], []
    while pending or running:
        if stop.count:
            for case, proc, err in running:
                proc.kill()
                proc.wait()
                err.close()
            return None
        while pending and len(running) < jobs:
            case = pending.pop(0)
            cmd = [crater, "check", plan["scenario"], *level_args(plan)]
            for s in case_sets(plan, case):
                cmd += ["--set", s]
            err = tempfile.TemporaryFile()
            proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                    stderr=err, preexec_fn=child_setup)
            running.append((case, proc, err))
        done = [r for r in running if r[1].poll() is not None]
        for r in done:
            running.remove(r)
            case, proc, err = r
            err.seek(0)
            text = err.read().decode("utf-8", "replace")
            err.close()
            if proc.returncode != 0:
                failed.append((case, proc.returncode, text))
        if not done:
            time.sleep(POLL_S)
    return failed


def acquire_lock(sweep_dir, stop):
    """An exclusive flock on DIR/.sweep.lock, held by this script and passed to its crater runs:
    a second sweep in DIR waits until the first one and all its runs are gone. None if
    interrupted meanwhile."""
    import fcntl
    fd = os.open(Path(sweep_dir) / LOCK_FILE, os.O_RDWR | os.O_CREAT, 0o644)
    deadline, told = time.monotonic() + LOCK_WAIT_S, False
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return fd
        except BlockingIOError:
            if stop.count:
                os.close(fd)
                return None
            if time.monotonic() > deadline:
                os.close(fd)
                raise InputError(f"{sweep_dir}: another crater sweep (or crater runs it started) "
                                 "is still running there") from None
            if not told:
                say(f"waiting for the crater runs of another sweep in {sweep_dir} to stop")
                told = True
            time.sleep(0.5)


def read_summary(case_dir):
    try:
        s = json.loads((Path(case_dir) / "summary.json").read_text())
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    return s if isinstance(s, dict) else None


def is_completed(case_dir):
    s = read_summary(case_dir)
    return bool(s) and s.get("status") == "completed"


def has_checkpoint(case_dir):
    d = Path(case_dir) / "checkpoints"
    return d.is_dir() and any(d.glob("*.ckpt"))


class Job:
    def __init__(self, index, case, mode):
        self.index, self.case, self.mode = index, case, mode  # mode: "fresh" or "resume"
        self.proc, self.err, self.start, self.notes = None, None, None, []


class Sweep:
    """One session of running the cases of a plan in DIR."""

    def __init__(self, crater, plan, sweep_dir, jobs, threads, lock_fd, stop):
        self.crater, self.plan, self.dir = crater, plan, Path(sweep_dir)
        self.jobs, self.threads, self.lock_fd, self.stop = jobs, threads, lock_fd, stop
        self.results = {}  # case id -> {"status", "exit_code", "seconds", "message"}
        self.running_ids = set()
        self.old_exit_codes = read_exit_codes(self.dir / CSV_FILE)

    def case_dir(self, case):
        return self.dir / CASES_DIR / case["id"]

    def command(self, job):
        d = str(self.case_dir(job.case))
        if job.mode == "resume":
            return [self.crater, "run", "--resume", d, "--quiet", "--threads", str(self.threads)]
        cmd = [self.crater, "run", self.plan["scenario"], "--out", d, "--quiet",
               "--threads", str(self.threads), "--force", *level_args(self.plan)]
        for s in case_sets(self.plan, job.case):
            cmd += ["--set", s]
        return cmd

    def launch(self, job):
        (self.dir / STDERR_DIR).mkdir(exist_ok=True)
        (self.dir / CASES_DIR).mkdir(exist_ok=True)
        if job.err is not None:
            job.err.close()
        job.err = open(self.dir / STDERR_DIR / f"{job.case['id']}.stderr", "w+b")
        job.proc = subprocess.Popen(self.command(job), stdin=subprocess.DEVNULL,
                                    stdout=subprocess.DEVNULL, stderr=job.err,
                                    pass_fds=(self.lock_fd,), preexec_fn=child_setup)
        if job.start is None:
            job.start = time.monotonic()
        self.running_ids.add(job.case["id"])

    def read_stderr(self, job):
        job.err.seek(0)
        text = job.err.read().decode("utf-8", "replace")
        job.err.close()
        job.err = None
        try:
            os.unlink(self.dir / STDERR_DIR / f"{job.case['id']}.stderr")
        except OSError:
            pass
        return text

    def log(self, job, cmd, code, text):
        cid = job.case["id"]
        lines = [f"{cid}: $ {' '.join(cmd)}"]
        lines += [f"{cid}: {ln}" for ln in text.splitlines()]
        lines.append(f"{cid}: exit {code}")
        with open(self.dir / LOG_FILE, "a") as f:
            f.write("\n".join(lines) + "\n")

    def run(self, todo):
        """Runs the jobs todo, self.jobs at a time; returns when all are done or, after
        SIGINT/SIGTERM, when the running ones have stopped."""
        pending, running = list(todo), []
        forwarded = killed = False
        total = len(self.plan["cases"])
        while running or (pending and not self.stop.count):
            if self.stop.count and not forwarded:
                forwarded = True
                if running:
                    say(f"interrupted: waiting for {len(running)} running case(s) to write a "
                        "checkpoint (interrupt twice more to kill them)")
                for job in running:
                    send(job.proc, signal.SIGINT)
            if self.stop.count >= 3 and not killed:
                killed = True
                for job in running:
                    send(job.proc, signal.SIGKILL)
            while pending and len(running) < self.jobs and not self.stop.count:
                job = pending.pop(0)
                self.launch(job)
                running.append(job)
            done = [job for job in running if job.proc.poll() is not None]
            for job in done:
                running.remove(job)
                code = exit_code(job.proc.returncode)
                cmd = self.command(job)
                text = self.read_stderr(job)
                self.log(job, cmd, code, text)
                if (job.mode == "resume" and code == CRATER_EXIT_INPUT and not self.stop.count):
                    job.notes.append(f"--resume refused ({last_message(text)}); ran afresh")
                    job.mode = "fresh"
                    self.launch(job)
                    running.append(job)
                    continue
                self.finish(job, code, text, total)
            if not done:
                time.sleep(POLL_S)

    def finish(self, job, code, text, total):
        cid = job.case["id"]
        self.running_ids.discard(cid)
        seconds = time.monotonic() - job.start
        if code == 0 and is_completed(self.case_dir(job.case)):
            status = "completed"
        elif code == CRATER_EXIT_INTERRUPTED:
            status = "interrupted"
        else:
            status = "failed"
        message = "" if status in ("completed", "interrupted") else last_message(text)
        if job.proc.returncode < 0:
            try:
                name = signal.Signals(-job.proc.returncode).name
            except ValueError:
                name = f"signal {-job.proc.returncode}"
            message = f"crater was killed by {name}" + (f"; {message}" if message else "")
        if code == 0 and status == "failed":
            message = "exit 0 but summary.json does not say completed"
        self.results[cid] = {"status": status, "exit_code": code, "seconds": seconds,
                             "message": message}
        line = (f"case {job.index + 1}/{total} ({values_text(self.plan, job.case)}) "
                f"{status}")
        if status != "completed":
            line += f" (exit code {code})"
        line += f" in {format_seconds(seconds)}"
        if job.mode == "resume":
            line += ", resumed from its checkpoint"
        if job.notes:
            line += "; " + "; ".join(job.notes)
        if message:
            line += f": {message}"
        print(line, file=sys.stderr, flush=True)
        self.write_csv()

    def write_csv(self):
        rows, columns = collect_rows(self.plan, self.dir, self.results, self.old_exit_codes,
                                     self.running_ids)
        write_atomic(self.dir / CSV_FILE, csv_text(rows, columns))
        return rows, columns


def send(proc, sig):
    try:
        proc.send_signal(sig)
    except (ProcessLookupError, OSError):
        pass


def exit_code(returncode):
    """A process's exit code as a shell shows it: 128 + signal when a signal ended it."""
    return 128 - returncode if returncode < 0 else returncode


def format_seconds(s):
    return f"{s:.1f} s" if s < 10 else f"{s:.0f} s"


# ---------------------------------------------------------------------------------------------
# sweep.csv
# ---------------------------------------------------------------------------------------------

def flatten(obj, prefix=""):
    """The scalars of a JSON object, nested objects' keys joined with '.'; lists left out."""
    out = {}
    for k, v in obj.items():
        name = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(flatten(v, name + "."))
        elif v is None or isinstance(v, (bool, int, float, str)):
            out[name] = v
    return out


def read_exit_codes(path):
    """{case: exit code} of an earlier sweep.csv, for cases not run in this session."""
    codes = {}
    try:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                if row.get("case") and row.get("exit_code", "") != "":
                    try:
                        codes[row["case"]] = int(row["exit_code"])
                    except ValueError:
                        pass
    except (OSError, UnicodeDecodeError, csv.Error):
        pass
    return codes


def collect_rows(plan, sweep_dir, results, old_exit_codes, running_ids=()):
    """One dict per case (Python values), and the columns in order."""
    keys = plan_keys(plan)
    rows, metric_names = [], set()
    for case in plan["cases"]:
        cid = case["id"]
        summary = read_summary(Path(sweep_dir) / CASES_DIR / cid) or {}
        row = {"case": cid, **{k: case["values"][k] for k in keys}}
        res = results.get(cid)
        sstatus = summary.get("status")
        if cid in running_ids:
            status, code = "running", None
        elif res:
            status, code = res["status"], res["exit_code"]
        elif sstatus == "completed":
            status, code = "completed", 0
        elif sstatus == "failed":
            status, code = "failed", old_exit_codes.get(cid)
        elif sstatus in ("running", "interrupted"):
            status, code = "interrupted", old_exit_codes.get(cid)
        else:
            status, code = "not run", None
        row["status"], row["exit_code"] = status, code
        run = summary.get("run") if isinstance(summary.get("run"), dict) else {}
        row["wall_s"] = run.get("wall_time_s") if cid not in running_ids else None
        if cid not in running_ids:
            metrics = summary.get("metrics")
            if isinstance(metrics, dict):
                for name, v in flatten(metrics).items():
                    if name not in row:
                        row[name] = v
                        metric_names.add(name)
            # Each part's mass and diagnostics as parts.<part>.<name>
            # (parts.plate.eroded_mass_kg, ...): charted only when --metrics names them.
            for part in summary.get("parts") or []:
                if not isinstance(part, dict) or not isinstance(part.get("name"), str):
                    continue
                values = {"mass_kg": part.get("mass_kg")}
                if isinstance(part.get("diagnostics"), dict):
                    values.update(part["diagnostics"])
                for name, v in flatten(values, "parts." + part["name"] + ".").items():
                    if name not in row and isinstance(v, (int, float)) and not isinstance(v, bool):
                        row[name] = v
                        metric_names.add(name)
            energy = summary.get("energy")
            if isinstance(energy, dict) and "balance_error" in energy:
                row[ENERGY_COLUMN] = energy["balance_error"]
                metric_names.add(ENERGY_COLUMN)
        rows.append(row)
    fixed = [*FIXED_COLUMNS, *keys, *STATUS_COLUMNS]
    columns = fixed + sorted(metric_names - set(fixed))
    return rows, columns


def csv_cell(v):
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else str(v)
    return str(v)


def csv_text(rows, columns):
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for row in rows:
        w.writerow([csv_cell(row.get(c)) for c in columns])
    return buf.getvalue()


def numeric(v):
    """A metric's value as a finite float, or None."""
    if isinstance(v, bool):
        return float(v)
    if isinstance(v, (int, float)):
        return float(v) if math.isfinite(v) else None
    return None


def metric_columns(columns, plan):
    skip = {*FIXED_COLUMNS, *plan_keys(plan), *STATUS_COLUMNS}
    return [c for c in columns if c not in skip]


def choose_metrics(rows, columns, plan, wanted):
    """The metrics to chart: wanted (names of sweep.csv columns), else every metric numeric in
    the completed cases that takes more than one value there, the summary's metrics before
    energy.balance_error (the parts.* columns only when named), at most MAX_DEFAULT_METRICS."""
    done = [r for r in rows if r["status"] == "completed"]
    if wanted:
        chosen = []
        for m in wanted:
            if m not in columns:
                warn(f"--metrics: no column {m} in {CSV_FILE}; not charted")
            elif not any(numeric(r.get(m)) is not None for r in done):
                warn(f"--metrics: {m} has no numeric value in a completed case; not charted")
            else:
                chosen.append(m)
        return chosen
    names = [n for n in metric_columns(columns, plan) if not n.startswith(PARTS_PREFIX)]
    names = [n for n in names if n != ENERGY_COLUMN] + [n for n in names if n == ENERGY_COLUMN]
    chosen = []
    for m in names:
        vals = {numeric(r.get(m)) for r in done} - {None}
        if len(vals) > 1:
            chosen.append(m)
    if len(chosen) > MAX_DEFAULT_METRICS:
        warn(f"{len(chosen)} metrics vary; charting the first {MAX_DEFAULT_METRICS} "
             "(choose with --metrics)")
    return chosen[:MAX_DEFAULT_METRICS]


# ---------------------------------------------------------------------------------------------
# Charts
# ---------------------------------------------------------------------------------------------

def import_numpy():
    try:
        import numpy
    except ImportError as e:
        raise ToolError(f"{sys.executable} lacks a module ({e}); install the Debian packages "
                        f"{DEBIAN_PACKAGES}") from None
    return numpy


def import_plotting():
    np = import_numpy()
    try:
        os.environ.setdefault("MPLBACKEND", "Agg")
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.transforms import blended_transform_factory
    except ImportError as e:
        raise ToolError(f"{sys.executable} lacks a module ({e}); install the Debian packages "
                        f"{DEBIAN_PACKAGES}") from None
    warnings.filterwarnings("ignore", category=RuntimeWarning)
    warnings.filterwarnings("ignore", category=UserWarning)
    return np, plt, blended_transform_factory


def chart_filename(metric, taken):
    base = re.sub(r"[^A-Za-z0-9._-]+", "_", metric).strip("._") or "metric"
    name, k = f"{base}.png", 2
    while name in taken:
        name, k = f"{base}_{k}.png", k + 1
    taken.add(name)
    return name


class Axis:
    """A varied key's values as chart coordinates: numbers as such, anything else (true/false,
    words) by its position among the key's values, with the values as tick labels."""

    def __init__(self, np, key, raw):
        self.key = key
        nums = [parse_number(v) for v in raw]
        if all(x is not None and math.isfinite(x) for x in nums):
            self.pos = np.array(nums, dtype=float)
            self.labels = None
            pos = self.pos
            self.log = bool(len(pos) and pos.min() > 0 and pos.max() / pos.min() >= 100)
        else:
            cats = list(dict.fromkeys(raw))
            self.pos = np.array([cats.index(v) for v in raw], dtype=float)
            self.labels = cats
            self.log = False
        self.distinct = len(set(raw))

    def style(self, ax, which):
        (ax.set_xlabel if which == "x" else ax.set_ylabel)(self.key)
        if self.log:
            (ax.set_xscale if which == "x" else ax.set_yscale)("log")
        if self.labels is not None:
            ticks = list(range(len(self.labels)))
            if which == "x":
                ax.set_xticks(ticks)
                ax.set_xticklabels(self.labels)
            else:
                ax.set_yticks(ticks)
                ax.set_yticklabels(self.labels)


def draw_charts(plan, rows, sweep_dir, wanted):
    """Draws DIR/charts/<metric>.png; returns [(metric, Path)]."""
    charts_dir = Path(sweep_dir) / CHARTS_DIR
    columns = []
    for r in rows:
        columns += [c for c in r if c not in columns]
    metrics = choose_metrics(rows, columns, plan, wanted)
    if charts_dir.is_dir():
        for old in charts_dir.glob("*.png"):
            old.unlink()
    keys = plan_keys(plan)
    if not any(len({r[k] for r in rows}) > 1 for k in keys):
        say("every case has the same values; no charts")
        return []
    if not metrics:
        say("no metric varies over the completed cases; no charts")
        return []
    np, plt, blended = import_plotting()
    charts_dir.mkdir(exist_ok=True)
    axes = [Axis(np, k, [r[k] for r in rows]) for k in keys]
    varied = [a for a in axes if a.distinct > 1]
    status = np.array([r["status"] for r in rows])
    taken, out = set(), []
    for m in metrics:
        z = np.array([numeric(r.get(m)) if r["status"] == "completed" else None for r in rows],
                     dtype=float)  # None -> nan
        path = charts_dir / chart_filename(m, taken)
        if len(varied) == 1:
            fig = line_chart(np, plt, blended, varied[0], z, status, m)
        elif len(varied) == 2:
            fig = contour_chart(np, plt, varied[0], varied[1], z, status, m,
                                grid=plan.get("samples") is None)
        else:
            fig = scatter_chart(np, plt, blended, varied, z, status, m)
        fig.savefig(path, dpi=DPI)
        plt.close(fig)
        out.append((m, path))
    return out


def mark_unfinished_1d(ax, blended, x, status):
    """Failed cases as red x, the others not completed as grey +, at the foot of the axes."""
    tr = blended(ax.transData, ax.transAxes)
    for st, style, label in (("failed", "rx", "failed"), (None, "+", "not completed")):
        sel = (status == "failed") if st else ((status != "failed") & (status != "completed"))
        if sel.any():
            kw = {"color": "0.5"} if st is None else {}
            ax.plot(x[sel], [0.03] * int(sel.sum()), style, transform=tr, markersize=9,
                    markeredgewidth=2, label=label, clip_on=False, **kw)
            ax.legend(loc="best", fontsize=8)


def line_chart(np, plt, blended, axis, z, status, metric):
    fig, ax = plt.subplots(figsize=(7, 5))
    order = np.argsort(axis.pos, kind="stable")
    x, y = axis.pos[order], z[order]
    ax.plot(x, y, "o-", color="#2f5f9e")  # nan (not completed) breaks the line
    right = right_half(np, axis)
    for xi, yi, r in zip(x, y, right[order]):
        if np.isfinite(yi):
            ax.annotate(f"{yi:.3g}", (xi, yi), xytext=(-4 if r else 4, 4),
                        textcoords="offset points", ha="right" if r else "left", fontsize=8)
    axis.style(ax, "x")
    ax.set_ylabel(metric)
    ax.set_title(metric)
    ax.grid(True, alpha=0.3)
    mark_unfinished_1d(ax, blended, x, status[order])
    fig.tight_layout()
    return fig


def contour_chart(np, plt, ax_x, ax_y, z, status, metric, grid):
    fig, ax = plt.subplots(figsize=(7, 5.5))
    ok = np.isfinite(z)
    zs = z[ok]
    filled = None
    if len(zs) and zs.max() > zs.min():
        levels = np.linspace(zs.min(), zs.max(), 12)
        try:
            if grid:
                xs, ys = np.unique(ax_x.pos), np.unique(ax_y.pos)
                zz = np.full((len(ys), len(xs)), np.nan)
                for xi, yi, zi in zip(ax_x.pos, ax_y.pos, z):
                    zz[np.searchsorted(ys, yi), np.searchsorted(xs, xi)] = zi
                if np.isfinite(zz).sum() >= 4:
                    # a cell with a corner not completed stays blank: no interpolation through
                    filled = ax.contourf(xs, ys, np.ma.masked_invalid(zz), levels=levels,
                                         cmap="viridis")
            elif ok.sum() >= 3:
                filled = ax.tricontourf(ax_x.pos[ok], ax_y.pos[ok], zs, levels=levels,
                                        cmap="viridis")
        except (ValueError, RuntimeError):
            filled = None  # e.g. the points on a line: no triangles
    if filled is not None:
        fig.colorbar(filled, ax=ax, label=metric)
        ax.scatter(ax_x.pos[ok], ax_y.pos[ok], c="k", s=14, zorder=3)
    elif ok.any():
        sc = ax.scatter(ax_x.pos[ok], ax_y.pos[ok], c=zs, cmap="viridis", s=60, zorder=3,
                        edgecolors="k")
        fig.colorbar(sc, ax=ax, label=metric)
    right = right_half(np, ax_x)[ok]
    for xi, yi, zi, r in zip(ax_x.pos[ok], ax_y.pos[ok], zs, right):
        ax.annotate(f"{zi:.3g}", (xi, yi), xytext=(-4 if r else 4, 4),
                    textcoords="offset points", ha="right" if r else "left", fontsize=8,
                    zorder=4,
                    bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                          "alpha": 0.7})
    failed = status == "failed"
    other = ~ok & ~failed
    if failed.any():
        ax.plot(ax_x.pos[failed], ax_y.pos[failed], "rx", markersize=10, markeredgewidth=2,
                label="failed", zorder=4)
    if other.any():
        ax.plot(ax_x.pos[other], ax_y.pos[other], "+", color="0.4", markersize=10,
                markeredgewidth=2, label="not completed", zorder=4)
    if failed.any() or other.any():
        ax.legend(loc="best", fontsize=8)
    ax_x.style(ax, "x")
    ax_y.style(ax, "y")
    pad_axes(np, ax, ax_x, ax_y)
    ax.set_title(metric)
    fig.tight_layout()
    return fig


def right_half(np, axis):
    """Which points lie in the right half of the axis (their labels go to their left)."""
    pos = np.log(axis.pos) if axis.log else axis.pos
    return pos > 0.5 * (pos.min() + pos.max()) if len(pos) else pos.astype(bool)


def pad_axes(np, ax, ax_x, ax_y):
    """Room around the outermost points, for their markers and labels."""
    for a, setter in ((ax_x, ax.set_xlim), (ax_y, ax.set_ylim)):
        lo, hi = float(np.min(a.pos)), float(np.max(a.pos))
        if a.log:
            f = (hi / lo) ** 0.06
            setter(lo / f, hi * f)
        else:
            d = 0.06 * (hi - lo) if hi > lo else 0.5
            setter(lo - d, hi + d)


def scatter_chart(np, plt, blended, varied, z, status, metric):
    n = len(varied)
    ncols = min(3, n)
    nrows = (n + ncols - 1) // ncols
    fig, axs = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 3.6 * nrows), squeeze=False)
    ok = np.isfinite(z)
    for i, a in enumerate(varied):
        ax = axs[i // ncols][i % ncols]
        ax.plot(a.pos[ok], z[ok], "o", color="#2f5f9e")
        a.style(ax, "x")
        ax.set_ylabel(metric)
        ax.grid(True, alpha=0.3)
        mark_unfinished_1d(ax, blended, a.pos, status)
    for j in range(n, nrows * ncols):
        axs[j // ncols][j % ncols].set_visible(False)
    fig.suptitle(metric)
    fig.tight_layout()
    return fig


# ---------------------------------------------------------------------------------------------
# report.md
# ---------------------------------------------------------------------------------------------

def md_cell(v):
    if v is None or v == "":
        return ""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v).replace("|", "\\|")


def write_report(plan, rows, charts, sweep_dir, out_dir):
    out_dir.mkdir(parents=True, exist_ok=True)
    sweep_dir = Path(sweep_dir)
    keys = plan_keys(plan)

    def link(path):
        return os.path.relpath(Path(path).resolve(), out_dir.resolve())

    counts = {}
    for r in rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    lines = [f"# Sweep of `{plan['scenario']}`", ""]
    lines.append(f"- Scenario: `{plan['scenario']}`"
                 + (f", level `{plan['level']}`" if plan.get("level") else ""))
    if plan["sets"]:
        lines.append("- Set in every case: " + ", ".join(f"`{s}`" for s in plan["sets"]))
    if plan.get("samples"):
        lines.append(f"- Latin hypercube: {plan['samples']} samples, seed {plan['seed']}, over "
                     + ", ".join(f"`{v['key']}` in [{v['range'][0]}, {v['range'][1]}]"
                                 for v in plan["vary"]))
    else:
        lines.append("- Grid over " + " x ".join(
            f"`{v['key']}` = {', '.join(v['values'])}" for v in plan["vary"]))
    lines.append(f"- Cases: {len(rows)}: " + ", ".join(f"{n} {s}" for s, n in sorted(
        counts.items())))
    if plan.get("crater_version"):
        lines.append(f"- Binary: {plan['crater_version']}")
    lines.append(f"- Data: [{CSV_FILE}]({link(sweep_dir / CSV_FILE)}) (every metric), "
                 f"[{PLAN_FILE}]({link(sweep_dir / PLAN_FILE)}), the runs in "
                 f"[{CASES_DIR}/]({link(sweep_dir / CASES_DIR)})")
    lines.append("")
    lines.append("## Cases")
    lines.append("")
    metrics = [m for m, _ in charts]
    head = ["case", *keys, "status", *metrics]
    lines.append("| " + " | ".join(f"`{h}`" if h in keys or h in metrics else h
                                   for h in head) + " |")
    lines.append("| " + " | ".join("---" for _ in head) + " |")
    for r in rows:
        cells = [r["case"], *(r[k] for k in keys), r["status"]]
        cells += [r.get(m) if r["status"] == "completed" else None for m in metrics]
        lines.append("| " + " | ".join(md_cell(c) for c in cells) + " |")
    lines.append("")
    lines.append("## Charts")
    lines.append("")
    if not charts:
        lines.append("No chart: no metric varies over the completed cases, or the cases do "
                     "not differ.")
        lines.append("")
    for m, path in charts:
        lines.append(f"### `{m}`")
        lines.append("")
        lines.append(f"![{m}]({link(path)})")
        lines.append("")
    path = out_dir / REPORT_FILE
    write_atomic(path, "\n".join(lines))
    return path


# ---------------------------------------------------------------------------------------------
# The commands
# ---------------------------------------------------------------------------------------------

def parse_metrics(text):
    if text is None:
        return None
    names = [m.strip() for m in text.split(",") if m.strip()]
    if not names:
        raise InputError("--metrics: no metric named")
    return names


def report_main(args):
    extra = [o for o, v in (("SCENARIO", args.scenario), ("--vary", args.vary),
                            ("--set", args.sets), ("--level", args.level),
                            ("--samples", args.samples), ("--seed", args.seed),
                            ("--jobs", args.jobs), ("--threads-per-job", args.threads_per_job),
                            ("--resume", args.resume)) if v]
    if extra:
        raise InputError(f"--report DIR takes only --out and --metrics, not {', '.join(extra)}")
    sweep_dir = Path(args.report)
    if not sweep_dir.is_dir():
        raise InputError(f"{sweep_dir}: no such directory")
    plan = load_plan(sweep_dir)
    wanted = parse_metrics(args.metrics) or plan.get("metrics")
    out_dir = Path(args.out) if args.out else sweep_dir / "report"
    rows, _ = collect_rows(plan, sweep_dir, {}, read_exit_codes(sweep_dir / CSV_FILE))
    charts = draw_charts(plan, rows, sweep_dir, wanted)
    path = write_report(plan, rows, charts, sweep_dir, out_dir)
    print(f"crater sweep: {path} and {len(charts)} chart(s) in {sweep_dir / CHARTS_DIR}")
    return EXIT_OK


def sweep_main(args, crater):
    if args.resume:
        extra = [o for o, v in (("SCENARIO", args.scenario), ("--vary", args.vary),
                                ("--set", args.sets), ("--level", args.level),
                                ("--samples", args.samples), ("--seed", args.seed),
                                ("--out", args.out), ("--metrics", args.metrics)) if v]
        if extra:
            raise InputError("--resume DIR takes only --jobs and --threads-per-job (the rest is "
                             f"DIR/{PLAN_FILE}), not {', '.join(extra)}")
        sweep_dir = Path(args.resume)
        old = load_plan(sweep_dir)
        plan = {f: old.get(f) for f in PLAN_IDENTITY}
        if plan["scenario_sha256"] is not None:
            p = Path(plan["scenario"])
            if not p.is_file():
                raise InputError(f"{p}: the sweep's scenario file is gone")
            plan["scenario_sha256"] = hashlib.sha256(p.read_bytes()).hexdigest()
            if plan["scenario_sha256"] != old.get("scenario_sha256"):
                raise InputError(f"{p}: the scenario file changed since the sweep started; "
                                 "start a new sweep (another --out)")
        wanted = old.get("metrics")
        jobs = args.jobs if args.jobs is not None else int(old.get("jobs") or 1)
        threads = (args.threads_per_job if args.threads_per_job is not None
                   else int(old.get("threads_per_job") or 1))
    else:
        plan = build_plan(args)
        sweep_dir = Path(args.out or DEFAULT_OUT)
        old = None
        wanted = parse_metrics(args.metrics)
        jobs = 1 if args.jobs is None else args.jobs
        threads = 1 if args.threads_per_job is None else args.threads_per_job
    if jobs < 1:
        raise InputError(f"--jobs {jobs}: at least 1")
    if threads < 1:
        raise InputError(f"--threads-per-job {threads}: at least 1")

    if old is None and sweep_dir.exists():
        if not sweep_dir.is_dir():
            raise InputError(f"--out {sweep_dir}: exists and is not a directory")
        if (sweep_dir / PLAN_FILE).is_file():
            old = load_plan(sweep_dir)
            diff = plan_difference(old, plan)
            if diff:
                raise InputError(f"--out {sweep_dir} holds another sweep ({diff}); use another "
                                 f"--out, or delete {sweep_dir} to start this one there")
        elif any(sweep_dir.iterdir()):
            raise InputError(f"--out {sweep_dir}: not empty and not a sweep directory "
                             f"(no {PLAN_FILE}); use another --out")

    version = crater_version(crater)
    cases = plan["cases"]
    n = len(cases)
    todo = [(i, c) for i, c in enumerate(cases)
            if not is_completed(sweep_dir / CASES_DIR / c["id"])]
    cpus = os.cpu_count() or 1
    if jobs * threads > cpus:
        warn(f"--jobs {jobs} x --threads-per-job {threads} = {jobs * threads} threads on "
             f"{cpus} core(s): the runs will slow each other down")

    stop = Stop()
    stop.install()
    try:
        if todo:
            say(f"checking {len(todo)} case(s) with crater check")
            failed = check_cases(crater, plan, [c for _, c in todo], jobs, stop)
            if failed is None:
                say("interrupted while checking; nothing was run")
                return EXIT_INTERRUPTED
            if failed:
                for case, code, text in failed[:MAX_LISTED_REJECTED]:
                    idx = cases.index(case)
                    msg = "\n  ".join(ln for ln in text.strip().splitlines()) or f"exit {code}"
                    say(f"case {idx + 1}/{n} ({values_text(plan, case)}) is rejected by crater "
                        f"check (exit {code}):\n  {msg}")
                if len(failed) > MAX_LISTED_REJECTED:
                    say(f"... and {len(failed) - MAX_LISTED_REJECTED} more case(s)")
                say(f"{len(failed)} of {n} case(s) rejected; nothing was run")
                return EXIT_INPUT

        sweep_dir.mkdir(parents=True, exist_ok=True)
        lock_fd = acquire_lock(sweep_dir, stop)
        if lock_fd is None:
            say("interrupted while waiting; nothing was run")
            return EXIT_INTERRUPTED
        # Under the lock: another sweep may have written DIR in the meantime.
        if (sweep_dir / PLAN_FILE).is_file():
            old = load_plan(sweep_dir)
            diff = plan_difference(old, plan)
            if diff:
                raise InputError(f"--out {sweep_dir} holds another sweep ({diff})")
        record = dict(old) if old else {}
        record.update(plan)
        if not old:
            record["created"] = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
            record["crater_version"] = version
        elif old.get("crater_version") != version:
            warn(f"the sweep was started with {old.get('crater_version')}, this is {version}")
        record["crater_binary"] = crater
        record["jobs"], record["threads_per_job"] = jobs, threads
        record["metrics"] = wanted
        save_plan(sweep_dir, record)

        sweep = Sweep(crater, plan, sweep_dir, jobs, threads, lock_fd, stop)
        jobs_todo = []
        for i, c in todo:
            d = sweep.case_dir(c)
            if is_completed(d):
                continue
            jobs_todo.append(Job(i, c, "resume" if has_checkpoint(d) else "fresh"))
        n_resume = sum(j.mode == "resume" for j in jobs_todo)
        say(f"{n} case(s) in {sweep_dir}: {n - len(jobs_todo)} completed before, "
            f"{n_resume} to resume, {len(jobs_todo) - n_resume} to run "
            f"({jobs} at a time, {threads} thread(s) each)")
        sweep.write_csv()
        sweep.run(jobs_todo)
        rows, _ = sweep.write_csv()
        try:
            (sweep_dir / STDERR_DIR).rmdir()
        except OSError:
            pass
    finally:
        stop.restore()

    not_done = [(i, c) for i, c in enumerate(cases) if rows[i]["status"] != "completed"]
    if stop.count:
        say(f"interrupted: {len(not_done)} of {n} case(s) not completed; continue with: "
            f"crater sweep --resume {sweep_dir}")
        return EXIT_INTERRUPTED
    try:
        charts = draw_charts(plan, rows, sweep_dir, wanted)
    except ToolError as e:
        warn(f"no charts: {e}")
        charts = []
    print(f"crater sweep: {n - len(not_done)} of {n} case(s) completed; {sweep_dir / CSV_FILE}"
          + (f", {len(charts)} chart(s) in {sweep_dir / CHARTS_DIR}" if charts else ""))
    if not_done:
        say(f"{len(not_done)} case(s) not completed:")
        for i, c in not_done:
            r = rows[i]
            res = sweep.results.get(c["id"], {})
            msg = res.get("message") or ""
            code = r.get("exit_code")
            print(f"  case {i + 1}/{n} ({values_text(plan, c)}): {r['status']}"
                  + (f", exit code {code}" if code is not None else "")
                  + (f": {msg}" if msg else ""), file=sys.stderr)
        say(f"their output is in {sweep_dir / LOG_FILE}; rerun the command (or crater sweep "
            f"--resume {sweep_dir}) to run them again")
        return EXIT_FAILED
    return EXIT_OK


def main(argv):
    global PRCTL
    args = parse_args(argv)
    if args.report:
        return report_main(args)
    crater = args.crater or os.environ.get("CRATER_BIN") or "crater"
    if os.sep in crater:
        crater = str(Path(crater).resolve())
    PRCTL = load_prctl()
    return sweep_main(args, crater)


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        print(f"crater sweep: error: {e}", file=sys.stderr)
        sys.exit(EXIT_INPUT)
    except ToolError as e:
        print(f"crater sweep: error: {e}", file=sys.stderr)
        sys.exit(EXIT_FAILED)
    except KeyboardInterrupt:
        print("crater sweep: interrupted", file=sys.stderr)
        sys.exit(EXIT_INTERRUPTED)
    except OSError as e:
        print(f"crater sweep: error: {e}", file=sys.stderr)
        sys.exit(EXIT_FAILED)
    except Exception as e:  # a bug here, not bad input: one line, the traceback on request
        if os.environ.get("CRATER_SWEEP_DEBUG"):
            raise
        print(f"crater sweep: internal error: {type(e).__name__}: {e} "
              "(CRATER_SWEEP_DEBUG=1 shows the traceback)", file=sys.stderr)
        sys.exit(EXIT_FAILED)
