"""`carve`: a soil box holding a charge and a plate. The DEM grains and the SPH particles of a
part that carves others are not laid where they would reach into those parts' regions, and
the carved parts may overlap the carving part's region (the overlap check lets them). The
laid grains are read back from the first VTU frame with VTK's reader."""
import sys
import unittest

import numpy as np

from crater_test import crater, read_vtu, run_scenario, scratch

SCENARIO = """
[scenario]
name = "carve"
description = "a soil box carved by a charge and a plate"
dimension = 2
end_time_s = 1e-6
[time]
max_steps = 1
[domain]
min_m = [0.0, -1.0]
max_m = [1.0, 0.5]
[[materials]]
name = "tnt"
model = "jwl"
rho0_kg_m3 = 1630.0
a_pa = 373.8e9
b_pa = 3.747e9
r1 = 4.15
r2 = 0.90
omega = 0.35
e0_j_m3 = 6.0e9
d_cj_m_s = 6930.0
[[materials]]
name = "steel"
model = "elastic"
rho0_kg_m3 = 7850
youngs_modulus_pa = 200e9
poisson_ratio = 0.3
[[materials]]
name = "sand"
model = "granular"
rho0_kg_m3 = 1920
shear_modulus_pa = 29e9
poisson_ratio = 0.2
friction = 0.84
restitution = 0.5
[[parts]]
name = "charge"
method = "sph"
material = "tnt"
spacing_m = 0.02
region = { type = "disk", center_m = [0.5, -0.6], radius_m = 0.15 }
[[parts]]
name = "plate"
method = "fem"
material = "steel"
spacing_m = 0.02
region = { type = "box", min_m = [0.0, -0.4], max_m = [1.0, -0.3] }
[[parts]]
name = "soil"
method = "dem"
material = "sand"
spacing_m = 0.02
region = { type = "box", min_m = [0.0, -1.0], max_m = [1.0, 0.0] }
carve = ["charge", "plate"]
[parts.dem]
radius_min_m = 0.007
radius_max_m = 0.009
"""


class Carve(unittest.TestCase):
    def test_grains_leave_the_carved_regions_empty(self):
        work = scratch("carve")
        (work / "case.toml").write_text(SCENARIO)
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
        (work / "case.toml").write_text(SCENARIO.replace('carve = ["charge", "plate"]\n', ""))
        proc = crater("check", work / "case.toml", check=False)
        self.assertEqual(proc.returncode, 2)
        self.assertIn("bodies overlap", proc.stderr)

    def test_unknown_and_self_carving_are_refused(self):
        work = scratch("carve_bad")
        for bad, text in (('carve = ["charge", "rock"]', "no part named 'rock'"),
                          ('carve = ["soil"]', "cannot carve itself")):
            (work / "case.toml").write_text(SCENARIO.replace('carve = ["charge", "plate"]', bad))
            proc = crater("check", work / "case.toml", check=False)
            self.assertEqual(proc.returncode, 2, proc.stderr)
            self.assertIn(text, proc.stderr)
            self.assertIn("parts[2].carve", proc.stderr)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
