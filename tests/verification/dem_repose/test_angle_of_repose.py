# ctest-cost: 28
"""Angle of repose of a poured heap of spheres for mu = 0.84 (the paper's sand friction,
tan 40 degrees) against the DEM correlation of Zhou, Xu, Yu & Zulli 2002 (Powder Technol. 125,
45-54, Eq. 5; setup, reference and conversion of the rolling friction in repose_case.py).

Reference: Zhou's Eq. 5 for mu_s,pp = 0.84, mu_s,pw = 0.6, mu_r = 0.02 (0.0475 / 0.095 mm),
d = 9.5 mm: 23.4 degrees. Tolerance: +-4 degrees, twice the 2-degree standard deviation of
Zhou's fit.

EXPECTED FAILURE (the gap): crater's poured heap stands at 17.8 degrees (2026-11-24, after the
DEM pair loop's force sums changed order; 18.5 before, 17.5 with another seed), 5-6 degrees
below the correlation. Its trend with mu is right and about parallel to
Zhou's (9.8 / 14.2 / 18.5 degrees at mu = 0.2 / 0.5 / 0.84 against 15.9 / 20.4 / 23.4;
test_angle_of_repose_sweep.py). The cause is not settled; ruled out so far:
- the pour's restarts (each batch is a new run, which drops every contact's springs): three
  more restarts of the finished heap with nothing added lowered it by 0.15, 0.05 and 0.03
  degrees;
- the formation (2026-11-24): a heap drained from a plate as Zhou's (16,038 spheres settled
  in a walled 30 d x 30 d box, then the side walls taken away and the spheres beyond the
  plate's edges removed, outflow = "remove"; a pyramid of four flanks, about 2,400 spheres
  left; drained_heap.py) has flanks of 16.8 and 18.7 degrees, 17.7 on average, as the cone;
- the rolling spring's softness: ten times stiffer (k_n = 2e4 N/m), 17.0 degrees;
- the rolling model's form (measured with a temporary build, not kept): a constant torque
  against the relative rolling (Ai et al.'s model A, LIGGGHTS cdt) gave 12.4 degrees on the
  drained heap, and Zhou's own form (each sphere's torque against its own spin) 14.5, both
  lower than the spring;
- crater's implementation of the model (2026-11-25): LIGGGHTS, given the same drained heap
  (lattice, springs, dashpots, friction, model C rolling resistance as its `epsd`, walls,
  stages, step), stands at 17.4 degrees (mean of three seeds) against crater's 17.2;
  test_drained_heap_vs_liggghts.py checks it. The gap lies between the model with these
  parameters and Zhou's correlation as quoted, whatever code runs it;
- the heap's shape (2026-11-25, LIGGGHTS): a ridge, periodic along z with no front and rear
  walls (run.py --ridge), stands at 18.7 and 18.2 degrees (9 and 4 rows deep, mean of three
  seeds), a degree above the pyramid.
The angle depends more steeply on mu_r than Zhou's fit (mu_r = 0.1: 28 degrees, Eq. 5
converted 31.4; mu_r = 0: about 2), and monosized spheres (r = 5 mm) stand at about 14 degrees.
The range check runs and is expected to fail (unittest.expectedFailure): if it
starts passing, the unexpected success fails the test and this note must go.
"""
import sys
import unittest

from repose_case import pour, zhou_angle

MU = 0.84
TOLERANCE_DEG = 4.0


class AngleOfRepose(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.angle, cls.apex, cls.rings, cls.grains, cls.kinetic = pour(MU)
        cls.reference = zhou_angle(MU)
        print(f"mu = {MU}: poured heap {cls.angle:.1f} deg ({cls.rings} rings fitted, apex "
              f"{cls.apex * 100:.1f} cm, {cls.grains} spheres, kinetic energy at the end "
              f"{cls.kinetic:.1e} J); Zhou et al. 2002 Eq. 5: {cls.reference:.1f} +- "
              f"{TOLERANCE_DEG} deg", file=sys.stderr)

    def test_heap_formed(self):
        self.assertEqual(self.grains, 2400)
        self.assertGreaterEqual(self.rings, 6)
        self.assertGreater(self.angle, 10.0)

    # The gap (module docstring): crater's heap is about 5 degrees below Zhou's correlation.
    @unittest.expectedFailure
    def test_in_published_range(self):
        self.assertLess(abs(self.angle - self.reference), TOLERANCE_DEG)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
