# ctest-labels: slow
# ctest-fixtures: bundled_bed
# ctest-timeout: 2400
"""Issue 28's acceptance, whole: `make run`'s scene (paper-20cm at its demo level) run to its
end time of 10 ms, then extended to 15 ms with `crater run --resume DIR --set
scenario.end_time_s=0.015`, leaves the run directory of a single 15 ms run bit for bit (every
VTU frame, .pvd, history.csv, surface_profile.csv; summary.json but its "run" block; the
manifest as the same set of names). About 6 minutes on one thread; the same check over 0.25 ->
0.5 ms, with and without multi-rate stepping, is in `make test` (test_extend_run.py)."""
import sys
import unittest

from crater_test import crater, run_scenario, scratch
from test_extend_run import assert_same_run


class ExtendDemo(unittest.TestCase):
    def test_10_to_15_ms(self):
        ext = scratch("extend_demo")
        first = run_scenario("paper-20cm", ext, threads=1, timeout=1800)
        self.assertEqual((first["status"], first["time_s"]), ("completed", 1e-2))
        crater("run", "--resume", ext, "--quiet", "--set", "scenario.end_time_s=0.015",
               timeout=1800)
        single = scratch("extend_demo_single")
        whole = run_scenario("paper-20cm", single, threads=1, timeout=2400,
                             sets=["scenario.end_time_s=0.015"])
        self.assertEqual(whole["status"], "completed")
        names = assert_same_run(self, single, ext)
        self.assertIn("surface_profile.csv", names)
        print(f"{first['steps']} + {whole['steps'] - first['steps']} steps; {len(names)} files "
              "identical", file=sys.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
