# ctest-processors: 2
# ctest-timeout: 600
"""Moving rigid walls of a DEM part ([[parts.dem.wall_motion]], issue 24; docs/theory.md §3).

- A wall at constant speed is where kinematics puts it: the top wall of a 1 m box moves in at
  2 m/s from 0.02 s to 0.08 s after a 0.01 s linear ramp, the right wall (placed at 0.6 m) out
  at 1 m/s from the start; every history row's position is x_0 + the integral of the speed to
  1e-9 m (the sum of the steps' increments), and the reported speed is the prescribed one.
- A servo wall holds its stress on a settled bed: 102 sand grains (the paper's sand, radii
  4-10 mm) settled in a 0.2 m wide box, the top wall servo-controlled to 20 kPa (gain 0.5, at
  most 5 cm/s), frictionless walls. Over the last 40 % of 60 ms the mean stress is within 0.5 %
  of the target and every row within 3 % (measured: -0.002 %; rows -0.5 % to +1.1 %); the
  bottom wall (velocity 0: a fixed wall that reports its load) carries the top's force plus
  the grains' weight, to 5 % of the weight (frictionless side walls carry none of it;
  measured 1.0 %).
- The same run is bit-identical on 1 and 2 threads (the walls' loads are reproducible sums:
  the same bits in any order), and a run restarted from a checkpoint taken while the servo
  works ends bit-identical to the uninterrupted one (the walls' planes, speeds and loads are in
  the checkpoint).
- Input errors (exit 2, naming the key): a face that is not one of the part's walls; both
  velocity_m_s and stress_pa, or neither; two entries of one face whose windows overlap.
- Zero wall friction gave NaN contact energies (the sliding power divided by the step, zero
  for the forces of t = 0): the servo run's energy columns are finite.
"""
import csv
import shutil
import sys
import unittest

import numpy as np

from crater_test import (assert_bit_identical_runs, crater, scratch,
                         summary_without_run_block)
from scenario_blocks import (SAND, box, compose_scenario, domain, output, part, particle,
                             write_scenario)

TARGET_PA = 20e3
WIDTH_M = 0.2


def history(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def speed_case():
    motion = [{"face": "top", "velocity_m_s": -2.0, "start_s": 0.02, "end_s": 0.08,
               "ramp_s": 0.01},
              {"face": "right", "position_m": 0.6, "velocity_m_s": 1.0}]
    return compose_scenario(
        "wall-speed", 2, 0.1, domain=domain([0.0, 0.0], [1.0, 1.0], [0.0, -9.81]),
        output=output(0.05, 100), materials=[SAND],
        parts=[part("soil", "dem", "sand", 0.02, box([0.2, 0.0], [0.4, 0.1]),
                    dem={"walls": ["left", "right", "bottom", "top"],
                         "hertz_2d": "row_of_spheres", "wall_motion": motion},
                    particles=[particle([0.3, 0.01], 0.01)])])


def servo_case(work, end_s):
    motion = [{"face": "top", "position_m": 0.1, "stress_pa": TARGET_PA, "max_speed_m_s": 0.05},
              {"face": "bottom", "velocity_m_s": 0.0}]
    # The energy guard off: before the wall arrives the bed rests, with next to no kinetic
    # energy or work (the guard's scale), and its creep of 1e-6 J against the frictionless
    # walls reads as 125 %.
    return compose_scenario(
        "wall-servo", 2, end_s, domain=domain([0.0, 0.0], [WIDTH_M, 0.2], [0.0, -9.81]),
        time={"energy_stop_error": 0.0, "energy_warn_error": 0.0},
        output=output(end_s / 4, 20), materials=[SAND],
        parts=[part("soil", "dem", "sand", 0.02, box([0.0, 0.0], [WIDTH_M, 0.1]),
                    dem={"radius_min_m": 0.004, "radius_max_m": 0.01,
                         "hertz_2d": "row_of_spheres", "wall_friction": 0.0,
                         "walls": ["left", "right", "bottom", "top"], "wall_motion": motion},
                    packing={"method": "dense", "settle": True,
                             "cache_dir": str(work / "cache")})])


class ConstantSpeed(unittest.TestCase):
    def test_positions_follow_the_prescribed_speed(self):
        work = scratch("wall_motion_speed")
        write_scenario(work / "case.toml", speed_case())
        crater("run", work / "case.toml", "--out", work / "out", "--force", "--quiet")
        h = history(work / "out" / "history.csv")
        t = h["time_s"]
        # Top: ramp 0 -> -2 m/s over [0.02, 0.03], then -2 m/s to 0.08.
        ramp = np.clip(t - 0.02, 0, 0.01)
        moved = -2.0 * (ramp ** 2 / (2 * 0.01) + np.clip(t - 0.03, 0, 0.05))
        np.testing.assert_allclose(h["soil_wall_top_position_m"], 1.0 + moved, atol=1e-9)
        np.testing.assert_allclose(h["soil_wall_right_position_m"], 0.6 + t, atol=1e-9)
        self.assertAlmostEqual(h["soil_wall_top_position_m"][-1], 1 - 2 * 0.055, delta=1e-9)
        after = (t > 0.031) & (t < 0.079)
        np.testing.assert_allclose(h["soil_wall_top_velocity_m_s"][after], -2.0, rtol=1e-9)
        self.assertEqual(h["soil_wall_top_velocity_m_s"][-1], 0.0)


class Servo(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("wall_motion_servo")
        cls.case = cls.work / "case.toml"
        write_scenario(cls.case, servo_case(cls.work, 0.06))
        crater("run", cls.case, "--out", cls.work / "out", "--force", "--quiet")
        cls.h = history(cls.work / "out" / "history.csv")

    def test_top_wall_holds_its_stress(self):
        h = self.h
        late = h["time_s"] > 0.6 * h["time_s"][-1]
        stress = h["soil_wall_top_stress_pa"][late]
        self.assertLess(abs(stress.mean() / TARGET_PA - 1), 0.005)
        self.assertLess(np.abs(stress / TARGET_PA - 1).max(), 0.03)
        # The stress is the force over the width between the side walls.
        np.testing.assert_allclose(h["soil_wall_top_force_n"], h["soil_wall_top_stress_pa"] *
                                   WIDTH_M, rtol=1e-12)

    def test_bottom_carries_top_plus_weight(self):
        import json
        summary = json.loads((self.work / "out" / "summary.json").read_text())
        mass = summary["parts"][0]["mass_kg"]
        weight = mass * 9.81
        h = self.h
        late = h["time_s"] > 0.6 * h["time_s"][-1]
        carried = (h["soil_wall_bottom_force_n"] - h["soil_wall_top_force_n"])[late].mean()
        self.assertLess(abs(carried / weight - 1), 0.05)
        self.assertTrue(np.all(h["soil_wall_bottom_position_m"] == 0.0))

    def test_energy_columns_are_finite(self):
        for k in ("contact_j", "total_j", "energy_error"):
            self.assertTrue(np.all(np.isfinite(self.h[k])), k)

    def test_one_and_two_threads_are_bit_identical(self):
        work = scratch("wall_motion_threads")
        case = work / "case.toml"
        write_scenario(case, servo_case(self.work, 0.015))  # the cached bed of setUpClass
        assert_bit_identical_runs(case, work)

    def test_restart_is_bit_identical(self):
        work = scratch("wall_motion_restart")
        case = work / "case.toml"
        write_scenario(case, servo_case(self.work, 0.015))
        sets = ["--set", "output.checkpoint_every_steps=6000", "--set",
                "output.checkpoint_keep=100"]
        full = work / "full"
        crater("run", case, "--out", full, "--force", "--quiet", *sets)
        cks = sorted((full / "checkpoints").glob("*.ckpt"))
        self.assertGreaterEqual(len(cks), 2)
        again = work / "again"
        shutil.copytree(full, again)
        (again / "summary.json").unlink()
        crater("run", case, "--restart", again / "checkpoints" / cks[1].name, "--quiet", *sets)
        for f in sorted(full.iterdir()):
            if f.is_file() and f.name not in ("summary.json", "crater-command.toml"):
                self.assertEqual(f.read_bytes(), (again / f.name).read_bytes(), f.name)
        self.assertEqual(summary_without_run_block(full / "summary.json"),
                         summary_without_run_block(again / "summary.json"))


class InputErrors(unittest.TestCase):
    def check(self, motion, key, words):
        work = scratch("wall_motion_errors")
        sc = speed_case()
        sc["parts"][0]["dem"]["walls"] = ["bottom", "top"]
        sc["parts"][0]["dem"]["wall_motion"] = motion
        write_scenario(work / "case.toml", sc)
        p = crater("check", work / "case.toml", check=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn(key, p.stderr)
        self.assertIn(words, p.stderr)

    def test_face_not_a_wall(self):
        self.check([{"face": "left", "velocity_m_s": 1.0}],
                   "parts[0].dem.wall_motion[0].face", "not one of")

    def test_velocity_and_stress(self):
        self.check([{"face": "top", "velocity_m_s": 1.0, "stress_pa": 1e3}],
                   "parts[0].dem.wall_motion[0].stress_pa", "not both")

    def test_neither_velocity_nor_stress(self):
        self.check([{"face": "top"}], "parts[0].dem.wall_motion[0].velocity_m_s", "missing")

    def test_overlapping_windows(self):
        self.check([{"face": "top", "velocity_m_s": 1.0, "end_s": 0.05},
                    {"face": "top", "stress_pa": 1e3, "start_s": 0.04}],
                   "parts[0].dem.wall_motion[1].start_s", "already moves")


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
