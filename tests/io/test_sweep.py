# ctest-cost: 26
"""`crater sweep`: a scenario over a grid or a Latin hypercube of scenario values, each case an
ordinary `crater run` (tools/sweep/crater_sweep.py, embedded in the binary), and `crater report`
of a sweep directory. The scene is tests/data/fem_plate_2d.toml (an impulsively loaded plate, a
fraction of a second per run) with the plate probe on, so that summary.json has metrics.

1. A 2 x 2 grid on two jobs: every case completed, sweep.csv holds each case's values and its
   own summary.json metrics, a chart per varied metric, the plan in sweep.json.
2. kill -9 of the sweep (and its crater run) during the second case; the same command again
   finishes it from the case's checkpoint and leaves the first case alone.
3. Bad input exits 2 and runs nothing: a key crater does not know (crater check names it),
   malformed --vary, and an --out holding another sweep.
4. A Latin hypercube: one value per stratum of each range, the same seed the same cases.
5. A case that fails (time.min_dt_s: exit 3): the others still run, the sweep exits 1.
6. `crater report DIR` of a sweep: report.md and the charts.
"""
import csv
import json
import os
import re
import signal
import subprocess
import sys
import time
import unittest
from pathlib import Path

import numpy as np

from crater_test import BIN, SOURCE_DIR, crater, scratch

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
SCENE = str(SOURCE_DIR / "tests" / "data" / "fem_plate_2d.toml")
# The plate probe (summary.json metrics); its stress time inside the 0.1 ms run.
PROBES = ["--set", "probes.plate=plate", "--set", "probes.stress_time_s=5e-5"]
COARSE = ["--set", "parts.0.spacing_m=0.004"]  # about 0.1 s a run


def sweep_command(*args):
    return [BIN, "sweep", *map(str, args)]


def sweep(*args, timeout=300):
    """Runs `crater sweep`; returns the CompletedProcess (callers test the exit code)."""
    return subprocess.run(sweep_command(*args), capture_output=True, text=True, timeout=timeout)


def report(sweep_dir, *args):
    cmd = [BIN, "report", str(sweep_dir), *map(str, args)]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300)


def read_csv(path):
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        return reader.fieldnames, list(reader)


def summary(case_dir):
    return json.loads((Path(case_dir) / "summary.json").read_text())


def case_dirs(sweep_dir):
    return sorted(p for p in (Path(sweep_dir) / "cases").iterdir() if p.is_dir())


def assert_png(test, path):
    data = Path(path).read_bytes()
    test.assertEqual(data[:8], PNG_SIGNATURE, f"{path} is not a PNG")
    import matplotlib.image
    pixels = matplotlib.image.imread(str(path))
    test.assertGreater(pixels.shape[0], 200)
    test.assertGreater(pixels.shape[1], 200)
    test.assertGreater(float(np.std(pixels)), 0.0, f"{path}: one flat colour")


class Sweep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("sweep")
        cls.grid = cls.work / "grid"
        cls.grid_keys = ["parts.0.spacing_m", "time.safety_factor"]
        cls.grid_args = [SCENE, "--vary", "parts.0.spacing_m=0.004,0.005",
                         "--vary", "time.safety_factor=0.5,0.9", *PROBES,
                         "--jobs", 2, "--out", cls.grid]
        cls.grid_proc = sweep(*cls.grid_args)

    # 1 -----------------------------------------------------------------------------------
    def test_grid_on_two_jobs(self):
        p = self.grid_proc
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        expected = [("0.004", "0.5"), ("0.004", "0.9"), ("0.005", "0.5"), ("0.005", "0.9")]
        dirs = case_dirs(self.grid)
        self.assertEqual([d.name for d in dirs],
                         ["case_0001", "case_0002", "case_0003", "case_0004"])
        for d in dirs:
            self.assertEqual(summary(d)["status"], "completed", d)
        # one progress line per case
        self.assertEqual(len(re.findall(r"^case \d/4 \(parts\.0\.spacing_m=[0-9.]+, "
                                        r"time\.safety_factor=[0-9.]+\) completed in ",
                                        p.stderr, re.M)), 4, p.stderr)

        plan = json.loads((self.grid / "sweep.json").read_text())
        self.assertEqual(plan["scenario"], SCENE)
        self.assertEqual(plan["sets"], ["probes.plate=plate", "probes.stress_time_s=5e-5"])
        self.assertEqual([v["key"] for v in plan["vary"]], self.grid_keys)
        self.assertEqual([v["values"] for v in plan["vary"]], [["0.004", "0.005"],
                                                                ["0.5", "0.9"]])
        self.assertEqual([tuple(c["values"][k] for k in self.grid_keys) for c in plan["cases"]],
                         expected, "the first key varies slowest")
        self.assertEqual(plan["crater_version"], crater("--version").stdout.strip())

        # sweep.csv: the values, the status, and each case's own metrics, exactly
        header, rows = read_csv(self.grid / "sweep.csv")
        self.assertEqual(header[:6], ["case", *self.grid_keys, "status", "exit_code", "wall_s"])
        self.assertEqual(header[6:], sorted(header[6:]))
        self.assertIn("plate_peak_von_mises_pa", header)
        self.assertIn("energy.balance_error", header)
        self.assertEqual(len(rows), 4)
        for row, values, d in zip(rows, expected, dirs):
            self.assertEqual(row["case"], d.name)
            self.assertEqual((row[self.grid_keys[0]], row[self.grid_keys[1]]), values)
            self.assertEqual((row["status"], row["exit_code"]), ("completed", "0"))
            s = summary(d)
            self.assertEqual(s["run"]["command"]["set"][-2:],
                             [f"{k}={v}" for k, v in zip(self.grid_keys, values)])
            self.assertEqual(float(row["wall_s"]), s["run"]["wall_time_s"])
            self.assertEqual(float(row["energy.balance_error"]), s["energy"]["balance_error"])
            self.assertTrue(s["metrics"])
            for name, value in s["metrics"].items():
                self.assertEqual(float(row[name]), float(value), f"{d.name} {name}")
            # Each part's mass and diagnostics, as parts.<part>.<name>
            for part in s["parts"]:
                self.assertEqual(float(row[f"parts.{part['name']}.mass_kg"]), part["mass_kg"])
                for name, value in part["diagnostics"].items():
                    self.assertEqual(float(row[f"parts.{part['name']}.{name}"]), float(value))

        # a contour chart per metric that varies over the cases
        varying = sorted(m for m in header[6:] if m != "energy.balance_error"
                         and not m.startswith("parts.") and len({r[m] for r in rows}) > 1)
        if len({r["energy.balance_error"] for r in rows}) > 1:
            varying.append("energy.balance_error")
        self.assertTrue(varying)
        charts = sorted(p.name for p in (self.grid / "charts").glob("*.png"))
        self.assertEqual(charts, sorted(f"{m}.png" for m in varying[:12]))
        for name in charts:
            with self.subTest(chart=name):
                assert_png(self, self.grid / "charts" / name)
        self.assertIn("case_0001", (self.grid / "sweep.log").read_text())

    # 6 -----------------------------------------------------------------------------------
    def test_report_of_a_sweep(self):
        self.assertEqual(self.grid_proc.returncode, 0, self.grid_proc.stderr)
        for out in (None, self.work / "grid_report"):
            with self.subTest(out=out):
                p = report(self.grid, *(["--out", out] if out else []))
                self.assertEqual(p.returncode, 0, p.stderr)
                out_dir = out or self.grid / "report"
                text = (out_dir / "report.md").read_text()
                links = re.findall(r"!\[[^\]]*\]\(([^)\s]+\.png)\)", text)
                self.assertTrue(links)
                for link in links:
                    assert_png(self, out_dir / link)
                self.assertEqual(sorted(Path(link).name for link in links),
                                 sorted(p.name for p in (self.grid / "charts").glob("*.png")))
                for k in self.grid_keys:
                    self.assertIn(k, text)
                self.assertEqual(len(re.findall(r"^\| case_000\d \|.*\| completed \|", text,
                                                re.M)), 4, text)
        empty = scratch("sweep_not_a_sweep")
        self.assertEqual(report(empty).returncode, 2)

    # 2 -----------------------------------------------------------------------------------
    def test_resumes_after_kill_9(self):
        out = self.work / "killed"
        # the second case runs 10 x longer (some 2.5 s), with a checkpoint every 200 steps
        args = [SCENE, "--vary", "scenario.end_time_s=1e-4,1e-3,2e-4",
                "--set", "output.checkpoint_every_steps=200", "--out", out]
        proc = subprocess.Popen(sweep_command(*args), stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE, text=True, start_new_session=True)
        first, second = out / "cases" / "case_0001", out / "cases" / "case_0002"
        deadline = time.monotonic() + 120
        try:
            while time.monotonic() < deadline and proc.poll() is None:
                ckpt = list((second / "checkpoints").glob("*.ckpt")) \
                    if (second / "checkpoints").is_dir() else []
                if ckpt and (first / "summary.json").is_file():
                    break
                time.sleep(0.02)
            self.assertIsNone(proc.poll(), "the sweep ended before it could be killed")
            self.assertEqual(summary(first)["status"], "completed")
            self.assertNotEqual(summary(second)["status"], "completed",
                                "the second case finished before the kill")
        finally:
            os.killpg(proc.pid, signal.SIGKILL)  # the sweep and its crater run
            proc.communicate()
        self.assertEqual(proc.returncode, -signal.SIGKILL)
        before = ((first / "summary.json").stat().st_mtime_ns,
                  (first / "summary.json").read_bytes())
        _, rows = read_csv(out / "sweep.csv")
        self.assertEqual(rows[0]["status"], "completed", "the partial sweep.csv")

        p = sweep(*args)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertRegex(p.stderr, r"case 2/3 \(scenario\.end_time_s=1e-3\) completed in .* "
                                   r"resumed from its checkpoint")
        self.assertNotIn("case 1/3", p.stderr, "the completed case is not run again")
        after = ((first / "summary.json").stat().st_mtime_ns,
                 (first / "summary.json").read_bytes())
        self.assertEqual(after, before)
        self.assertGreater(summary(second)["run"].get("resumed_at_step", 0), 0)
        _, rows = read_csv(out / "sweep.csv")
        self.assertEqual([r["status"] for r in rows], ["completed"] * 3)
        self.assertEqual([r["scenario.end_time_s"] for r in rows], ["1e-4", "1e-3", "2e-4"])
        for d in case_dirs(out):
            self.assertEqual(summary(d)["status"], "completed")

    # 3 -----------------------------------------------------------------------------------
    def test_bad_input_runs_nothing(self):
        out = self.work / "bad"
        p = sweep(SCENE, "--vary", "parts.0.bogus_key=1,2", "--out", out)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("bogus_key", p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        self.assertFalse(list(out.rglob("summary.json")) if out.exists() else [],
                         "no case was run")
        for args in (["--vary", "time.safety_factor"],             # no values
                     ["--vary", "time.safety_factor="],
                     ["--vary", "time.safety_factor=0.5,,0.9"],    # an empty value
                     ["--vary", "no such key=1"],
                     ["--vary", "time.safety_factor=0.5", "--vary", "time.safety_factor=0.6"],
                     [],                                           # no --vary
                     ["--vary", "time.safety_factor=0.3:0.9"],     # a range without --samples
                     ["--samples", 3, "--vary", "time.safety_factor=0.5,0.9"],
                     ["--samples", 3, "--vary", "time.safety_factor=0.9:0.3"],
                     ["--samples", 1, "--vary", "time.safety_factor=0.3:0.9"],
                     ["--vary", "time.safety_factor=0.5", "--jobs", 0]):
            with self.subTest(args=args):
                p = sweep(SCENE, *args, "--out", out)
                self.assertEqual(p.returncode, 2, p.stderr)
                self.assertRegex(p.stderr, r"crater sweep: error: ")
                self.assertFalse(out.exists(), "nothing written")

        # an --out that holds another sweep
        done = self.work / "other_plan"
        base = [SCENE, *COARSE, "--set", "scenario.end_time_s=2e-5", "--out", done]
        p = sweep(*base, "--vary", "time.safety_factor=0.9")
        self.assertEqual(p.returncode, 0, p.stderr)
        mark = (done / "cases" / "case_0001" / "summary.json").stat().st_mtime_ns
        p = sweep(*base, "--vary", "time.safety_factor=0.8")
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("another --out", p.stderr)
        self.assertEqual((done / "cases" / "case_0001" / "summary.json").stat().st_mtime_ns,
                         mark)
        self.assertEqual(json.loads((done / "sweep.json").read_text())["cases"][0]["values"],
                         {"time.safety_factor": "0.9"})

    # 4 -----------------------------------------------------------------------------------
    def test_latin_hypercube(self):
        out = self.work / "lhs"
        ranges = {"time.safety_factor": (0.3, 0.9), "scenario.end_time_s": (5e-5, 1e-4)}
        args = [SCENE, *COARSE, *PROBES, "--samples", 4, "--seed", 7,
                *[a for k, (lo, hi) in ranges.items() for a in ("--vary", f"{k}={lo}:{hi}")],
                "--jobs", 2, "--out", out]
        p = sweep(*args)
        self.assertEqual(p.returncode, 0, p.stderr)
        plan = json.loads((out / "sweep.json").read_text())
        self.assertEqual((plan["samples"], plan["seed"]), (4, 7))
        self.assertEqual(len(plan["cases"]), 4)
        self.assertEqual(len(case_dirs(out)), 4)
        _, rows = read_csv(out / "sweep.csv")
        self.assertEqual([r["status"] for r in rows], ["completed"] * 4)
        for key, (lo, hi) in ranges.items():
            values = [float(c["values"][key]) for c in plan["cases"]]
            self.assertEqual([float(r[key]) for r in rows], values)
            for v in values:
                self.assertTrue(lo <= v <= hi, f"{key} = {v}")
            quarters = sorted(int((v - lo) / (hi - lo) * 4) for v in values)
            self.assertEqual(quarters, [0, 1, 2, 3], f"{key}: one value per quarter: {values}")
        # the same seed, the same cases: the same command again is the same plan (nothing is
        # run again); another seed is another plan
        p = sweep(*args)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertNotRegex(p.stderr, r"case \d/4 .* completed in")
        self.assertEqual(json.loads((out / "sweep.json").read_text())["cases"], plan["cases"])
        other = [str(a) for a in args]
        other[other.index("--seed") + 1] = "8"
        p = sweep(*other)
        self.assertEqual(p.returncode, 2, p.stderr)

    # 5 -----------------------------------------------------------------------------------
    def test_a_failing_case(self):
        out = self.work / "failing"
        # time.min_dt_s = 4e-7 stops that case at its first steps (exit 3)
        p = sweep(SCENE, *COARSE, *PROBES, "--vary", "time.min_dt_s=1e-12,4e-7,1e-9",
                  "--metrics", "energy.balance_error", "--jobs", 2, "--out", out)
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertRegex(p.stderr, r"case 2/3 \(time\.min_dt_s=4e-7\) failed \(exit code 3\)")
        _, rows = read_csv(out / "sweep.csv")
        self.assertEqual([(r["status"], r["exit_code"]) for r in rows],
                         [("completed", "0"), ("failed", "3"), ("completed", "0")])
        self.assertEqual(summary(out / "cases" / "case_0001")["status"], "completed")
        self.assertEqual(summary(out / "cases" / "case_0003")["status"], "completed")
        assert_png(self, out / "charts" / "energy.balance_error.png")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
