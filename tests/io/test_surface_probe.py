"""The ground-surface probe ignores material in flight (issue 24): a flat bed of grains with a
dense clump of grains above it, thrown upwards. The clump fills whole cells of the probe, so a
measure that takes the highest dense cells for the ground would put the surface at the clump;
the ground is what stands on the floor, up to the first gap of more than three grain diameters.
Every column's surface, at t = 0 and at the end, must be the bed's: within two grain diameters
of its top (y = 0), never higher; the crater depth and settlement stay within a grain.

A stream of ejecta leaves no gap: the second case puts, on the same bed, a column of grains
(a 0.2 m wide, 0.6 m high square lattice of pitch 2.2 r from y = 0 up, 0.83 of the bed's
fill), all moving up at 3 m/s. Its grains touch nothing (they move together, apart) and fly fast
enough to rise more than their diameter (|v|^2 > 4 g r): they are in flight, not ground, and
the columns under the stream keep the bed's surface (the gap rule alone puts it at the stream's
top, 0.6 m)."""
import csv
import json
import sys
import unittest

import numpy as np

from crater_test import crater, scratch
from scenario_blocks import (SAND, box, compose_scenario, domain, output, part, particle,
                             write_scenario)

R = 0.01  # grain radius [m]


def grains(stream=False):
    """A bed 1 m wide and 0.3 m deep on a square lattice of pitch 2R (top at y = 0), and a
    0.2 m x 0.16 m clump of the same lattice between y = 0.3 and 0.46, at 3 m/s upwards; or
    (stream) a 0.2 m x 0.6 m column of grains standing on the bed, from y = 0 up, at 3 m/s."""
    bed = [particle([R + 2 * R * i, -R - 2 * R * j], R) for i in range(50) for j in range(15)]
    if stream:  # pitch 2.2 R: 0.83 of the bed's fill, dense for the probe, grains apart
        clump = [particle([0.4 + 1.1 * R + 2.2 * R * i, 1.1 * R + 2.2 * R * j], R, [0.0, 3.0])
                 for i in range(9) for j in range(27)]
        return bed + clump
    clump = [particle([0.4 + R + 2 * R * i, 0.3 + R + 2 * R * j], R, [0.0, 3.0])
             for i in range(10) for j in range(8)]
    return bed + clump


class SurfaceIgnoresMaterialInFlight(unittest.TestCase):
    STREAM = False

    @classmethod
    def setUpClass(cls):
        work = scratch("surface_probe_stream" if cls.STREAM else "surface_probe_flight")
        scenario = compose_scenario(
            "surface-in-flight", 2, 2e-3, domain=domain([0.0, -0.3], [1.0, 1.0], [0.0, -9.81]),
            output=output(1e-3), materials=[SAND],
            parts=[part("soil", "dem", "sand", 2 * R, box([0.0, -0.3], [1.0, 0.0]),
                        dem={"radius_min_m": R, "radius_max_m": R,
                             "walls": ["left", "right", "bottom"]},
                        particles=grains(cls.STREAM))],
            probes={"soil": "soil"})
        write_scenario(work / "case.toml", scenario)
        cls.out = work / "out"
        crater("run", str(work / "case.toml"), "--out", str(cls.out), "--force", "--quiet")
        with open(cls.out / "summary.json") as f:
            cls.m = json.load(f)["metrics"]
        with open(cls.out / "surface_profile.csv") as f:
            cls.rows = list(csv.DictReader(f))

    def test_surface_is_the_bed_not_the_clump(self):
        for key in ("surface_initial_m", "surface_m"):
            y = np.array([float(r[key]) for r in self.rows])
            self.assertTrue(np.isfinite(y).all(), key)
            # Never above the bed's top (y = 0) + 2 d; not below it by more than 2 d either.
            self.assertLessEqual(y.max(), 4 * R, key)
            self.assertGreaterEqual(y.min(), -4 * R, key)

    def test_no_crater_no_settlement(self):
        # The bed at rest on its floor: no column moves by a grain radius.
        self.assertEqual(self.m["crater_depth_m"], 0.0)
        self.assertLess(abs(self.m["surface_settlement_max_m"]), R)


class SurfaceIgnoresAStreamInFlight(SurfaceIgnoresMaterialInFlight):
    STREAM = True


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
