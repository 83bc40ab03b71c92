# ctest-labels: slow
# ctest-timeout: 1800
"""The dam break of test_dam_break.py (Martin & Moyce 1952, n^2 = 2, a = 2.25 in; same set-up,
reference, tolerances and checks) at twice the resolution, dx = a/40 (3200 particles):
surge front within 10 % of the measurements for T <= 2.5, no particle crossing a wall."""
import sys
import unittest

from dam_break_case import A, run_case
from test_dam_break import DamBreakChecks, figure, report


class DamBreakFine(DamBreakChecks, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.result = run_case(A / 40, "a40")
        report(cls.result)
        figure(cls.result, "sph_dam_break_fine")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
