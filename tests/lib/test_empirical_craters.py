"""Checks of tests/lib/empirical_craters.py (run: /usr/bin/python3 -m unittest tests/lib/test_empirical_craters.py).

None of the sources could be read for a worked example (docs/empirical-craters.md), so the
checks are the relations' definitions, their scaling with W, and unit consistency.
"""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402

import empirical_craters as ec  # noqa: E402

CBRT2 = 2.0 ** (1.0 / 3.0)


class ScaledDepth(unittest.TestCase):
    def test_case_value(self):
        # 1.2 m / 1814^(1/3) kg^(1/3); 1814^(1/3) = 12.196. Tolerance 1e-4 m/kg^(1/3).
        self.assertAlmostEqual(ec.scaled_depth(1814.0, 1.2), 0.09839, delta=1e-4)

    def test_us_units_agree(self):
        # The same charge in lb and ft: 1814 kg = 3999 lb, 1.2 m = 3.937 ft. Relative 1e-9.
        W_lb = 1814.0 / ec.KG_PER_LB
        d_ft = 1.2 / ec.M_PER_FT
        lam_ft_lb = d_ft / W_lb ** (1.0 / 3.0)
        self.assertAlmostEqual(ec.scaled_depth_ft_lb(1814.0, 1.2) / lam_ft_lb, 1.0, places=9)

    def test_conversion_factor(self):
        # 1 m/kg^(1/3) = 2.520 ft/lb^(1/3) (to 1e-3).
        self.assertAlmostEqual(ec.FT_LB_PER_M_KG, 2.520, delta=1e-3)


class KinneyGraham(unittest.TestCase):
    def test_definition(self):
        # D = 0.8 W^(1/3) m for W in kg: 1 kg gives D = 0.8 m, R = 0.4 m (exact, 1e-12).
        R, depth = ec.kinney_graham_surface(1.0)
        self.assertAlmostEqual(2.0 * R, 0.8, places=12)
        self.assertIsNone(depth)

    def test_cube_root_scaling(self):
        # Doubling W multiplies R by 2^(1/3) (relative 1e-12).
        for W in (1.0, 7.0, 1814.0):
            R1, _ = ec.kinney_graham_surface(W)
            R2, _ = ec.kinney_graham_surface(2.0 * W)
            self.assertAlmostEqual(R2 / R1, CBRT2, places=12)

    def test_units(self):
        # The same physical radius from the coefficient in ft/lb^(1/3): 0.4 m/kg^(1/3) =
        # 1.008 ft/lb^(1/3); W = 4000 lb. Relative 1e-9.
        W_lb = 4000.0
        R_ft = 0.4 * ec.FT_LB_PER_M_KG * W_lb ** (1.0 / 3.0)
        R_m, _ = ec.kinney_graham_surface(W_lb * ec.KG_PER_LB)
        self.assertAlmostEqual(R_ft * ec.M_PER_FT / R_m, 1.0, places=9)

    def test_case(self):
        # 0.4 x 1814^(1/3) = 4.878 m (1e-3).
        R, _ = ec.kinney_graham_surface(1814.0, 1.2)
        self.assertAlmostEqual(R, 4.878, delta=1e-3)


class ScaleDimension(unittest.TestCase):
    def test_cube_root(self):
        # m = 3: eight times the charge doubles a dimension (1e-12).
        self.assertAlmostEqual(ec.scale_dimension(1.0, 1.0, 8.0), 2.0, places=12)

    def test_exponent_3_4(self):
        # m = 3.4 (CASTLE-era fit for TNT in Nevada soil): 1000 x the charge gives 1000^(1/3.4)
        # = 7.62 (1e-2), 24 % less than cube-root's 10.
        r = ec.scale_dimension(1.0, 1.0, 1000.0, m=3.4)
        self.assertAlmostEqual(r, 7.62, delta=1e-2)
        self.assertLess(r, ec.scale_dimension(1.0, 1.0, 1000.0))


class Band(unittest.TestCase):
    def test_default_band_excludes_unverified(self):
        b = ec.band()
        self.assertTrue(b["relations"]["kinney_graham_1985_surface"]["in_band"])
        self.assertFalse(b["relations"]["brief_0.87_surface"]["in_band"])
        R_kg, _ = ec.kinney_graham_surface(1814.0)
        self.assertAlmostEqual(b["radius_min_m"], R_kg, places=12)
        self.assertAlmostEqual(b["radius_max_m"], R_kg, places=12)
        self.assertIsNone(b["depth_min_m"])  # no relation read here gives a depth

    def test_all_statuses(self):
        b = ec.band(statuses=("verified", "secondary", "unverified"))
        radii = [r["radius_m"] for r in b["relations"].values()]
        self.assertAlmostEqual(b["radius_min_m"], min(radii), places=12)
        self.assertAlmostEqual(b["radius_max_m"], max(radii), places=12)
        self.assertLessEqual(b["radius_min_m"], b["radius_max_m"])

    def test_every_relation_scales_as_cube_root(self):
        for name, rel in ec.RELATIONS.items():
            R1, _ = rel["function"](100.0, 0.0)
            R2, _ = rel["function"](200.0, 0.0)
            self.assertAlmostEqual(R2 / R1, CBRT2, places=12, msg=name)

    def test_statuses_are_known(self):
        for name, rel in ec.RELATIONS.items():
            self.assertIn(rel["status"], ("verified", "secondary", "unverified"), msg=name)
            self.assertTrue(rel["function"].__doc__, msg=name)

    def test_arrays(self):
        R, _ = ec.kinney_graham_surface(np.array([1.0, 8.0]))
        np.testing.assert_allclose(R, [0.4, 0.8], rtol=1e-12)


if __name__ == "__main__":
    unittest.main()
