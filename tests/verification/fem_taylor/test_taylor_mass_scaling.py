# ctest-cost: 15
"""Selective mass scaling on a crushed element set: the 3D Taylor bar of test_taylor_bar.py (a
42CrMo4 rod at 287 m/s on a rigid frictionless wall), whose impact-face elements flatten and
would hold the whole run's step down.

With fem.mass_scaling_step_ratio = r, an element whose stable step falls below r times the rod's
initial step gains the mass that keeps its step there (LS-DYNA's DT2MS < 0). References:
- the same rod without mass scaling (the run the added mass perturbs): final length and impact
  face diameter within 1 %, since the added mass stays under 1 % of the rod's;
- the Abaqus/Explicit result of test_taylor_bar.py: within the 5 % of that test;
- exact bookkeeping: the rod's mass grows by exactly the added mass the summary reports, which
  stays under the limit; the run's smallest step is never below safety x floor, where the
  unscaled run's is; the energy balance holds to 1 % as it does unscaled.
Past the limit (fem.mass_scaling_limit = 1e-5) the run stops with exit code 3, naming the part
and an element, after writing the last good state (rod_failure.vtu) and a failed summary.
"""
import json
import subprocess
import sys
import unittest

import numpy as np

from crater_test import BIN, read_vtu, run_scenario, scratch
from test_taylor_bar import REF_D, REF_L, write_case

RATIO = 0.8
INTERVAL = 2e-5  # the frame interval of the composed scenario


def steps_between_frames(out):
    """dt of every step that was not shortened to land on a frame time (history_every = 1)."""
    h = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
    t, dt = h["time_s"][1:], h["dt_s"][1:]
    at_frame = np.abs(t / INTERVAL - np.round(t / INTERVAL)) < 1e-9
    return dt[~at_frame]


def shape(out):
    points, _, _, time = read_vtu(out / "rod_000004.vtu")
    face = points[np.abs(points[:, 1]) < 1e-9]
    return points[:, 1].max(), 2 * np.hypot(face[:, 0], face[:, 2]).max(), time


class TaylorMassScaling(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("fem_taylor_mass_scaling")
        scenario = write_case(cls.work)
        every = "output.history_every=1"
        cls.plain = run_scenario(scenario, cls.work / "plain", sets=[every])
        cls.scaled = run_scenario(scenario, cls.work / "scaled",
                                  sets=[every, f"parts.rod.fem.mass_scaling_step_ratio={RATIO}"])
        cls.plain_shape = shape(cls.work / "plain")
        cls.scaled_shape = shape(cls.work / "scaled")
        cls.diag = cls.scaled["parts"][0]["diagnostics"]

    def test_mass_is_added_and_bounded(self):
        d = self.diag
        initial = d["initial_mass_kg"]
        print(f"added {d['added_mass_kg']:.4g} kg = {100 * d['added_mass_fraction']:.3f} % of "
              f"{initial:.4g} kg on {d['mass_scaled_elements']:.0f} elements; floor "
              f"{d['mass_scaling_min_step_s']:.4g} s")
        self.assertGreater(d["mass_scaled_elements"], 0)
        self.assertGreater(d["added_mass_kg"], 0)
        self.assertLessEqual(d["added_mass_fraction"], 0.01)  # the default limit
        # The rod's mass is its initial mass plus exactly what was added (nothing eroded).
        self.assertEqual(d["eroded_elements"], 0)
        self.assertAlmostEqual(self.scaled["parts"][0]["mass_kg"], initial + d["added_mass_kg"],
                               delta=1e-12 * initial)
        self.assertAlmostEqual(self.plain["parts"][0]["mass_kg"], initial, delta=1e-12 * initial)

    def test_step_held_at_the_floor(self):
        floor = self.diag["mass_scaling_min_step_s"]
        safety = self.scaled["time_step"]["safety_factor"]
        plain_min = steps_between_frames(self.work / "plain").min()
        scaled_min = steps_between_frames(self.work / "scaled").min()
        print(f"smallest step: {plain_min:.4g} s plain, {scaled_min:.4g} s scaled, "
              f"safety x floor {safety * floor:.4g} s; steps {self.plain['steps']} -> "
              f"{self.scaled['steps']}")
        self.assertLess(plain_min, safety * floor * (1 - 1e-6))  # the case does crush elements
        self.assertGreaterEqual(scaled_min, safety * floor * (1 - 1e-9))
        self.assertLess(self.scaled["steps"], self.plain["steps"])

    def test_shape_matches_the_unscaled_run_and_abaqus(self):
        (lp, dp, tp), (ls, ds, ts) = self.plain_shape, self.scaled_shape
        print(f"final length {ls * 1e3:.3f} mm scaled vs {lp * 1e3:.3f} mm plain "
              f"({100 * (ls / lp - 1):+.3f} %), Abaqus {REF_L * 1e3:.2f} mm; impact face "
              f"{ds * 1e3:.3f} vs {dp * 1e3:.3f} mm ({100 * (ds / dp - 1):+.3f} %), Abaqus "
              f"{REF_D * 1e3:.2f} mm")
        self.assertAlmostEqual(ts, tp, delta=1e-12)
        self.assertLess(abs(ls / lp - 1), 0.01)
        self.assertLess(abs(ds / dp - 1), 0.01)
        self.assertLess(abs(ls / REF_L - 1), 0.05)
        self.assertLess(abs(ds / REF_D - 1), 0.05)

    def test_energy_balance(self):
        plain = self.plain["energy"]["balance_error"]
        scaled = self.scaled["energy"]["balance_error"]
        picked = self.diag["mass_scaling_dissipated_j"]
        print(f"balance error {scaled:.2e} scaled, {plain:.2e} plain; kinetic energy given up "
              f"by the nodes taking mass {picked:.4g} J")
        self.assertGreaterEqual(picked, 0)
        self.assertLess(abs(scaled), 0.01)

    def test_past_the_limit_exit_3(self):
        out = self.work / "limit"
        r = subprocess.run(
            [BIN, "run", str(self.work / "taylor.toml"), "--out", str(out), "--force",
             "--quiet", "--set", f"parts.rod.fem.mass_scaling_step_ratio={RATIO}",
             "--set", "parts.rod.fem.mass_scaling_limit=1e-5"],
            capture_output=True, text=True, timeout=600)
        print(next((l for l in r.stderr.splitlines() if "mass_scaling_limit" in l), r.stderr))
        self.assertEqual(r.returncode, 3, r.stderr)
        self.assertIn("mass_scaling_limit", r.stderr)
        self.assertIn("'rod'", r.stderr)
        self.assertTrue((out / "rod_failure.vtu").exists())
        with open(out / "summary.json") as f:
            s = json.load(f)
        self.assertEqual(s["status"], "failed")
        # The summary reports the mass that passed the limit.
        self.assertGreater(s["parts"][0]["diagnostics"]["added_mass_fraction"], 1e-5)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
