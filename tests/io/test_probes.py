"""Resolution levels and the paper's probes (issue 6) on the bundled paper-20cm scenario.

Levels: `--level` applies the file's [levels.<name>] overrides (the counts `check` prints grow
as the paper's section IV-B says), an unknown level or a malformed levels table exits 2.
Probes: the measurements of summary.json agree with what the VTU files show when read with
VTK's own reader (the plate's peak von Mises stress at the sampled frame, the eroded element
count), the initial ground surface of the flat bed is y = 0 to within a grain diameter, and
crater depth and settlement agree with surface_profile.csv."""
# ctest-timeout: 900
# ctest-fixtures: bundled_bed
# ctest-cost: 75
import csv
import json
import re
import sys
import unittest

import numpy as np

from crater_test import SOURCE_DIR, crater, read_pvd, read_vtu_cells, scratch

INTERVAL_S = 1e-4
FRAME = 6
# The frame time exactly as the run computes it (interval x frame number, rounded to 15
# significant digits: 6e-4, not 6.000000000000001e-04), so that the stress sample (the first step
# reaching stress_time_s) is that frame.
STRESS_TIME_S = float(f"{INTERVAL_S * FRAME:.14e}")
R_MAX = 0.02  # the largest grain radius of paper-20cm's demo bed [m]


class Levels(unittest.TestCase):
    checked = {}  # `crater check` of each level, once: the finer levels lay their beds (~50 s)

    def counts(self, *args):
        if args not in self.checked:
            self.checked[args] = crater("check", "paper-20cm", *args).stdout
        out = self.checked[args]
        rows = {}
        for line in out.splitlines():
            f = line.split()
            if len(f) > 2 and f[1] in ("sph", "fem", "dem"):
                rows[f[0]] = int(f[2])
        return rows, out

    def test_levels_refine_every_part(self):
        demo, out = self.counts()
        self.assertEqual(demo, self.counts("--level", "demo")[0])
        medium, out = self.counts("--level", "medium")
        self.assertIn("level medium", out)
        # Paper section IV-B, medium: SPH 1.2 cm (our 1.25 cm: the paper's count, 8,234
        # particles in the disk), FEM 5 mm (800 x 40 elements in the 4 m x 0.2 m plate).
        self.assertAlmostEqual(medium["charge"], 8234, delta=100)
        self.assertEqual(medium["plate"], 800 * 40)
        self.assertGreater(medium["soil"], 10 * demo["soil"])

    def test_every_level_reports_a_dense_bed(self):
        # Issue 24: crater check reports the soil's solid fraction (grain area over the soil's
        # box less the charge and plate) and bulk density at every level: at least 0.80 (a
        # dense random packing of disks), the density the grains' 1920 kg/m^3 times it (1 %).
        for level in ("demo", "coarse", "medium", "fine"):
            with self.subTest(level=level):
                _, out = self.counts("--level", level)
                m = re.search(r"soil: solid fraction ([0-9.]+) .*bulk density ([0-9.]+) kg/m\^3",
                              out)
                self.assertIsNotNone(m, out)
                phi, rho = float(m[1]), float(m[2])
                self.assertGreaterEqual(phi, 0.80)
                self.assertLess(abs(rho - 1920 * phi) / (1920 * phi), 0.01)

    def test_levels_combine(self):
        # --level a,b: a's overrides, then b's. `wide` doubles the domain's width (soil and
        # plate across it) and depth, at the resolution of the level before it.
        demo, _ = self.counts()
        wide, out = self.counts("--level", "demo,wide")
        self.assertIn("level demo,wide", out)
        self.assertEqual(wide["plate"], 2 * demo["plate"])
        self.assertEqual(wide["charge"], demo["charge"])
        # 8 m x 4 m less the charge and the plate, against 4 m x 2 m less the same: 4.6 x.
        self.assertAlmostEqual(wide["soil"] / demo["soil"], (32 - 1.29 - 1.6) / 5.913, delta=0.15)
        p = crater("check", "paper-20cm", "--level", "demo,nope", check=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("no level 'nope'", p.stderr)

    def test_unknown_level_exits_2(self):
        p = crater("check", "paper-20cm", "--level", "extreme", check=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("no level 'extreme'", p.stderr)
        self.assertIn("medium", p.stderr)
        p = crater("check", "demo", "--level", "medium", check=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("defines no levels", p.stderr)

    def test_bad_level_table_exits_2(self):
        d = scratch("levels_bad")
        text = (SOURCE_DIR / "scenarios/demo.toml").read_text()
        for body, needle in [
            ('[levels.a]\nsets = ["x=1"]\n', "levels.a.sets"),
            ('[levels.a]\nset = [1]\n', "levels.a.set[0]"),
            ('[levels.a]\nset = ["parts.charge.spacing_m = -1"]\n', "spacing_m"),
        ]:
            f = d / "bad.toml"
            f.write_text(text + "\n" + body)
            p = crater("check", f, "--level", "a", check=False)
            self.assertEqual(p.returncode, 2, p.stderr)
            self.assertIn(needle, p.stderr)
            self.assertNotIn("Traceback", p.stderr)

    def test_list_shows_levels(self):
        p = crater("list")
        self.assertRegex(p.stdout, r"paper-20cm .*\n\s+levels: demo, coarse, medium, fine")


class PlateProbeOnAnyMesh(unittest.TestCase):
    def test_plate_metrics_read_live_fields(self):
        # A sweep over spacing_m found it (issue 28): the plate metrics kept a pointer into a
        # temporary list of the plate's fields, and a 35 x 3 mesh of the clamped plate reused
        # that memory and crashed (SIGSEGV) at the end of the run. Such lookups now take a
        # named list only (fields::find_field refuses a temporary at compile time).
        out = scratch("probes_plate_35x3")
        plate = SOURCE_DIR / "tests" / "data" / "fem_plate_2d.toml"
        p = crater("run", plate, "--out", out, "--force", "--quiet", "--set",
                   "parts.0.spacing_m=0.0057747968", "--set", "probes.plate=plate", "--set",
                   "scenario.end_time_s=1e-6", check=False)
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(out / "summary.json") as f:
            m = json.load(f)["metrics"]
        self.assertEqual(m["plate_eroded_elements"], 0)
        self.assertEqual(m["plate_perforated"], 0)


class Probes(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.out = scratch("probes_paper20")
        crater("run", "paper-20cm", "--out", cls.out, "--force", "--quiet",
               "--set", "scenario.end_time_s=7e-4", "--set", f"output.interval_s={INTERVAL_S!r}",
               "--set", f"probes.stress_time_s={STRESS_TIME_S!r}")
        with open(cls.out / "summary.json") as f:
            cls.summary = json.load(f)
        cls.m = cls.summary["metrics"]

    def test_every_metric_is_written(self):
        for k in ["plate_peak_von_mises_pa", "plate_peak_von_mises_max_pa",
                  "surface_settlement_max_m", "surface_settlement_max_x_m", "crater_depth_m",
                  "crater_radius_m", "plate_eroded_elements", "plate_perforated",
                  "delamination_gap_max_m", "crater_radius_lower_bound"]:
            self.assertIn(k, self.m)
            self.assertTrue(np.isfinite(self.m[k]), k)

    def test_peak_stress_is_the_frames_maximum(self):
        frames = read_pvd(self.out / "plate.pvd")
        t, name = frames[FRAME]
        self.assertEqual(t, self.m["plate_peak_von_mises_time_s"])
        cells = read_vtu_cells(self.out / name)
        live = cells["eroded"] == 0
        self.assertGreater(self.m["plate_peak_von_mises_pa"], 0)
        self.assertEqual(self.m["plate_peak_von_mises_pa"], float(cells["von_mises"][live].max()))
        self.assertGreaterEqual(self.m["plate_peak_von_mises_max_pa"],
                                self.m["plate_peak_von_mises_pa"])
        with open(self.out / "history.csv") as f:
            rows = list(csv.DictReader(f))
        hist = max(float(r["plate_max_von_mises_pa"]) for r in rows)
        self.assertLessEqual(hist, self.m["plate_peak_von_mises_max_pa"])
        self.assertGreater(hist, 0)

    def test_eroded_count_matches_last_frame(self):
        _, name = read_pvd(self.out / "plate.pvd")[-1]
        cells = read_vtu_cells(self.out / name)
        self.assertEqual(self.m["plate_eroded_elements"], int((cells["eroded"] != 0).sum()))

    def test_surface_profile(self):
        with open(self.out / "surface_profile.csv") as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(list(rows[0].keys()), ["x_m", "surface_initial_m", "surface_m",
                                                "vertical_displacement_m"])
        # Columns of ~8 r_max (r_max 20 mm: the dense bed's 8-20 mm) tiling the 4 m width.
        self.assertEqual(len(rows), round(4.0 / (8 * R_MAX)))
        y0 = np.array([float(r["surface_initial_m"]) for r in rows])
        # The bed is laid up to y = 0 (ground surface) and settled: to within a grain diameter.
        self.assertLess(np.abs(y0).max(), 2 * R_MAX)
        dy = np.array([float(r["vertical_displacement_m"]) for r in rows])
        dy = dy[np.isfinite(dy)]
        # A crater is a drop deeper than the largest grain radius; less is no crater.
        deepest = -dy.min()
        self.assertAlmostEqual(self.m["crater_depth_m"], deepest if deepest > R_MAX else 0.0,
                               delta=1e-12)
        # Settlement: the largest drop outside the crater (all columns when there is none).
        if self.m["crater_depth_m"] == 0:
            self.assertAlmostEqual(self.m["surface_settlement_max_m"], deepest, delta=1e-12)
        else:
            self.assertLessEqual(self.m["surface_settlement_max_m"], deepest)
        self.assertGreaterEqual(self.m["crater_radius_m"], 0)
        # The crater: the columns around the deepest one that dropped by more than R_MAX; its
        # radius is a lower bound (flag 1) when they reach a side of the domain (no plane of
        # symmetry here).
        raw = np.array([float(r["vertical_displacement_m"]) for r in rows])
        sunk = np.isfinite(raw) & (-raw > R_MAX)
        reaches = False
        if self.m["crater_depth_m"] > 0:
            lo = hi = int(np.nanargmin(raw))
            while lo > 0 and sunk[lo - 1]:
                lo -= 1
            while hi < len(raw) - 1 and sunk[hi + 1]:
                hi += 1
            reaches = lo == 0 or hi == len(raw) - 1
            self.assertAlmostEqual(self.m["crater_radius_m"], (hi - lo + 1) * 4.0 / len(raw) / 2,
                                   delta=1e-12)
        self.assertEqual(self.m["crater_radius_lower_bound"], 1.0 if reaches else 0.0)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
