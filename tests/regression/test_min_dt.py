"""time.min_dt_s (LS-DYNA's TSMIN): a run whose step falls below it stops with exit 3, the last
state written, naming the part and entity that limit the step and the key; above it nothing
changes. Found on paper-tunnel (docs/validation.md), whose step collapsed from 8.5e-7 s to
7e-9 s and whose run then crawled on for hours.

Scenario: the bundled demo (2D SPH TNT charge; its step at t = 0 is about 1e-6 s).
- min_dt_s = 1 s: the first step is below it: exit 3, "time.min_dt_s" and the charge named,
  charge_failure.vtu written, summary "failed";
- the same with multi_rate = true (the plan's step is checked);
- min_dt_s = 1e-12 s: 5 steps, exit 0, the same history as without the key.
"""
import filecmp
import json
import os
import sys
import unittest
from pathlib import Path

from crater_test import crater, scratch

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DEMO = SOURCE / "scenarios" / "demo.toml"


class MinDt(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = scratch("min_dt")

    def test_step_below_stops_the_run(self):
        for name, extra in (("one_rate", []), ("multi_rate", ["--set", "time.multi_rate=true"])):
            with self.subTest(stepping=name):
                out = self.dir / name
                p = crater("run", DEMO, "--out", out, "--force", "--quiet",
                           "--set", "time.min_dt_s=1", *extra, check=False)
                self.assertEqual(p.returncode, 3, p.stderr)
                self.assertIn("time.min_dt_s", p.stderr)
                self.assertIn("part 'charge'", p.stderr)
                self.assertTrue((out / "charge_failure.vtu").exists())
                summary = json.loads((out / "summary.json").read_text())
                self.assertEqual(summary["status"], "failed")

    def test_step_above_changes_nothing(self):
        outs = []
        for name, extra in (("plain", []), ("guarded", ["--set", "time.min_dt_s=1e-12"])):
            out = self.dir / name
            crater("run", DEMO, "--out", out, "--force", "--quiet", "--set", "time.max_steps=5",
                   *extra)
            outs.append(out)
        self.assertTrue(filecmp.cmp(outs[0] / "history.csv", outs[1] / "history.csv",
                                    shallow=False))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
