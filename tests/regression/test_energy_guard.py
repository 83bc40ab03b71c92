# ctest-timeout: 300
"""The energy guard (issue 22, item 5): before it, a real blow-up (SPH Courant number 1 at
safety factor 1) ran 2,480 steps at ~100 % balance error and then stopped on a particle leaving
the domain, with advice to enlarge the domain; a run with a large error exited 0 silently.

Now (time.energy_warn_error, default 2 %; time.energy_stop_error, default 20 %):
- the blow-up stops with exit 3 at the first history row above 20 %, naming the part whose
  energy grew and the key, and writes the failure state (charge_failure.vtu, summary "failed");
- a run whose error passes the warning level warns once and goes on (exit 0);
- 0 turns the guard off: the blow-up then runs on as before.
Scenario: the bundled demo (2D SPH TNT charge).
"""
import csv
import json
import os
import sys
import unittest
from pathlib import Path

from crater_test import crater, scratch

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DEMO = SOURCE / "scenarios" / "demo.toml"
BLOW_UP = ["--set", "parts.charge.sph.cfl=1", "--set", "time.safety_factor=1"]


def history(out):
    with open(out / "history.csv") as f:
        return list(csv.DictReader(f))


class EnergyGuard(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = scratch("energy_guard")

    def test_blow_up_stops_at_the_stop_level(self):
        out = self.dir / "stop"
        proc = crater("run", DEMO, "--out", out, "--force", "--quiet", *BLOW_UP, check=False)
        self.assertEqual(proc.returncode, 3, proc.stderr)
        self.assertIn("part 'charge'", proc.stderr)
        self.assertIn("time.energy_stop_error", proc.stderr)
        rows = history(out)
        errors = [abs(float(r["energy_error"])) for r in rows]
        self.assertGreater(errors[-1], 0.2)
        self.assertTrue(all(e <= 0.2 for e in errors[:-1]), "the guard let a row above 20 % by")
        self.assertLess(int(rows[-1]["step"]), 2480)
        self.assertTrue((out / "charge_failure.vtu").exists())
        summary = json.loads((out / "summary.json").read_text())
        self.assertEqual(summary["status"], "failed")
        self.assertIn("energy", summary["message"])

    def test_guard_off_lets_the_blow_up_run(self):
        out = self.dir / "off"
        proc = crater("run", DEMO, "--out", out, "--force", "--quiet", *BLOW_UP,
                      "--set", "time.energy_stop_error=0", "--set", "time.energy_warn_error=0",
                      check=False)
        self.assertEqual(proc.returncode, 3, proc.stderr)
        self.assertNotIn("energy", proc.stderr)
        self.assertGreater(max(abs(float(r["energy_error"])) for r in history(out)), 0.9)

    def test_warning_is_given_once_and_the_run_goes_on(self):
        # Without artificial viscosity the demo's balance error reaches ~0.27 %: a warning
        # level of 0.1 % is passed, a stop level of 1 % is not.
        out = self.dir / "warn"
        proc = crater("run", DEMO, "--out", out, "--force", "--quiet",
                      "--set", "parts.charge.sph.av_alpha=0",
                      "--set", "time.energy_warn_error=0.001",
                      "--set", "time.energy_stop_error=0.01")
        self.assertEqual(proc.returncode, 0)
        warnings = [ln for ln in (proc.stdout + proc.stderr).splitlines()
                    if "time.energy_warn_error" in ln]
        self.assertEqual(len(warnings), 1, proc.stdout + proc.stderr)
        self.assertIn("part 'charge'", warnings[0])
        errors = [abs(float(r["energy_error"])) for r in history(out)]
        self.assertGreater(max(errors), 0.001)
        self.assertLess(max(errors), 0.01)

    def test_warning_above_stop_level_is_refused(self):
        proc = crater("check", DEMO, "--set", "time.energy_warn_error=0.5", check=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("time.energy_warn_error", proc.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
