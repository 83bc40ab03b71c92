# ctest-labels: slow
# ctest-timeout: 1800
"""Convergence of the Sod shock tube (set-up, reference and error measure of test_sod.py) over
dx = 1/200, 1/400, 1/800, 1/1600.

Tolerances:
- the L1 density error decreases at every halving of dx;
- observed order log2(E(dx) / E(dx/2)) >= 0.5 for every halving. Half an order is the floor
  for first-order treatment of discontinuities: a contact smeared by first-order diffusion
  spreads like sqrt(dx t), costing O(dx^1/2) in L1, a shock held to a few dx costs O(dx);
  SPH's Lagrangian contact does not diffuse, so the order should be nearer 1.
"""
import math
import sys
import unittest

from sod_case import run_case

SPACINGS = [1 / 200, 1 / 400, 1 / 800, 1 / 1600]
MIN_ORDER = 0.5


class SodConvergence(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.runs = [run_case(dx, f"conv{round(1 / dx)}") for dx in SPACINGS]
        for r in cls.runs:
            print(f"sod dx = 1/{1 / r['dx']:.0f}: L1 {100 * r['l1']:.4f} %, "
                  f"{r['summary']['steps']} steps, {r['wall_s']:.1f} s", file=sys.stderr)

    def test_order(self):
        for a, b in zip(self.runs, self.runs[1:]):
            with self.subTest(dx=f"1/{1 / a['dx']:.0f} -> 1/{1 / b['dx']:.0f}"):
                self.assertLess(b["l1"], a["l1"])
                order = math.log2(a["l1"] / b["l1"])
                print(f"  order 1/{1 / a['dx']:.0f} -> 1/{1 / b['dx']:.0f}: {order:.3f}",
                      file=sys.stderr)
                self.assertGreaterEqual(order, MIN_ORDER)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
