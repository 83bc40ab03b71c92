# ctest-processors: 2
# ctest-timeout: 600
"""Packing of DEM grains ([parts.packing]): the random packing generator, settling under
gravity, and the reuse of a settled packing.

1. Grading. A 2D random packing (no settling) from a sieve curve, d = 2, 3, 4, 6 mm with mass
   fraction passing 0, 0.3, 0.7, 1, to porosity 0.5 of a 0.3 m x 0.15 m region (about 2,000
   disks). Independent references: the sieve curve itself and the region's volume.
   - mass fraction passing each sieve, recomputed from the radii in the VTU output: within
     0.01 of the curve (each class is filled to its volume within half a grain: < 0.3 %);
   - total grain volume = (1 - n) x region volume within one largest grain;
   - no two grains overlap (brute force over all pairs: gap >= -1e-12 m), all inside the
     region's sides and above its floor.
2. Settling and reuse. 2D disks, r = 4-6 mm, settled under gravity in an open box. The run's
   grains start from the settled packing:
   - static equilibrium, by the settling criterion itself (mean kinetic energy per grain below
     1e-4 m g r of the mean grain): over the following run (50 ms) the mean kinetic energy
     stays below 1e-3 m g r and is back below 1e-4 m g r at the end. (The run restarts without
     the contacts' tangential springs, which the packing file does not keep: friction rebuilds
     them with a small readjustment, measured at about 2e-4 m g r.)
   - the bed rests on the floor: no grain sinks into it deeper than the Hertz overlap of one
     grain carrying the weight of the whole bed (the largest overlap statics allows);
   - a second run with the same inputs reuses the saved packing (summary diagnostics and log),
     on 1 thread instead of 2, and its VTU frames and history.csv are bit-identical to the
     first run's (the first run also starts from the saved file);
   - a packing file with one flipped byte is not used: the run settles again and writes the
     same result; changing an input that shapes the packing (friction) settles anew into a
     second file;
   - a cache_dir that cannot be written (the bundled scenarios of an installed crater sit in a
     read-only share/crater/scenarios; here a plain file stands where the directory should be)
     does not stop the run: the packing goes to the user's cache ($XDG_CACHE_HOME/crater/
     packings), byte for byte the file the writable cache got, with a warning naming both, and
     the next run reuses it from there.
   The grains' shear modulus is 50 MPa instead of sand's 29 GPa: it makes the time step ~25x
   larger and does not change what is checked here.
"""
import itertools
import math
import os
import shutil
import subprocess
import sys
import unittest
from pathlib import Path

import numpy as np

from crater_test import BIN, crater, read_pvd, read_vtu, run_scenario, scratch
from scenario_blocks import (SAND, box, compose_scenario, domain, material, output, part,
                             scenario_text)

SIEVE_D = [0.002, 0.003, 0.004, 0.006]
SIEVE_PASS = [0.0, 0.3, 0.7, 1.0]
REGION = (0.3, 0.15)
POROSITY = 0.5


def soil_box(name, *, end, output_, top, spacing, region_top, shear_modulus_pa, dem, packing):
    """A 2D box of sand under gravity, [0, 0] to `top`, whose part "soil" (the box's lower
    part, up to `region_top`) is packed by [parts.packing]."""
    return scenario_text(compose_scenario(
        name, 2, end, output=output_, domain=domain([0.0, 0.0], top, gravity=[0.0, -9.81]),
        materials=[material(SAND, shear_modulus_pa=shear_modulus_pa)],
        parts=[part("soil", "dem", "sand", spacing, box([0.0, 0.0], region_top), dem=dem,
                    packing=packing)]))


GRADING = soil_box(
    "packing-grading", end=1.0e-7, output_=output(1.0e-7), top=[REGION[0], 0.6], spacing=0.01,
    region_top=REGION, shear_modulus_pa=29e9,
    dem={"walls": ["left", "right", "bottom"], "seed": 7},
    packing={"method": "random", "porosity": POROSITY, "sieve_diameter_m": SIEVE_D,
             "sieve_passing": SIEVE_PASS})

SETTLE = soil_box(
    "packing-settle", end=0.05, output_=output(0.01, history_every=20), top=[0.1, 0.15],
    spacing=0.012, region_top=[0.1, 0.03], shear_modulus_pa=5e7,
    dem={"radius_min_m": 0.004, "radius_max_m": 0.006, "walls": ["left", "right", "bottom"],
         "local_damping": 0.157},
    packing={"method": "random", "porosity": 0.3, "settle": True})


def last_frame(out):
    frames = read_pvd(out / "soil.pvd")
    return read_vtu(out / frames[-1][1])


def all_frames(out):
    return [read_vtu(out / f) for _, f in read_pvd(out / "soil.pvd")]


class Grading(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        d = scratch("dem_packing_grading")
        (d / "grading.toml").write_text(GRADING)
        cls.summary = run_scenario(d / "grading.toml", d / "out")
        pts, arrays, _, _ = read_vtu(d / "out" / read_pvd(d / "out" / "soil.pvd")[0][1])
        cls.x = pts[:, :2]
        cls.r = arrays["radius"]
        print(f"grading: {len(cls.r)} grains", file=sys.stderr)

    def test_grading_curve(self):
        area = math.pi * self.r ** 2
        for dk, fk in zip(SIEVE_D, SIEVE_PASS):
            passing = area[2 * self.r <= dk * (1 + 1e-12)].sum() / area.sum()
            print(f"  sieve {dk * 1e3:.0f} mm: passing {passing:.4f} (curve {fk})",
                  file=sys.stderr)
            with self.subTest(sieve_m=dk):
                self.assertLessEqual(abs(passing - fk), 0.01)

    def test_solid_volume(self):
        solid = (math.pi * self.r ** 2).sum()
        target = (1 - POROSITY) * REGION[0] * REGION[1]
        self.assertLessEqual(abs(solid - target), math.pi * max(self.r) ** 2,
                             f"solid area {solid:.6g} vs {target:.6g} m^2")

    def test_no_overlap_and_inside(self):
        x, r = self.x, self.r
        min_gap = np.inf
        for i in range(len(r) - 1):
            d = np.linalg.norm(x[i + 1:] - x[i], axis=1) - r[i + 1:] - r[i]
            min_gap = min(min_gap, d.min())
        print(f"  smallest gap {min_gap:.3g} m", file=sys.stderr)
        self.assertGreaterEqual(min_gap, -1e-12)
        self.assertTrue(np.all(x[:, 0] - r >= -1e-12) and np.all(x[:, 0] + r <= REGION[0] + 1e-12))
        self.assertTrue(np.all(x[:, 1] - r >= -1e-12))


class SettleAndReuse(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = scratch("dem_packing_settle")
        cls.toml = cls.dir / "settle.toml"
        cls.toml.write_text(SETTLE)
        cls.cache = cls.dir / ".crater-cache"
        cls.first = run_scenario(cls.toml, cls.dir / "first", threads=2)
        cls.files = sorted(cls.cache.glob("soil-*.pack"))
        proc = crater("run", cls.toml, "--out", cls.dir / "second", "--force", "--threads", 1)
        cls.second_log = proc.stdout + proc.stderr
        cls.second = run_summary(cls.dir / "second")

    def diag(self, summary):
        return summary["parts"][0]["diagnostics"]

    def test_first_run_settled_and_saved(self):
        d = self.diag(self.first)
        print(f"settle: {self.first['parts'][0]['count']} grains, {d}", file=sys.stderr)
        self.assertEqual(d["packing_reused"], 0)
        self.assertGreater(d["settle_steps"], 0)
        self.assertEqual(len(self.files), 1, f"cache files: {self.files}")

    def test_bed_is_static(self):
        _, a, _, _ = last_frame(self.dir / "first")
        n = len(a["radius"])
        m, r = a["mass"].mean(), a["radius"].mean()
        scale = m * 9.81 * r
        ke = []
        with open(self.dir / "first" / "history.csv") as f:
            head = f.readline().strip().split(",")
            k = head.index("kinetic_j")
            for line in f:
                ke.append(float(line.split(",")[k]) / n / scale)
        print(f"  mean kinetic energy after settling: max {max(ke):.3g}, end {ke[-1]:.3g} "
              f"x m g r ({n} grains)", file=sys.stderr)
        self.assertLess(max(ke), 1e-3)
        self.assertLess(ke[-1], 1e-4)

    def test_bed_rests_on_floor(self):
        pts, a, _, _ = last_frame(self.dir / "first")
        # Hertz, grain on a rigid wall of the same material (as crater's walls): F = 4/3 E*
        # sqrt(R) d^1.5 with E* = E / (2 (1 - nu^2)) (docs/theory.md), F = the bed's weight.
        e_mod, nu = 2 * 5e7 * 1.2, 0.2
        e_star = e_mod / (2 * (1 - nu ** 2))
        weight = a["mass"].sum() * 9.81
        r = a["radius"].max()
        bound = (3 * weight / (4 * e_star * math.sqrt(r))) ** (2 / 3)
        depth = (a["radius"] - pts[:, 1]).max()
        print(f"  deepest floor overlap {depth:.3g} m (static bound {bound:.3g} m)",
              file=sys.stderr)
        self.assertLessEqual(depth, bound)

    def test_second_run_reuses_bit_identically(self):
        self.assertEqual(self.diag(self.second)["packing_reused"], 1)
        self.assertIn("reused from", self.second_log)
        self.assert_same_outputs(self.dir / "first", self.dir / "second")

    def test_damaged_file_is_not_used(self):
        f = self.files[0]
        data = bytearray(f.read_bytes())
        data[len(data) // 2] ^= 0x01
        f.write_bytes(bytes(data))
        s = run_scenario(self.toml, self.dir / "damaged", threads=2)
        self.assertEqual(self.diag(s)["packing_reused"], 0)
        self.assert_same_outputs(self.dir / "first", self.dir / "damaged")

    def test_changed_input_settles_anew(self):
        s = run_scenario(self.toml, self.dir / "friction", sets=["materials.0.friction=0.5"])
        self.assertEqual(self.diag(s)["packing_reused"], 0)
        self.assertEqual(len(list(self.cache.glob("soil-*.pack"))), 2)

    def test_unwritable_cache_dir_uses_the_users_cache(self):
        d = self.dir / "readonly"
        d.mkdir(exist_ok=True)
        (d / "settle.toml").write_text(SETTLE)
        (d / ".crater-cache").write_text("a file where the cache directory would go\n")
        env = dict(os.environ, XDG_CACHE_HOME=str(d / "xdg"))
        user_cache = d / "xdg" / "crater" / "packings"
        shutil.rmtree(user_cache, ignore_errors=True)
        runs = []
        for out in ("first", "second"):
            runs.append(subprocess.run(
                [BIN, "run", d / "settle.toml", "--out", d / out, "--force", "--threads", "1",
                 "--set", "scenario.end_time_s=0.002", "--set", "output.interval_s=0.001"],
                capture_output=True, text=True, timeout=900, env=env))
            self.assertEqual(runs[-1].returncode, 0, runs[-1].stderr)
        self.assertIn("cannot be written", runs[0].stderr)
        self.assertIn(str(user_cache), runs[0].stderr)
        self.assertEqual(self.diag(run_summary(d / "first"))["packing_reused"], 0)
        self.assertEqual(self.diag(run_summary(d / "second"))["packing_reused"], 1)
        saved = sorted(user_cache.glob("soil-*.pack"))
        self.assertEqual([f.name for f in saved], [f.name for f in self.files])
        self.assertEqual(saved[0].read_bytes(), self.files[0].read_bytes())

    def assert_same_outputs(self, a, b):
        names = sorted(p.name for p in a.iterdir() if p.suffix in (".vtu", ".csv"))
        self.assertTrue(any(n.endswith(".vtu") for n in names))
        for n in names:
            self.assertEqual((a / n).read_bytes(), (b / n).read_bytes(), f"{n} differs")


def run_summary(out):
    import json
    with open(Path(out) / "summary.json") as f:
        return json.load(f)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
