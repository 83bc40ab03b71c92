# ctest-timeout: 600
# ctest-cost: 18
"""The grains' stress (the VTU field `stress_pa`, docs/theory.md §3): each grain's Love-Weber
stress sigma_i = (1/V_i) sum_c sym((x_c - x_i) (x) f_c) over its contacts, tension positive,
V_i = pi r_i^2 (x 1 m) / phi its share of the bulk, so that sum_i sigma_i V_i / V over the
grains of a region is the region's mean stress.

- A bed at rest under gravity (issue 24: "the vertical stress at mid-depth within 5 % of
  rho_bulk g z"): the bed of test_dense_bed.py's at-rest case (dense_bed_case.py: 2D disks of
  sand, radii 4-10 mm, filling a 0.6 m x 0.3 m box, rigid walls left, right and bottom,
  relaxed, run for 10 ms). The grains whose centres lie 0.12-0.18 m below the surface and at
  least 0.1 m from the side walls (clear of most of their friction, which could hold part of
  the weight: Janssen's effect) give sigma_yy = sum sigma_yy,i V_i / V_band,
  V_band = 0.06 m x 0.4 m x 1 m, within 5 % of -rho_bulk g z_mid in every frame (0 to 10 ms),
  z_mid = 0.15 m and rho_bulk the part's `bulk_density_kg_m3` (summary.json). The surface is
  the region's top, y = 0: rho_bulk is the grains' mass over the region's volume, so
  rho_bulk g z is the weight above depth z of a column of the region; the highest grain's top
  is 0.2 mm below it (0.13 % of z_mid). Measured: -2320.0 Pa expected, +1.15 % at t = 0 (after
  the relaxation), down to +0.24 % at 7 ms and +0.59 % (-2333.7 Pa) at 10 ms, the bed's slow
  vertical oscillation. The bed is laid geometrically and relaxed: the walls' friction is
  hardly mobilised, the band away from the walls and the whole width read nearly the same
  (+0.83 % at 10 ms), and with frictionless walls the band reads +1.7 % (the scatter of bands
  this narrow: 0.05 m bands between 0.05 and 0.25 m deep read -4.7 % to +5.7 %).
- The floor carries the bed's weight (no wall reactions are written, so through the stress):
  for a bed in equilibrium on its floor, sum_i sigma_yy,i V_i over every grain is -W h, W the
  bed's weight and h its centre of mass's height above the floor (the virial of the contact
  forces: the pairs' terms cancel into the branch vectors, the floor's give y_floor W, gravity
  -W y_cm), less what the side walls' friction carries and the bed's residual motion; within
  2 % in every frame. Measured: +0.89 % at t = 0 to +0.28 % at 7 ms, +0.52 % at 10 ms, with the
  band's oscillation (frictionless walls: -0.14 % at 10 ms). Without the floor contacts' moments
  the sum would be about 5 % short (their arms, a grain's radius, over h = 0.15 m).
- Two disks pressed together and one on the floor, at t = 0 (linear springs, at rest: the
  forces k_n delta exactly): sigma_xx = -(r - delta/2) k_n delta / V of each of the pair and
  sigma_yy = -(r - delta) k_n delta / V of the one on the floor, everything else zero, to
  rounding.
"""
import json
import math
import sys
import unittest

import numpy as np

from crater_test import crater, read_pvd, read_vtu, scratch
from dense_bed_case import BOX, GRAVITY, bed_alone
from scenario_blocks import (box, compose_scenario, domain, output, part, particle,
                             write_scenario)

XX, YY, ZZ, XY, YZ, XZ = range(6)  # VTK's order of a symmetric tensor's components


def soil_diagnostics(out):
    with open(out / "summary.json") as f:
        return json.load(f)["parts"][0]["diagnostics"]


class BedAtRest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        work = scratch("bed_stress")
        write_scenario(work / "case.toml", bed_alone(work))
        out = work / "out"
        crater("run", str(work / "case.toml"), "--out", str(out), "--force", "--quiet")
        cls.diag = soil_diagnostics(out)
        # Every frame (t = 0 to 10 ms, 1 ms apart): points, fields, V_i [m^3 per m].
        cls.frames = []
        for t, name in read_pvd(out / "soil.pvd"):
            pts, f, _, _ = read_vtu(out / name)
            r = f["radius"]
            cls.frames.append((t, pts, f, math.pi * r * r / cls.diag["solid_fraction"]))

    def test_tensor_layout(self):
        for t, pts, f, _ in self.frames:
            self.assertEqual(f["stress_pa"].shape, (len(pts), 6), t)
            for k in (ZZ, YZ, XZ):
                self.assertEqual(float(np.abs(f["stress_pa"][:, k]).max()), 0.0, t)

    def test_vertical_stress_at_mid_depth(self):
        top, width = BOX[1][1], BOX[1][0] - BOX[0][0]
        z0, z1, clear = 0.12, 0.18, 0.1
        v_band = (z1 - z0) * (width - 2 * clear)
        expected = -self.diag["bulk_density_kg_m3"] * GRAVITY * 0.5 * (z0 + z1)
        self.assertEqual(len(self.frames), 11)
        for t, pts, f, volume in self.frames:
            x, y = pts[:, 0], pts[:, 1]
            band = (y <= top - z0) & (y > top - z1) & (x >= clear) & (x <= width - clear)
            measured = float(np.sum(f["stress_pa"][band, YY] * volume[band])) / v_band
            error = measured / expected - 1
            print(f"t = {t:.3f} s, mid-depth band ({int(np.sum(band))} grains): sigma_yy = "
                  f"{measured:.1f} Pa, -rho_bulk g z = {expected:.1f} Pa, error "
                  f"{100 * error:+.2f} %")
            self.assertGreater(int(np.sum(band)), 50)
            self.assertLess(abs(error), 0.05, t)

    def test_floor_carries_the_weight(self):
        for t, pts, f, volume in self.frames:
            m, y = f["mass"], pts[:, 1]
            weight = float(np.sum(m)) * GRAVITY
            height = float(np.sum(m * (y - BOX[0][1]))) / float(np.sum(m))
            total = float(np.sum(f["stress_pa"][:, YY] * volume))
            error = total / (-weight * height) - 1
            print(f"t = {t:.3f} s, whole bed: sum sigma_yy V = {total:.2f} N m, -W h = "
                  f"{-weight * height:.2f} N m, error {100 * error:+.2f} %")
            self.assertLess(abs(error), 0.02, t)


# Two disks pressed together along x and a third on the floor, at rest (2D, per metre).
KN = 1.0e6  # N/m
R1, R2, R3 = 0.004, 0.006, 0.005
DELTA, DELTA_FLOOR = 1.0e-5, 2.0e-5
FLOOR = -0.02
GRAINS = [particle([-0.02, 0.0], R1), particle([-0.02 + R1 + R2 - DELTA, 0.0], R2),
          particle([0.02, FLOOR + R3 - DELTA_FLOOR], R3)]
REGION = ([-0.03, FLOOR], [0.03, 0.01])


def pressed_grains():
    glass = {"name": "glass", "model": "granular", "rho0_kg_m3": 2500.0,
             "shear_modulus_pa": 1.0e9, "poisson_ratio": 0.25, "friction": 0.5,
             "restitution": 0.5}
    return compose_scenario(
        "pressed-grains", 2, 1e-6, domain=domain([-0.04, FLOOR], [0.04, 0.04], [0.0, 0.0]),
        output=output(1e-6), materials=[glass],
        parts=[part("grains", "dem", "glass", 0.01, box(*REGION),
                    dem={"contact": "linear_spring", "normal_stiffness_n_m": KN,
                         "walls": ["bottom"]},
                    particles=GRAINS)])


class PressedGrains(unittest.TestCase):
    def test_stress_of_the_contact_forces_at_t0(self):
        work = scratch("bed_stress_pressed")
        write_scenario(work / "case.toml", pressed_grains())
        out = work / "out"
        crater("run", str(work / "case.toml"), "--out", str(out), "--force", "--quiet")
        phi = soil_diagnostics(out)["solid_fraction"]
        area = (REGION[1][0] - REGION[0][0]) * (REGION[1][1] - REGION[0][1])
        self.assertAlmostEqual(phi, math.pi * (R1**2 + R2**2 + R3**2) / area, delta=1e-12)
        _, name = read_pvd(out / "grains.pvd")[0]
        pts, f, _, _ = read_vtu(out / name)
        sigma = f["stress_pa"][np.argsort(f["id"])]
        expected = np.zeros((3, 6))
        for k, (r, arm, overlap) in enumerate([(R1, R1 - DELTA / 2, DELTA),
                                               (R2, R2 - DELTA / 2, DELTA),
                                               (R3, R3 - DELTA_FLOOR, DELTA_FLOOR)]):
            expected[k, XX if k < 2 else YY] = -arm * KN * overlap * phi / (math.pi * r * r)
        print(f"pressed grains: sigma = {sigma[:, [XX, YY, XY]].tolist()} Pa")
        # The overlaps (1e-5 m) are differences of 1e-2 m positions: rounding of those is
        # 1e-13 of the overlap; the zeros are exact (the pair lies along x, the floor along y).
        np.testing.assert_allclose(sigma, expected, rtol=1e-9, atol=0)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
