# ctest-fixtures: bundled_bed
# ctest-cost: 32
"""Extending a finished run (issue 28): `crater run --resume DIR --set scenario.end_time_s=LATER`
continues from the checkpoint every run writes at its end (output.checkpoint_at_end), and the
run directory it leaves is bit for bit the one of a single run to the later end time: every VTU
frame, .pvd, history.csv, the probes' files, and summary.json but its "run" block (wall time,
threads); the manifest (crater-manifest.txt, the names --force may delete) holds the same
names, in another order. Here on the paper's coupled scene at its demo level (SPH charge, eroding plate, DEM
soil, three contacts, the surface probe), 0.125 ms extended to 0.25 ms with one step for all,
0.25 ms to 0.5 ms with multi-rate stepping (whose step ratios open up from 0.22 ms); and on the clamped plate, whose first end time (6e-5 s) is not the
double its frames' interval makes (6 x 1e-5 = 6.000000000000001e-05). The whole 10 -> 15 ms of
the acceptance runs under `ctest -L slow` (test_extend_run_demo.py).

And what may not be extended: a key that changes the state (a material), the output interval,
or an end time not after the run's; each is refused with exit 2, naming the reason, and leaves
the run directory as it was."""
import filecmp
import shutil
import sys
import unittest
from pathlib import Path

from crater_test import (COMMAND_FILE, SOURCE_DIR, crater, run_scenario, scratch,
                         summary_without_run_block)

# Frames every 0.25 ms (the file's: 0.5 ms), so that the first end time is an output time.
DEMO_FRAMES = ["output.interval_s=2.5e-4"]
PLATE = str(Path(SOURCE_DIR) / "tests" / "data" / "fem_plate_2d.toml")


def assert_same_run(test, single, extended):
    """Every file of the single run is in the extended one, byte for byte (summary.json: all but
    its "run" block; the command file records each run's own command line)."""
    names = sorted(p.name for p in single.iterdir() if p.is_file())
    test.assertEqual(names, sorted(p.name for p in extended.iterdir() if p.is_file()))
    test.assertTrue(any(n.endswith(".vtu") for n in names))
    for n in names:
        if n == COMMAND_FILE:
            continue
        if n == "crater-manifest.txt":  # what the run wrote, for --force: the same set of names
            test.assertEqual(sorted((single / n).read_text().splitlines()),
                             sorted((extended / n).read_text().splitlines()))
            continue
        if n == "summary.json":
            test.assertEqual(summary_without_run_block(single / n),
                             summary_without_run_block(extended / n))
        else:
            test.assertTrue(filecmp.cmp(single / n, extended / n, shallow=False), f"{n} differs")
    return names


class ExtendRun(unittest.TestCase):
    def extend(self, scenario, name, first_end, later_end, sets=()):
        """Runs to first_end, extends to later_end; runs to later_end at once; compares."""
        base = [*sets, "output.checkpoint_every_s=0"]
        ext = scratch(f"extend_{name}")
        s1 = run_scenario(scenario, ext, threads=1, sets=[*base, f"scenario.end_time_s={first_end}"])
        self.assertEqual(s1["status"], "completed")
        ckpts = sorted((ext / "checkpoints").glob("*.ckpt"))
        self.assertEqual(len(ckpts), 1, "one checkpoint, the run's last state")
        crater("run", "--resume", ext, "--quiet", "--set", f"scenario.end_time_s={later_end}")
        single = scratch(f"extend_{name}_single")
        s2 = run_scenario(scenario, single, threads=1,
                          sets=[*base, f"scenario.end_time_s={later_end}"])
        self.assertEqual(s2["status"], "completed")
        self.assertGreater(s2["steps"], s1["steps"])
        names = assert_same_run(self, single, ext)
        # The command file now holds the extension, so that a further --resume takes it.
        self.assertIn(f"scenario.end_time_s={later_end}", (ext / COMMAND_FILE).read_text())
        print(f"{name}: {s1['steps']} + {s2['steps'] - s1['steps']} steps, {len(names)} files "
              "identical", file=sys.stderr)
        return names

    def test_paper_20cm_demo(self):
        names = self.extend("paper-20cm", "paper20", "1.25e-4", "2.5e-4",
                            sets=["output.interval_s=1.25e-4"])
        self.assertIn("surface_profile.csv", names)
        self.assertIn("plate.pvd", names)

    def test_paper_20cm_demo_multi_rate(self):
        # The charge steps up to 8 times the plate's step from 0.22 ms, as its particles leave.
        self.extend("paper-20cm", "paper20_mr", "2.5e-4", "5e-4",
                    sets=[*DEMO_FRAMES, "time.multi_rate=true"])

    def test_end_time_off_the_frame_grid_of_doubles(self):
        self.extend(PLATE, "plate", "6e-5", "1e-4")

    def test_refusals_leave_the_run_as_it_was(self):
        out = scratch("extend_refused")
        run_scenario(PLATE, out, sets=["scenario.end_time_s=5e-5"])
        before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
        cases = [
            (["--set", "scenario.end_time_s=1e-4", "--set", "materials.0.a_pa=60e6"],
             "another scenario"),
            (["--set", "scenario.end_time_s=1e-4", "--set", "output.interval_s=2e-5"],
             "interval_s may change"),
            ([], "already at t = 5e-05 s"),
            (["--set", "scenario.end_time_s=4e-5"], "already at t = 5e-05 s"),
        ]
        for extra, expected in cases:
            with self.subTest(extra=extra):
                proc = crater("run", "--resume", out, "--quiet", *extra, check=False)
                self.assertEqual(proc.returncode, 2, proc.stderr)
                self.assertIn(expected, proc.stderr)
                after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
                self.assertEqual(before, after)

    def test_unset_interval_is_named(self):
        # An unset output.interval_s follows the end time (end_time_s / 20), so a later end time
        # means other frames: refused, and the message says what to set.
        text = Path(PLATE).read_text()
        self.assertIn("interval_s = 1e-5\n", text)
        d = scratch("extend_unset_interval")
        d.mkdir(parents=True, exist_ok=True)
        (d / "plate.toml").write_text(text.replace("interval_s = 1e-5\n", ""))
        run_scenario(d / "plate.toml", d / "out", sets=["scenario.end_time_s=5e-5"])
        proc = crater("run", "--resume", d / "out", "--quiet", "--set",
                      "scenario.end_time_s=1e-4", check=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("output.interval_s is unset, so it follows the end time", proc.stderr)
        # With the run's interval stated, the same extension goes through.
        crater("run", "--resume", d / "out", "--quiet", "--set", "scenario.end_time_s=1e-4",
               "--set", "output.interval_s=2.5e-6")

    def test_no_end_checkpoint_when_switched_off(self):
        out = scratch("extend_off")
        run_scenario(PLATE, out, sets=["output.checkpoint_at_end=false",
                                       "output.checkpoint_every_s=0"])
        self.assertFalse((out / "checkpoints").exists())


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
