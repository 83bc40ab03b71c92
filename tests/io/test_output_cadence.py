# ctest-timeout: 300
"""Output cadence (issue 22, item 3): before the fix `output.interval_s = 1e-15` passed
`check` and the run wrote a VTU every step (182 MB a minute, "ETA 140113885 s").

Now: more frames than output.max_frames (default 10,000) is refused by check and run (exit 2,
key output.interval_s); so is a total VTU size above output.max_bytes (default 50 GB); both
limits can be raised; an interval below the stable step is allowed but said.
Scenario: the bundled demo (end time 40 us, stable step ~0.48 us, ~0.15 MB a frame).
"""
import os
import sys
import unittest
from pathlib import Path

from crater_test import crater, scratch

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DEMO = SOURCE / "scenarios" / "demo.toml"


class OutputCadence(unittest.TestCase):
    def test_tiny_interval_is_refused_by_check_and_run(self):
        out = scratch("cadence_tiny")
        for cmd in (["check", DEMO], ["run", DEMO, "--out", out, "--quiet"]):
            proc = crater(*cmd, "--set", "output.interval_s=1e-15", check=False, timeout=60)
            self.assertEqual(proc.returncode, 2, proc.stderr)
            self.assertIn("output.interval_s", proc.stderr)
            self.assertIn("max_frames", proc.stderr)
        self.assertEqual(list(out.glob("*.vtu")), [])

    def test_frame_limit_can_be_raised(self):
        proc = crater("check", DEMO, "--set", "output.interval_s=1e-9", "--set",
                      "output.max_frames=50000", "--set", "output.max_bytes=1e12", timeout=60)
        self.assertIn("ok", proc.stdout)

    def test_byte_limit(self):
        # 401 frames of ~0.15 MB: 60 MB, above a 10 MB limit.
        for cmd in (["check", DEMO], ["run", DEMO, "--out", scratch("cadence_bytes"), "--quiet"]):
            proc = crater(*cmd, "--set", "output.interval_s=1e-7",
                          "--set", "output.max_bytes=1e7", check=False, timeout=60)
            self.assertEqual(proc.returncode, 2, proc.stderr)
            self.assertIn("output.max_bytes", proc.stderr)

    def test_interval_below_the_stable_step_is_said(self):
        proc = crater("check", DEMO, "--set", "output.interval_s=1e-7", timeout=60)
        self.assertIn("below the stable step", proc.stdout + proc.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
