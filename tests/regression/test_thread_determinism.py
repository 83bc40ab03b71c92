# ctest-processors: 2
# ctest-timeout: 1500
# ctest-fixtures: bundled_bed
# ctest-cost: 49
"""Same input, same binary => bit-identical outputs on 1 and 2 threads (every VTU, PVD,
history.csv, and summary.json except its "run" block): SPH in 2D (the demo) and 3D, a
settling DEM bed in 2D and an agitated one in 3D (on one thread the DEM pair loop sums the
received shares as it goes, on two it gathers them: the sums must agree bit for bit), a bonded
DEM block breaking on a floor in 2D, SPH particles and DEM grains leaving the domain
(outflow = "remove") in 2D, an FEM plate eroding in 2D, the 3D Taylor bar (FEM, Johnson-Cook
with heating, read from a Gmsh file) and the paper's coupled scene (paper-20cm, demo level:
the dense bed, settled by the first run when the cache lacks it, then 0.5 ms on each count)."""
import json
import sys
import unittest

from crater_test import SOURCE_DIR, assert_bit_identical_runs, scratch


class ThreadDeterminism(unittest.TestCase):
    def test_demo_2d(self):
        # Enough particles that parallel loops and blocked reductions split across threads.
        files = assert_bit_identical_runs("demo", scratch("det_demo"),
                                          sets=["parts.charge.spacing_m=0.0025"])
        self.assertIn("history.csv", files)

    def test_dem_bed_2d(self):
        files = assert_bit_identical_runs(SOURCE_DIR / "tests/data/dem_bed_2d.toml",
                                          scratch("det_dem_bed"))
        self.assertIn("sand.pvd", files)

    def test_dem_bed_3d(self):
        # The 3D benchmark's bed, 1,000 spheres, with rolling resistance.
        files = assert_bit_identical_runs(
            SOURCE_DIR / "bench/scenarios/dem_bed_3d.toml", scratch("det_dem_bed_3d"),
            sets=["parts.bed.region.max_m=[0.05,0.05,0.05]", "domain.max_m=[0.05,0.3,0.05]",
                  "time.max_steps=300", "output.vtu=true", "output.interval_s=4e-5",
                  "parts.bed.dem.rolling_friction=0.05"])
        self.assertIn("bed.pvd", files)

    def test_dem_bonded_2d(self):
        # Linear springs, parallel bonds breaking, rolling resistance, rate-dependent friction.
        files = assert_bit_identical_runs(SOURCE_DIR / "tests/data/dem_bonded_2d.toml",
                                          scratch("det_dem_bonded"))
        self.assertIn("rock.pvd", files)

    def test_fem_plate_2d(self):
        # Johnson-Cook plate with damage; elements erode during the run.
        files = assert_bit_identical_runs(SOURCE_DIR / "tests/data/fem_plate_2d.toml",
                                          scratch("det_fem_plate"))
        self.assertIn("plate.pvd", files)

    def test_fem_taylor_bar_3d(self):
        sys.path.insert(0, str(SOURCE_DIR / "tests/verification/fem_taylor"))
        from test_taylor_bar import write_case

        work = scratch("det_fem_taylor")
        files = assert_bit_identical_runs(
            write_case(work), work,
            sets=["scenario.end_time_s=1.5e-5", "output.interval_s=5e-6"])
        self.assertIn("rod.pvd", files)

    def test_fem_taylor_bar_mass_scaled(self):
        # Selective mass scaling: the impact face's elements gain mass from about 18 us on
        # (tests/verification/fem_taylor/test_taylor_mass_scaling.py); nodes gather it per node.
        sys.path.insert(0, str(SOURCE_DIR / "tests/verification/fem_taylor"))
        from test_taylor_bar import write_case

        work = scratch("det_fem_taylor_ms")
        files = assert_bit_identical_runs(
            write_case(work), work,
            sets=["scenario.end_time_s=3e-5", "output.interval_s=1e-5",
                  "parts.rod.fem.mass_scaling_step_ratio=0.8"])
        self.assertIn("rod.pvd", files)
        with open(work / "threads1" / "summary.json") as f:
            added = json.load(f)["parts"][0]["diagnostics"]["added_mass_kg"]
        self.assertGreater(added, 0)  # the case does scale

    def test_paper_20cm_demo(self):
        # The paper's coupled scene (SPH charge, eroding JC plate, DEM soil, three contacts)
        # through the products' impact on the plate and the first erosions (0.5 ms; the whole
        # 10 ms run: tests/regression/test_paper_scenarios.py, label slow).
        files = assert_bit_identical_runs("paper-20cm", scratch("det_paper20"),
                                          sets=["scenario.end_time_s=5e-4"])
        self.assertIn("surface_profile.csv", files)
        self.assertIn("plate.pvd", files)

    def test_paper_20cm_demo_multi_rate(self):
        # The same with each part at its own step (time.multi_rate): the charge steps up to 8
        # times the plate's step while its particles leave the domain (from 0.22 ms).
        files = assert_bit_identical_runs("paper-20cm", scratch("det_paper20_mr"),
                                          sets=["scenario.end_time_s=5e-4",
                                                "time.multi_rate=true"])
        self.assertIn("plate.pvd", files)

    def test_paper_fem_only_demo(self):
        # Pressure loads and FEM-FEM contacts (plate between four Drucker-Prager soil parts):
        # through the equivalent pressure's peak (0.11-0.25 ms) to 0.3 ms.
        files = assert_bit_identical_runs("paper-fem-only", scratch("det_paper_fem_only"),
                                          sets=["scenario.end_time_s=3e-4",
                                                "output.interval_s=1e-4"])
        self.assertIn("plate.pvd", files)
        self.assertIn("soil_top.pvd", files)

    def test_outflow_2d(self):
        # domain.outflow = "remove": SPH particles and DEM grains (with contacts and bonds) are
        # removed as they leave the box; the survivors are compacted in index order.
        files = assert_bit_identical_runs(SOURCE_DIR / "tests/data/outflow_2d.toml",
                                          scratch("det_outflow"))
        self.assertIn("gas.pvd", files)
        self.assertIn("columns.pvd", files)

    def test_sph_3d(self):
        files = assert_bit_identical_runs(SOURCE_DIR / "tests/data/sph3d_small.toml",
                                          scratch("det_sph3d"))
        self.assertIn("charge.pvd", files)

    def test_sph_3d_conductivity(self):
        # The artificial conductivity (Price 2008) adds a heat flux and a signal speed to each
        # particle's gather; the sums must stay in list order on any number of threads.
        files = assert_bit_identical_runs(SOURCE_DIR / "tests/data/sph3d_small.toml",
                                          scratch("det_sph3d_conductivity"),
                                          sets=["parts.charge.sph.conductivity_alpha=1"])
        self.assertIn("charge.pvd", files)

    def test_sph_3d_summation(self):
        # density = "summation": each particle's Newton solve for h and rho reads its own lists
        # in order; a charge expanding into vacuum makes its edge particles ask for longer lists
        # (rebuilds inside the density pass); by 20 us the outer ones reach the cap on h.
        files = assert_bit_identical_runs(SOURCE_DIR / "tests/data/sph3d_small.toml",
                                          scratch("det_sph3d_summation"),
                                          sets=["parts.charge.sph.density=\"summation\"",
                                                "scenario.end_time_s=2e-5"])
        self.assertIn("charge.pvd", files)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
