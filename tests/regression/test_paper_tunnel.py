# ctest-processors: 2
"""The paper-tunnel draft (issue 27; scenarios/drafts/paper-tunnel.toml): it loads, and its
first steps are the same on one and two threads.

- `crater check` accepts it: the lining and soil parts from the Gmsh file, their boundary
  conditions by physical group, the charge inside the ring (a mesh part's body is its nodes and
  elements, not its bounding box, for the overlap check);
- 60 steps (51 us) on 1 and 2 threads (nothing else running beside them: a 2-thread run
  beside another test waits at its barriers) write bit-identical frames, history and summary,
  with the lining probe's columns in history.csv. The lining-soil contact carries the ground's
  weight from the first step; the products reach the lining only at 0.77 ms (step 900), so the
  charge-lining contact is not exercised here (test_thread_determinism covers sph-fem).
The whole run to 20 ms and its metrics are in docs/validation.md ("paper-tunnel").
"""
import csv
import os
import sys
import unittest
from pathlib import Path

from crater_test import assert_bit_identical_runs, crater, scratch

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SCENARIO = SOURCE / "scenarios" / "drafts" / "paper-tunnel.toml"


class PaperTunnel(unittest.TestCase):
    def test_check(self):
        p = crater("check", SCENARIO)
        self.assertIn("lining", p.stdout)
        self.assertIn("soil", p.stdout)

    def test_first_steps_same_on_one_and_two_threads(self):
        work = scratch("paper_tunnel_threads")
        names = assert_bit_identical_runs(
            SCENARIO, work, sets=["time.max_steps=60", "output.interval_s=2e-5"])
        self.assertIn("history.csv", names)
        with open(Path(work) / "threads1" / "history.csv") as f:
            rows = list(csv.DictReader(f))
        self.assertIn("lining_crown_radial_m", rows[0])
        # The lining-soil contact acts (the soil's geostatic load on the lining).
        self.assertTrue(any(float(r["force_lining-soil_z"]) != 0 for r in rows))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
