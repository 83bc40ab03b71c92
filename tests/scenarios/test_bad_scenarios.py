#!/usr/bin/python3
"""Malformed scenarios are rejected before any simulation work, with a message naming the file,
the line and the key.

Every tests/scenarios/bad/*.toml holds exactly one problem and says, in its first comment
lines, what `crater check` must report:

    # expect-line: N            line the message names (FILE:N)
    # expect-key: dotted.key    the message says  key 'dotted.key'  (absent: TOML syntax errors)
    # expect-text: words        a fragment of the message (optional)

For each file: `crater check FILE` exits 2 and one "error:" line of stderr names FILE:N, the key
and the fragment; nothing crashed; `crater run FILE --out DIR` also exits 2 and writes no
summary.json (nothing was simulated). Further tests: --set overrides on scenarios/demo.toml and
the demo itself.

Environment (set by CMake): CRATER_BIN, CRATER_SOURCE_DIR, CRATER_TEST_TMP.
"""
import os
import re
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent
SOURCE_DIR = Path(os.environ.get("CRATER_SOURCE_DIR", HERE.parent.parent))
CRATER_BIN = os.environ.get("CRATER_BIN", str(SOURCE_DIR / "build/release/bin/crater"))
TMP_ROOT = Path(os.environ.get("CRATER_TEST_TMP", tempfile.gettempdir())) / "bad_scenarios"
BAD_DIR = HERE / "bad"
DEMO = SOURCE_DIR / "scenarios" / "demo.toml"
TIMEOUT_S = 120
EXIT_INPUT = 2

# Text that means the program (or this test) crashed instead of reporting an input error.
CRASH_MARKERS = (
    "Traceback (most recent call last)",
    "terminate called",
    "AddressSanitizer",
    "LeakSanitizer",
    "UndefinedBehaviorSanitizer",
    "ThreadSanitizer",
    "runtime error:",
    "Segmentation fault",
    "core dumped",
    "Assertion",
)

HEADER_RE = re.compile(r"^#\s*expect-(line|key|text):\s*(.*?)\s*$")


def read_expectations(path):
    """The expect-* lines of the leading comment block."""
    exp = {}
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.rstrip("\n")
            if not line.startswith("#"):
                break
            m = HEADER_RE.match(line)
            if m:
                exp[m.group(1)] = m.group(2)
    if "line" not in exp or not exp["line"].isdigit():
        raise ValueError(f"{path.name}: no '# expect-line: N' in its first comment lines")
    exp["line"] = int(exp["line"])
    return exp


def crater(*args):
    return subprocess.run([CRATER_BIN, *map(str, args)], capture_output=True, text=True,
                          errors="replace", timeout=TIMEOUT_S)


def bad_files():
    return sorted(BAD_DIR.glob("*.toml"))


class Helpers:
    def assert_no_crash(self, proc, what):
        for marker in CRASH_MARKERS:
            self.assertNotIn(marker, proc.stdout + proc.stderr,
                             f"{what}: crash marker {marker!r} in the output:\n{proc.stderr}")

    def assert_exit(self, proc, code, what):
        self.assertEqual(proc.returncode, code,
                         f"{what}: exit {proc.returncode}, expected {code}\n"
                         f"stdout:\n{proc.stdout}\nstderr:\n{proc.stderr}")

    def assert_reported(self, stderr, name, line=None, key=None, text=None, what=""):
        """One 'error:' line of stderr holds all of: name:line, key 'key', text."""
        loc = None
        if line is not None:
            # "bad.toml:12" followed by ':' (column), or end, never by another digit.
            loc = re.compile(re.escape(name) + ":" + str(line) + r"(?![0-9])")
        elif name is not None:
            loc = re.compile(re.escape(name))
        key_text = None if key is None else f"key '{key}'"
        for msg in stderr.splitlines():
            if not msg.startswith("error:"):
                continue
            if loc is not None and not loc.search(msg):
                continue
            if key_text is not None and key_text not in msg:
                continue
            if text is not None and text not in msg:
                continue
            return msg
        wanted = []
        if line is not None:
            wanted.append(f"{name}:{line}")
        if key_text:
            wanted.append(key_text)
        if text:
            wanted.append(repr(text))
        self.fail(f"{what}: no 'error:' line holds all of {', '.join(wanted)}; stderr was:\n"
                  f"{stderr}")


class BadScenarios(unittest.TestCase, Helpers):
    """One test method per file in bad/ (added below), so a failure names the file."""

    @classmethod
    def setUpClass(cls):
        TMP_ROOT.mkdir(parents=True, exist_ok=True)

    def test_collection_is_complete(self):
        files = bad_files()
        self.assertGreaterEqual(len(files), 24, f"too few bad scenarios in {BAD_DIR}")
        for f in files:
            with self.subTest(file=f.name):
                exp = read_expectations(f)
                n_lines = len(f.read_text(encoding="utf-8").splitlines())
                self.assertGreaterEqual(exp["line"], 1)
                self.assertLessEqual(exp["line"], max(n_lines, 1),
                                     f"{f.name}: expect-line beyond the end of the file")

    def check_bad_file(self, path):
        exp = read_expectations(path)
        line, key, text = exp["line"], exp.get("key"), exp.get("text")

        with self.subTest(command="check"):
            proc = crater("check", path)
            self.assert_no_crash(proc, f"check {path.name}")
            self.assert_exit(proc, EXIT_INPUT, f"check {path.name}")
            self.assert_reported(proc.stderr, path.name, line, key, text, f"check {path.name}")
            self.assertNotIn("\nok\n", "\n" + proc.stdout, f"check {path.name} printed 'ok'")

        with self.subTest(command="run"):
            out = TMP_ROOT / ("run_" + path.stem)
            shutil.rmtree(out, ignore_errors=True)
            proc = crater("run", path, "--out", out, "--quiet", "--threads", "1")
            self.assert_no_crash(proc, f"run {path.name}")
            self.assert_exit(proc, EXIT_INPUT, f"run {path.name}")
            self.assert_reported(proc.stderr, path.name, line, key, text, f"run {path.name}")
            self.assertFalse((out / "summary.json").exists(),
                             f"run {path.name} wrote {out / 'summary.json'}")
            self.assertFalse((out / "history.csv").exists(),
                             f"run {path.name} wrote {out / 'history.csv'}")
            if out.is_dir():
                vtus = sorted(p.name for p in out.iterdir() if p.suffix in (".vtu", ".pvd"))
                self.assertEqual(vtus, [], f"run {path.name} wrote output files")
            shutil.rmtree(out, ignore_errors=True)


def _add_file_tests():
    for path in bad_files():
        name = "test_" + re.sub(r"\W", "_", path.stem)

        def method(self, path=path):
            self.check_bad_file(path)

        method.__name__ = name
        method.__doc__ = f"bad/{path.name}"
        setattr(BadScenarios, name, method)


_add_file_tests()


class OtherBadInput(unittest.TestCase, Helpers):
    """Bad input that a file in bad/ cannot express."""

    @classmethod
    def setUpClass(cls):
        TMP_ROOT.mkdir(parents=True, exist_ok=True)

    def test_zero_byte_file(self):
        path = TMP_ROOT / "zero_bytes.toml"
        path.write_bytes(b"")
        proc = crater("check", path)
        self.assert_no_crash(proc, "zero-byte file")
        self.assert_exit(proc, EXIT_INPUT, "zero-byte file")
        self.assert_reported(proc.stderr, path.name, None, "scenario", "missing required key",
                             "zero-byte file")

    def test_nul_byte_file(self):
        path = TMP_ROOT / "nul_byte.toml"
        path.write_bytes(DEMO.read_bytes().replace(b'name = "demo"', b'name = "de\0mo"', 1))
        proc = crater("check", path)
        self.assert_no_crash(proc, "file with a NUL byte")
        self.assert_exit(proc, EXIT_INPUT, "file with a NUL byte")
        self.assert_reported(proc.stderr, path.name, what="file with a NUL byte")

    def test_missing_file(self):
        path = TMP_ROOT / "does_not_exist.toml"
        proc = crater("check", path)
        self.assert_no_crash(proc, "missing file")
        self.assert_exit(proc, EXIT_INPUT, "missing file")
        self.assert_reported(proc.stderr, path.name, text="no such file", what="missing file")

    def test_directory_as_scenario(self):
        proc = crater("check", BAD_DIR)
        self.assert_no_crash(proc, "directory")
        self.assert_exit(proc, EXIT_INPUT, "directory")


def part_counts(stdout):
    """{part name: count} from the table printed by `crater check`."""
    counts = {}
    in_table = False
    for line in stdout.splitlines():
        cols = line.split()
        if cols[:3] == ["part", "method", "count"]:
            in_table = True
            continue
        if in_table:
            if len(cols) >= 3 and cols[2].isdigit():
                counts[cols[0]] = int(cols[2])
            else:
                in_table = False
    return counts


class SetOverrides(unittest.TestCase, Helpers):
    """--set on the bundled demo."""

    def check_demo(self, *sets):
        args = ["check", DEMO]
        for s in sets:
            args += ["--set", s]
        proc = crater(*args)
        self.assert_no_crash(proc, f"check demo {' '.join(sets)}")
        return proc

    def test_demo_checks(self):
        proc = self.check_demo()
        self.assert_exit(proc, 0, "check demo")
        self.assertIn("ok", proc.stdout.split())
        self.assertEqual(proc.stderr.strip(), "", "check demo wrote to stderr")
        self.assertIn("charge", part_counts(proc.stdout))

    def test_good_override(self):
        proc = self.check_demo("time.safety_factor=0.5")
        self.assert_exit(proc, 0, "--set time.safety_factor=0.5")
        self.assertRegex(proc.stdout, r"global step: \S+ s = 0\.5 x ")

    def test_bad_type(self):
        proc = self.check_demo('time.safety_factor="fast"')
        self.assert_exit(proc, EXIT_INPUT, "--set of a string for a number")
        self.assert_reported(proc.stderr, None, None, "time.safety_factor", "expected a number",
                             "--set of a string for a number")

    def test_out_of_range(self):
        proc = self.check_demo("parts.charge.sph.h_factor=0.2")
        self.assert_exit(proc, EXIT_INPUT, "--set h_factor out of range")
        self.assert_reported(proc.stderr, None, None, "parts[0].sph.h_factor", "0.2",
                             "--set h_factor out of range")

    def test_unknown_key(self):
        proc = self.check_demo("time.safty_factor=0.5")
        self.assert_exit(proc, EXIT_INPUT, "--set of an unknown key")
        self.assert_reported(proc.stderr, None, None, "time.safty_factor", "did you mean",
                             "--set of an unknown key")

    def test_unknown_entry(self):
        proc = self.check_demo("parts.nosuchpart.spacing_m=0.004")
        self.assert_exit(proc, EXIT_INPUT, "--set of an entry that does not exist")
        self.assert_reported(proc.stderr, None, None, "parts.nosuchpart.spacing_m", "no entry",
                             "--set of an entry that does not exist")

    def test_missing_value(self):
        proc = self.check_demo("time.safety_factor")
        self.assert_exit(proc, EXIT_INPUT, "--set without '='")

    def test_entry_by_name_and_by_index(self):
        base = part_counts(self.check_demo().stdout)
        by_name = self.check_demo("parts.charge.spacing_m=0.004")
        self.assert_exit(by_name, 0, "--set parts.charge.spacing_m=0.004")
        by_index = self.check_demo("parts.0.spacing_m=0.004")
        self.assert_exit(by_index, 0, "--set parts.0.spacing_m=0.004")
        n_name = part_counts(by_name.stdout)
        n_index = part_counts(by_index.stdout)
        self.assertIn("charge", n_name)
        # Finer spacing, more particles: 0.005 m -> 0.004 m is ~(5/4)^2 = 1.56 x in 2D.
        self.assertGreater(n_name["charge"], base["charge"] * 1.3, (base, n_name))
        self.assertEqual(n_name, n_index)

    def test_run_with_bad_set_writes_nothing(self):
        out = TMP_ROOT / "run_bad_set"
        shutil.rmtree(out, ignore_errors=True)
        proc = crater("run", DEMO, "--out", out, "--quiet", "--set", "scenario.end_time_s=-1")
        self.assert_no_crash(proc, "run demo --set scenario.end_time_s=-1")
        self.assert_exit(proc, EXIT_INPUT, "run demo --set scenario.end_time_s=-1")
        self.assert_reported(proc.stderr, None, None, "scenario.end_time_s", "> 0",
                             "run demo --set scenario.end_time_s=-1")
        self.assertFalse((out / "summary.json").exists())
        shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    unittest.main(verbosity=2)
