"""A disk rolling down a slope without slipping: the static tangential spring (the contact's
history) must hold the contact point still through every neighbour-list rebuild and re-sort.

Gravity tilted by theta = 20 deg on a flat floor is a slope. For a disk (I = m r^2/2) rolling
without slip the analytic solution is a = (2/3) g sin(theta), omega = -v/r, needing a friction
force m g sin(theta)/3, well under mu m g cos(theta) for mu = 0.5 (sticking). Fast grains
elsewhere in the box force neighbour-list rebuilds and re-sorting every few dozen steps; if a
rebuild lost the spring, the disk would slip and v + omega r would jump.

Sensitivity, measured 2026-11-22 by clearing the histories at every rebuild on purpose: the
slip rose from 6e-6 to 1.8e-4 m/s (the bound is 5.6e-5) and the pyramid's bottom disks crept
9.3e-6 m apart instead of 4e-11 m (the bound is 1e-6 m): both tests fail without history.

Checks: v(t_end) within 1 % of (2/3) g sin(theta) t (after the short settling of the initial
overlap), and the slip speed |v + omega r| below 1e-3 of v over the run's last half. The run
must also have rebuilt the lists many times (checked through the fast grains' travel).
"""
import math
import sys
import unittest

import numpy as np

from crater_test import read_pvd, read_vtu, run_scenario, scratch
from scenario_blocks import (SAND, box, compose_scenario, domain, material, output, part,
                             particle, scenario_text)

G_MAG, THETA, R = 9.81, math.radians(20.0), 0.0025
CREEP_TOL = 1e-6  # [m], see StaticPyramid


def disks_on_floor(name, grains, interval, gravity, wall_friction=None):
    """A 2D box of sand (friction 0.5) with a frictional floor and disks (x, y, v_x) of radius
    R placed in it."""
    return scenario_text(compose_scenario(
        name, 2, 0.05, output=output(interval),
        domain=domain([0.0, 0.0], [0.4, 0.05], gravity=gravity),
        materials=[material(SAND, friction=0.5)],
        parts=[part("grains", "dem", "sand", 0.005, box([0.0, 0.0], [0.4, 0.05]),
                    dem={"walls": ["bottom"], "wall_friction": wall_friction,
                         "wall_restitution": None if wall_friction is None else 0.5},
                    particles=[particle([x, y], R, [v, 0.0]) for x, y, v in grains])]))


def scenario():
    gx, gy = G_MAG * math.sin(THETA), -G_MAG * math.cos(THETA)
    # The rolling disk sits on the floor (a hair of overlap); three fast grains roll the other
    # way far to its right, with room to travel.
    y0 = R - 1e-7
    grains = [(0.02, y0, 0.0)] + [(0.30 + 0.02 * k, y0, -2.0) for k in range(3)]
    return disks_on_floor("rolling-history", grains, 0.025, [gx, gy], wall_friction=0.5)


def pyramid_scenario():
    """Three touching disks stacked on a frictional floor (two below, one in their groove):
    static, the floor's friction springs holding the bottom disks against the top one's push
    (0.29 of its weight each side, against 0.5 x 1.5 weights available). Fast grains far
    away force list rebuilds and re-sorts."""
    y0 = R - 1e-7
    top = (0.05, y0 + 2 * R * math.sin(math.radians(60.0)))
    grains = [(0.05 - R, y0, 0.0), (0.05 + R, y0, 0.0), (top[0], top[1], 0.0)]
    grains += [(0.30 + 0.02 * k, y0, -2.0) for k in range(3)]
    return disks_on_floor("pyramid-history", grains, 0.01, [0.0, -9.81])


class StaticPyramid(unittest.TestCase):
    def test_bottom_disks_hold(self):
        d = scratch("dem_pyramid")
        path = d / "case.toml"
        path.write_text(pyramid_scenario())
        run_scenario(path, d / "out", threads=1)
        frames = [read_vtu(d / "out" / f) for _, f in read_pvd(d / "out" / "grains.pvd")]
        def gap(k):
            pts, arrays, _, _ = frames[k]
            a = pts[arrays["id"] == 0][0]
            b = pts[arrays["id"] == 1][0]
            return b[0] - a[0]
        creep = [gap(k) - gap(1) for k in range(1, len(frames))]
        print(f"pyramid: bottom gap creep over the run {max(map(abs, creep)):.3e} m",
              file=sys.stderr)
        self.assertLess(max(map(abs, creep)), CREEP_TOL)


class RollingWithoutSlip(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        d = scratch("dem_rolling")
        path = d / "case.toml"
        path.write_text(scenario())
        cls.summary = run_scenario(path, d / "out", threads=1)
        cls.frames = [(t, read_vtu(d / "out" / f)) for t, f in read_pvd(d / "out" / "grains.pvd")]

    def disk(self, k):
        t, (pts, arrays, _, _) = self.frames[k]
        i = int(np.where(arrays["id"] == 0)[0][0])
        return t, pts[i], arrays["velocity"][i], float(arrays["angular_velocity"][i])

    def test_acceleration_is_two_thirds_g_sin_theta(self):
        t, _, v, _ = self.disk(-1)
        expected = 2.0 / 3.0 * G_MAG * math.sin(THETA) * t
        print(f"rolling disk: v = {v[0]:.6f} m/s at t = {t} s, analytic {expected:.6f} "
              f"({100 * (v[0] / expected - 1):+.3f} %)", file=sys.stderr)
        self.assertLessEqual(abs(v[0] / expected - 1), 0.01)

    def test_no_slip(self):
        for k in (1, 2):
            t, _, v, w = self.disk(k)
            slip = abs(v[0] + w * R)
            print(f"t = {t}: v = {v[0]:.6f}, -omega r = {-w * R:.6f}, slip {slip:.2e} m/s",
                  file=sys.stderr)
            self.assertLess(slip, 1e-3 * abs(v[0]))

    def test_lists_were_rebuilt(self):
        # The fast grains travel ~0.1 m, far more than the list margin (0.3 x 2 r_max), so
        # the lists were rebuilt and re-sorted many times.
        _, (pts, arrays, _, _) = self.frames[-1]
        fast = arrays["id"] > 0
        self.assertGreater(np.abs(pts[fast, 0] - 0.32).max(), 50 * 0.3 * 2 * R)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
