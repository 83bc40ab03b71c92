# ctest-processors: 2
# ctest-timeout: 300
"""Probes and gauges on several MPI ranks (issue 29, docs/distributed.md, "Probes and gauges on
ranks"): the probes and the gauges read the entities each rank owns, and the root gets what
they find (the ground's per-cell sums as reproducible sums, extremes, eroded elements' numbers,
the gauged entities' values), so their outputs are one rank's bit for bit. No part is
gathered whole.

Each scene is run without a launcher on one thread (the reference) and under mpirun on 2 and 3
ranks and on 2 ranks of 2 threads. Every run must give the reference's files: every CSV file
byte for byte (history.csv with the probes' columns, gauges.csv, surface_profile.csv),
summary.json but its "run" block (the probes' metrics), the frames and the checkpoints (which
hold the probes' state). A 2-rank checkpoint is resumed on 3 ranks and on 1.
- tests/data/dem_bed_2d.toml at rest, with the ground-surface probe ([probes] soil): the bed
  settles by 1-2.4 cm in 0.02 s, so the profile and the crater metrics are not trivial;
- tests/data/fem_plate_2d.toml (a Johnson-Cook plate struck in its middle, with erosion) with
  the plate probes ([probes] plate: peak von Mises at a time and over the rows, eroded
  elements, perforation) and gauges at a point, at node and element ids and a face's sum;
- tests/data/contacts_ranks_2d.toml (a TNT disk in a bed under a clamped plate) with the soil
  and plate probes: the ground with the plate's elements in it, the crater, the gap, erosion
  and perforation;
- tests/data/sph_outflow_ranks_2d.toml (a gas blob splashing out of the box) with gauges at
  particle ids that leave one by one (NaN from then on, as on one rank);
- tests/data/sph_ranks_2d.toml (a dam break on no-slip walls) with gauges at particle ids
  (followed as they move between ranks) and at a point.
"""
import json
import unittest

from crater_test import SOURCE_DIR, scratch
from on_ranks import MPIRUN, assert_ranks_give, assert_resumes, checkpoints, plain

DATA = SOURCE_DIR / "tests" / "data"
RANKS = [(2, 1), (3, 1), (2, 2)]

PLATE_PROBES = """
[probes]
plate = "plate"
stress_time_s = 3e-5

[[gauges]]
name = "centre"
part = "plate"
fields = ["velocity", "von_mises"]
point_m = [0.0, 0.0]

[[gauges]]
name = "nodes"
part = "plate"
fields = ["displacement"]
ids = [0, 57, 300, 1100]

[[gauges]]
name = "elements"
part = "plate"
fields = ["von_mises", "eroded"]
element_ids = [10, 450, 499, 980]
sum = true

[[gauges]]
name = "clamp"
part = "plate"
fields = ["velocity"]
face = "left"
"""

FLUID_GAUGES = """
[[gauges]]
name = "front"
part = "fluid"
fields = ["velocity", "pressure"]
ids = [0, 19, 400, 799]

[[gauges]]
name = "corner"
part = "fluid"
fields = ["density"]
point_m = [0.9, 0.1]
"""

LEAVING_GAUGES = """
[[gauges]]
name = "blob"
part = "blob"
fields = ["velocity", "pressure"]
ids = [0, 40, 100, 160, 207]

[[gauges]]
name = "all"
part = "blob"
fields = ["pressure"]
ids = [0, 40, 100, 160, 207]
sum = true
"""

# The soil and the plate together: the ground's cells hold the plate's live elements where it
# was laid, and the gap between the plate and the grains under it and over it.
SOIL_AND_PLATE = """
[probes]
plate = "plate"
soil = "soil"
"""

# scene file, text appended, --set options, checkpoint interval [steps], checkpoint to resume
CASES = {
    "dem_ground": (DATA / "dem_bed_2d.toml", "",
                   ["--set", 'probes.soil="sand"', "--set",
                    "parts.sand.initial.velocity_m_s=[0.0,-0.2]", "--set",
                    "probes.surface_bin_m=0.02"], 10000, "step_000000010000.ckpt"),
    "fem_plate": (DATA / "fem_plate_2d.toml", PLATE_PROBES, [], 200, "step_000000000200.ckpt"),
    "bed_under_plate": (DATA / "contacts_ranks_2d.toml", SOIL_AND_PLATE, [], 500,
                        "step_000000000500.ckpt"),
    "sph_gauges": (DATA / "sph_ranks_2d.toml", FLUID_GAUGES, [], 500, "step_000000000500.ckpt"),
    "sph_leaving": (DATA / "sph_outflow_ranks_2d.toml", LEAVING_GAUGES, [], 1500,
                    "step_000000001500.ckpt"),
}



@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class ProbesOnRanks(unittest.TestCase):
    def run_case(self, name, expect_files):
        base, extra, sets, every, resume_from = CASES[name]
        work = scratch(f"probes_ranks_{name}")
        scene = work / "scene.toml"
        scene.write_text(base.read_text() + extra)
        ref = work / "plain"
        opts = [*sets, *checkpoints(every)]
        p = plain("run", scene, "--out", ref, "--force", "--quiet", "--threads", "1", *opts)
        self.assertEqual(p.returncode, 0, p.stderr)
        for f in expect_files:
            self.assertTrue((ref / f).is_file(), f)
        ckpts = sorted(f.name for f in (ref / "checkpoints").iterdir())
        self.assertIn(resume_from, ckpts)
        assert_ranks_give(self, ref, scene, opts, RANKS, ckpts, name)
        for np_ in (3, 1):
            with self.subTest(case=name, resumed_on=np_):
                assert_resumes(self, scene, work / "ranks2_threads1", resume_from, np_, opts,
                               f"{name} resumed on {np_}")
        return ref

    def test_ground_surface_probe(self):
        ref = self.run_case("dem_ground", ["surface_profile.csv"])
        rows = (ref / "surface_profile.csv").read_text().splitlines()
        self.assertEqual(len(rows), 11)  # header, 10 columns of 2 cm
        self.assertNotIn("nan", rows[1])

    def test_plate_probes_and_gauges(self):
        ref = self.run_case("fem_plate", ["gauges.csv"])
        header = (ref / "history.csv").read_text().splitlines()[0]
        self.assertIn("plate_max_von_mises_pa", header)
        self.assertIn("elements.sum.von_mises",
                      (ref / "gauges.csv").read_text().splitlines()[0])

    def test_soil_and_plate_probes(self):
        """The ground, the crater and the plate-soil gap read each rank's own grains and
        elements: per-cell sums and per-column extremes over the ranks. The products blow the
        plate open and throw the bed over it, so the gap is wide (9 cm) and set by grains
        another rank than the root owns on 3 ranks (mutation check: with the root's own grains
        alone, 1.5 mm there)."""
        ref = self.run_case("bed_under_plate", ["surface_profile.csv"])
        metrics = json.loads((ref / "summary.json").read_text())["metrics"]
        self.assertGreater(metrics["plate_eroded_elements"], 0, metrics)
        self.assertGreater(metrics["crater_depth_m"], 0, metrics)
        self.assertGreater(metrics["delamination_gap_max_m"], 0.01, metrics)

    def test_gauged_particles_that_leave(self):
        """Gauged particles leave through the outflow one by one: their columns turn NaN (and
        the sum with them) as on one rank, written from the ranks that still own the others."""
        ref = self.run_case("sph_leaving", ["gauges.csv"])
        rows = [r.split(",")[2:] for r in (ref / "gauges.csv").read_text().splitlines()[1:]]
        mixed = [r for r in rows if "nan" in r and any(x != "nan" for x in r)]
        self.assertGreater(len(mixed), 0, "no row has both gone and present particles")
        self.assertTrue(all(x == "nan" for x in rows[-1]), rows[-1])

    def test_particle_gauges(self):
        ref = self.run_case("sph_gauges", ["gauges.csv"])
        self.assertIn("front.particle799.pressure",
                      (ref / "gauges.csv").read_text().splitlines()[0])


if __name__ == "__main__":
    unittest.main()
