"""`carve`: a soil box holding a charge and a plate. The DEM grains and the SPH particles of a
part that carves others are not laid where they would reach into those parts' regions, and
the carved parts may overlap the carving part's region (the overlap check lets them). The
laid grains are read back from the first VTU frame with VTK's reader."""
import sys
import unittest

import numpy as np

from crater_test import crater, read_vtu, run_scenario, scratch
from scenario_blocks import (SAND, STEEL, TNT, box, compose_scenario, disk, domain, part,
                             scenario_text)


def scenario(carve=("charge", "plate")):
    """The soil box whose part "soil" carves the parts named in `carve` (None: no carve key)."""
    return scenario_text(compose_scenario(
        "carve", 2, 1e-6, description="a soil box carved by a charge and a plate",
        time={"max_steps": 1}, domain=domain([0.0, -1.0], [1.0, 0.5]),
        materials=[TNT, STEEL, SAND],
        parts=[part("charge", "sph", "tnt", 0.02, disk([0.5, -0.6], 0.15)),
               part("plate", "fem", "steel", 0.02, box([0.0, -0.4], [1.0, -0.3])),
               part("soil", "dem", "sand", 0.02, box([0.0, -1.0], [1.0, 0.0]),
                    carve=None if carve is None else list(carve),
                    dem={"radius_min_m": 0.007, "radius_max_m": 0.009})]))


class Carve(unittest.TestCase):
    def test_grains_leave_the_carved_regions_empty(self):
        work = scratch("carve")
        (work / "case.toml").write_text(scenario())
        run_scenario(work / "case.toml", work / "out")
        x, a, _, _ = read_vtu(work / "out" / "soil_000000.vtu")
        r = a["radius"]
        to_charge = np.hypot(x[:, 0] - 0.5, x[:, 1] + 0.6) - 0.15
        gap_below = -0.4 - x[:, 1]  # distance below the plate's bottom face
        gap_above = x[:, 1] + 0.3  # above its top face
        to_plate = np.maximum(gap_below, gap_above)
        print(f"{len(r)} grains; closest approach to the charge {np.min(to_charge - r) * 1e3:.2f} mm, "
              f"to the plate {np.min(to_plate - r) * 1e3:.2f} mm")
        self.assertGreater(len(r), 1000)
        self.assertTrue(np.all(to_charge >= r))
        self.assertTrue(np.all(to_plate >= r))
        # The carving leaves nothing more than it must: grains within a lattice pitch of both.
        self.assertLess(np.min(to_charge - r), 0.02)
        self.assertLess(np.min(to_plate - r), 0.02)

    def test_without_carve_the_bodies_overlap(self):
        work = scratch("carve_missing")
        (work / "case.toml").write_text(scenario(carve=None))
        proc = crater("check", work / "case.toml", check=False)
        self.assertEqual(proc.returncode, 2)
        self.assertIn("bodies overlap", proc.stderr)

    def test_unknown_and_self_carving_are_refused(self):
        work = scratch("carve_bad")
        for bad, text in ((["charge", "rock"], "no part named 'rock'"),
                          (["soil"], "cannot carve itself")):
            (work / "case.toml").write_text(scenario(carve=bad))
            proc = crater("check", work / "case.toml", check=False)
            self.assertEqual(proc.returncode, 2, proc.stderr)
            self.assertIn(text, proc.stderr)
            self.assertIn("parts[2].carve", proc.stderr)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
