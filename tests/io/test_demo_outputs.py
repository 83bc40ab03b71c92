"""The demo's outputs, read back by VTK's own readers (python3-vtk9), agree with summary.json:
every .pvd lists existing .vtu frames at increasing times ending at end_time_s; every .vtu has
the part's particle count, the expected arrays with the right sizes, finite values, and masses
summing to the part mass in summary.json; history.csv rows are consistent."""
import csv
import json
import math
import sys
import unittest
from pathlib import Path

import numpy as np

from crater_test import read_pvd, read_vtu, run_scenario, scratch

EXPECTED_SPH_ARRAYS = {
    # name: components (2D vectors are padded to 3 for ParaView)
    "id": 1, "velocity": 3, "mass": 1, "density": 1, "specific_energy": 1,
    "smoothing_length": 1, "pressure": 1, "sound_speed": 1, "burn_fraction": 1,
}


class DemoOutputs(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.out = scratch("demo_outputs")
        cls.summary = run_scenario("demo", cls.out)

    def test_summary_fields(self):
        s = self.summary
        self.assertEqual(s["status"], "completed")
        self.assertEqual(s["scenario"]["name"], "demo")
        self.assertEqual(s["scenario"]["dimension"], 2)
        self.assertAlmostEqual(s["time_s"], s["scenario"]["end_time_s"], delta=1e-15)
        self.assertGreater(s["steps"], 0)
        self.assertGreater(s["parts"][0]["count"], 0)
        for key in ("energy", "metrics", "time_step", "run"):
            self.assertIn(key, s)
        self.assertRegex(s["scenario"]["hash"], r"^[0-9a-f]{16}$")

    def test_every_pvd_and_vtu(self):
        end = self.summary["scenario"]["end_time_s"]
        for part in self.summary["parts"]:
            name, count = part["name"], part["count"]
            pvd = self.out / f"{name}.pvd"
            frames = read_pvd(pvd)
            self.assertGreaterEqual(len(frames), 2, "a start and an end frame at least")
            times = [t for t, _ in frames]
            self.assertEqual(times, sorted(times))
            self.assertEqual(times[0], 0.0)
            self.assertAlmostEqual(times[-1], end, delta=1e-12 * end)
            vtus = sorted(self.out.glob(f"{name}_*.vtu"))
            self.assertEqual(sorted(f for _, f in frames), [p.name for p in vtus])
            for t, f in frames:
                with self.subTest(file=f):
                    pts, arrays, ncells, tv = read_vtu(self.out / f)
                    self.assertEqual(pts.shape, (count, 3))
                    self.assertEqual(ncells, count)
                    self.assertAlmostEqual(tv, t, delta=1e-15)
                    self.assertTrue(np.all(pts[:, 2] == 0.0), "2D: z = 0")
                    self.assertEqual(set(arrays), set(EXPECTED_SPH_ARRAYS))
                    for a, comps in EXPECTED_SPH_ARRAYS.items():
                        arr = arrays[a]
                        shape = (count,) if comps == 1 else (count, comps)
                        self.assertEqual(arr.shape, shape, a)
                        self.assertTrue(np.all(np.isfinite(arr)), a)
                    self.assertTrue(np.all(arrays["velocity"][:, 2] == 0.0))
                    self.assertEqual(sorted(arrays["id"].tolist()), list(range(count)))
                    self.assertTrue(math.isclose(arrays["mass"].sum(), part["mass_kg"],
                                                 rel_tol=1e-12))
                    self.assertTrue(np.all(arrays["density"] > 0))
                    self.assertTrue(np.all((arrays["burn_fraction"] >= 0) &
                                           (arrays["burn_fraction"] <= 1)))

    def test_kinetic_energy_matches_vtu(self):
        # Kinetic energy from the last frame's masses and velocities equals summary.json's.
        name = self.summary["parts"][0]["name"]
        last = read_pvd(self.out / f"{name}.pvd")[-1][1]
        _, arrays, _, _ = read_vtu(self.out / last)
        ke = 0.5 * np.sum(arrays["mass"] * np.sum(arrays["velocity"] ** 2, axis=1))
        self.assertTrue(math.isclose(ke, self.summary["energy"]["final"]["kinetic_j"],
                                     rel_tol=1e-9))
        ie = np.sum(arrays["mass"] * arrays["specific_energy"])
        self.assertTrue(math.isclose(ie, self.summary["energy"]["final"]["internal_j"],
                                     rel_tol=1e-9))

    def test_history_csv(self):
        with open(self.out / "history.csv") as f:
            rows = list(csv.DictReader(f))
        self.assertGreater(len(rows), 2)
        steps = [int(r["step"]) for r in rows]
        self.assertEqual(steps, sorted(steps))
        self.assertEqual(steps[-1], self.summary["steps"])
        self.assertAlmostEqual(float(rows[-1]["time_s"]), self.summary["time_s"], delta=1e-15)
        self.assertAlmostEqual(float(rows[0]["internal_j"]),
                               self.summary["energy"]["initial"]["internal_j"], delta=1e-6)

    def test_base64_encoding_reads_the_same(self):
        out64 = scratch("demo_outputs_b64")
        run_scenario("demo", out64, sets=["output.vtu_encoding=\"base64\""])
        for f in sorted(self.out.glob("*.vtu")):
            _, a, _, _ = read_vtu(f)
            _, b, _, _ = read_vtu(out64 / f.name)
            for k in a:
                np.testing.assert_array_equal(a[k], b[k], err_msg=f"{f.name}:{k}")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
