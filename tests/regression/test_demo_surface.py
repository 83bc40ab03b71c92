# ctest-timeout: 1500
# ctest-fixtures: bundled_bed
# ctest-cost: 115
"""The surface probe on `make run`'s result (paper-20cm at its demo level, to 10 ms; issue 24):
the ground it reports in every column is never higher than the top of that column's settled
grains plus two grain diameters. A settled column is the issue's: the grains standing on the
bed from below, without a vertical gap of more than three largest diameters (what is above such
a gap is in flight). It is measured here from the last soil frame, read with VTK, with its own
binning (all grains whose centre is within the probe's column), independently of the probe's
cells and packing-fraction rule. Also: the run completes, its energy balance is within 1 %
(0.55 % measured, 2026-11-26), and the crater reaches the columns the blast emptied.

On one thread (the result is the 2-thread `make run`'s, bit for bit: the determinism tests):
about 112 s beside another test, against 89 s on both cores that ctest then keeps from every
other test. The bed is settled before (tests/CMakeLists.txt, fixture.bundled_bed)."""
import csv
import sys
import unittest

import numpy as np

from crater_test import read_pvd, read_vtu, run_scenario, scratch


def settled_column_tops(out, centres, half_width, floor):
    """Per column centre: the highest grain centre of the stack that stands on the floor (the
    domain's bottom) without a gap of more than 3 d_max, or the floor if none does; and the
    largest grain diameter of the frame."""
    frames = read_pvd(out / "soil.pvd")
    p, a, _, t = read_vtu(out / frames[-1][1])
    d_max = 2 * float(a["radius"].max())
    tops = []
    for x in centres:
        top = floor
        for y in np.sort(p[np.abs(p[:, 0] - x) <= half_width, 1]):
            if y - top > 3 * d_max:
                break
            top = y
        tops.append(top)
    return np.array(tops), d_max, t


class DemoSurface(unittest.TestCase):
    def test_probe_below_settled_columns(self):
        out = scratch("demo_surface")
        summary = run_scenario("paper-20cm", out, threads=1, timeout=1400)
        self.assertEqual(summary["status"], "completed")
        self.assertLess(abs(summary["energy"]["balance_error"]), 0.01)
        with open(out / "surface_profile.csv") as f:
            rows = list(csv.DictReader(f))
        x = np.array([float(r["x_m"]) for r in rows])
        surface = np.array([float(r["surface_m"]) for r in rows])
        initial = np.array([float(r["surface_initial_m"]) for r in rows])
        floor = -2.0  # the domain's bottom (scenarios/paper-20cm.toml)
        tops, d_max, t = settled_column_tops(out, x, 0.5 * (x[1] - x[0]), floor)
        self.assertAlmostEqual(t, 1e-2, delta=1e-9)
        excess = surface - (tops + 2 * d_max)
        for xi, s, top, e in zip(x, surface, tops, excess):
            print(f"x {xi:5.2f} m: probe {s:7.3f} m, settled column's top {top:7.3f} m, "
                  f"excess over top + 2 d {e:+.3f} m", file=sys.stderr)
        # Every column had ground at t = 0 and has a surface now (an emptied column's is the
        # domain's bottom).
        self.assertTrue(np.isfinite(initial).all())
        self.assertTrue(np.isfinite(surface).all())
        self.assertLessEqual(excess.max(), 0.0, "probe above a settled column's top + 2 d")
        # The columns with no settled grains are ground at the floor, and in the crater (they
        # join the deepest column: every one of them dropped by about the bed's depth).
        empty = tops == floor
        self.assertTrue((surface[empty] == floor).all())
        width = x[1] - x[0]
        print(f"{empty.sum()} columns without settled grains; crater radius "
              f"{summary['metrics']['crater_radius_m']} m", file=sys.stderr)
        if empty.any():
            self.assertGreaterEqual(2 * summary["metrics"]["crater_radius_m"] + 1e-9,
                                    empty.sum() * width)

if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
