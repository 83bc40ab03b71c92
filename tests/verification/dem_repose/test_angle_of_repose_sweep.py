# ctest-labels: slow
"""The angle of repose of a poured heap of spheres rises with the sliding friction: mu = 0.2,
0.5, 0.84 (setup in repose_case.py; three pours of about 1.5 minutes each).

Reference for the trend: Zhou, Xu, Yu & Zulli 2002 (Powder Technol. 125, 45-54), whose DEM
heaps rise as mu_s,pp^0.27 (their Eq. 5: 15.9 / 20.4 / 23.4 degrees here). Checked: the angle
rises strictly, by more than 2 degrees per step (the scatter between seeds is about 1 degree).
The level against Zhou's values is the expected failure of test_angle_of_repose.py; the
measured angles are printed (2026-11-22: 9.8 / 14.2 / 18.5 degrees).
"""
import sys
import unittest

from repose_case import pour, zhou_angle

MUS = (0.2, 0.5, 0.84)


class AngleOfReposeSweep(unittest.TestCase):
    def test_rises_with_friction(self):
        angles = []
        for mu in MUS:
            angle, apex, rings, grains, kinetic = pour(mu)
            angles.append(angle)
            print(f"mu = {mu}: poured heap {angle:.1f} deg ({rings} rings, apex "
                  f"{apex * 100:.1f} cm); Zhou et al. 2002 Eq. 5: {zhou_angle(mu):.1f} deg",
                  file=sys.stderr)
        for lower, higher in zip(angles, angles[1:]):
            self.assertGreater(higher - lower, 2.0)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
