# ctest-processors: 2
# ctest-timeout: 600
# ctest-cost: 55
"""A dense bed ([parts.packing] method = "dense", issue 24): 2D disks of sand, radii 4-10 mm
(the paper's coarse range, 2.5:1), filling a 0.6 m x 0.3 m box around a buried steel plate,
then relaxed under gravity with the plate as a fixed body.

- `crater check` reports the bed's solid fraction (grain area over the box less the plate's)
  and bulk density: the fraction is at least 0.80 (issue 24's floor for disks; dense random
  packings of such mixtures reach 0.82-0.85, Feng, Han & Owen 2003), and the bulk density is
  the grain density times the fraction (to 1e-9: one is computed from the other, the test
  recomputes both from the VTU's radii).
- After relaxation every grain is clear of the plate to within 1 % of its radius (it rests on
  the plate, whose region the bed was laid around), and grains lie above the plate as well as
  below it.
- The relaxed bed is the cached packing: a second run reuses it (same file, same grains).
- A bed at rest stays at rest (issue 24): the same box without the plate (dense_bed_case.py),
  relaxed to an unbalanced force of 1e-3 of its weight, then run for 10 ms from the cached
  packing, which carries the contacts' tangential springs. Every grain's speed in every frame
  (1 ms apart) stays below 1 mm/s (measured: 0.17 mm/s; without the springs the bed rang at
  2-5 mm/s). Its stress: test_bed_stress.py.
- The relaxed bed is the same on 1 and 2 threads: the packing files written by two runs into
  two cache directories are byte for byte the same.
"""
import re
import sys
import unittest

import numpy as np

from crater_test import crater, read_pvd, read_vtu, scratch
from dense_bed_case import bed_alone
from scenario_blocks import (SAND, STEEL, box, boundary, compose_scenario, contact, domain,
                             output, part, write_scenario)

PLATE = ([0.15, -0.16], [0.45, -0.14])


def scenario(work):
    return compose_scenario(
        "dense-bed", 2, 2e-4, domain=domain([0.0, -0.3], [0.6, 0.3], [0.0, -9.81]),
        output=output(1e-4), materials=[SAND, STEEL],
        parts=[part("soil", "dem", "sand", 0.02, box([0.0, -0.3], [0.6, 0.0]),
                    dem={"radius_min_m": 0.004, "radius_max_m": 0.01,
                         "walls": ["left", "right", "bottom"]},
                    packing={"method": "dense", "settle": True,
                             "cache_dir": str(work / "cache")},
                    carve=["plate"]),
               part("plate", "fem", "steel", 0.01, box(*PLATE),
                    fem={"boundary": [boundary("fixed", "left"), boundary("fixed", "right")]})],
        contacts=[contact("soil", "plate")])


class DenseBed(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("dense_bed")
        cls.case = cls.work / "case.toml"
        write_scenario(cls.case, scenario(cls.work))
        cls.check = crater("check", str(cls.case)).stdout
        cls.out = cls.work / "out"
        crater("run", str(cls.case), "--out", str(cls.out), "--force", "--quiet")
        _, name = read_pvd(cls.out / "soil.pvd")[0]
        cls.pts, cls.f, _, _ = read_vtu(cls.out / name)

    def test_solid_fraction_and_bulk_density(self):
        m = re.search(r"soil: solid fraction ([0-9.]+) .* bulk density ([0-9.]+) kg/m\^3",
                      self.check)
        self.assertIsNotNone(m, self.check)
        fraction, bulk = float(m.group(1)), float(m.group(2))
        r = self.f["radius"]
        free = 0.6 * 0.3 - (PLATE[1][0] - PLATE[0][0]) * (PLATE[1][1] - PLATE[0][1])
        measured = float(np.sum(np.pi * r * r)) / free
        self.assertAlmostEqual(fraction, measured, delta=1e-4)  # printed to 4 decimals
        self.assertGreaterEqual(measured, 0.80)
        self.assertAlmostEqual(bulk, SAND["rho0_kg_m3"] * measured, delta=0.1)

    def test_grains_rest_on_the_plate_not_in_it(self):
        x, y, r = self.pts[:, 0], self.pts[:, 1], self.f["radius"]
        dx = np.maximum(np.maximum(PLATE[0][0] - x, x - PLATE[1][0]), 0)
        dy = np.maximum(np.maximum(PLATE[0][1] - y, y - PLATE[1][1]), 0)
        gap = np.hypot(dx, dy) - r
        self.assertGreaterEqual((gap / r).min(), -0.01)
        over = (x > PLATE[0][0]) & (x < PLATE[1][0])
        self.assertGreater(int(np.sum(over & (y > PLATE[1][1]))), 100)
        self.assertGreater(int(np.sum(over & (y < PLATE[0][1]))), 100)

    def test_second_run_reuses_the_relaxed_bed(self):
        out2 = self.work / "out2"
        p = crater("run", str(self.case), "--out", str(out2), "--force")
        self.assertIn("reused", p.stderr + p.stdout)
        _, name = read_pvd(out2 / "soil.pvd")[0]
        pts2, f2, _, _ = read_vtu(out2 / name)
        np.testing.assert_array_equal(pts2, self.pts)
        np.testing.assert_array_equal(f2["radius"], self.f["radius"])


class BedAtRestStaysAtRest(unittest.TestCase):
    def test_grains_stay_below_1_mm_per_s_for_10_ms(self):
        work = scratch("dense_bed_at_rest")
        write_scenario(work / "case.toml", bed_alone(work))
        out = work / "out"
        crater("run", str(work / "case.toml"), "--out", str(out), "--force", "--quiet")
        frames = read_pvd(out / "soil.pvd")
        self.assertEqual(len(frames), 11)
        fastest = 0.0
        for _, name in frames:
            _, f, _, _ = read_vtu(out / name)
            fastest = max(fastest, float(np.linalg.norm(f["velocity"], axis=1).max()))
        self.assertLess(fastest, 1e-3)


class RelaxedBedOnOneAndTwoThreads(unittest.TestCase):
    def test_packing_files_are_identical(self):
        work = scratch("dense_bed_threads")
        write_scenario(work / "case.toml", bed_alone(work))
        files = []
        for threads in (1, 2):
            cache = work / f"cache{threads}"
            crater("run", str(work / "case.toml"), "--out", str(work / f"out{threads}"),
                   "--force", "--quiet", "--threads", str(threads),
                   "--set", f"parts.soil.packing.cache_dir={str(cache)!r}",
                   "--set", "scenario.end_time_s=1e-6")
            packs = sorted(cache.glob("*.pack"))
            self.assertEqual(len(packs), 1)
            files.append(packs[0])
        self.assertEqual(files[0].name, files[1].name)
        self.assertEqual(files[0].read_bytes(), files[1].read_bytes())


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
