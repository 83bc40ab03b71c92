# ctest-labels: slow
# ctest-timeout: 3000
"""Triaxial compression of the paper's sand in 3D, three packings (issue 24's soil
calibration; the case, its stages and the reduction: triaxial_case.py; docs/validation.md).

Asserted, per seed (1, 2, 3):
- the packing is dense: solid fraction >= 0.60 in the sample's interior (2 r_max inside the
  walls, at the end of consolidation), where a random dense packing of spheres reaches about
  0.64 (measured 0.634-0.640); the whole sample, its looser layers along the six walls
  included, is reported beside it (0.584-0.588);
- the servo: after consolidation (mean of the last 20 rows) each side wall, their mean and the
  platen hold sigma_3 = 100 kPa within 1 % (measured within 0.21 %); over the shearing the four
  walls' mean within 3 % and each wall within 5 % (measured +0.5 %: the proportional servo's
  lag, docs/theory.md);
- the residual (mean over eps_1 = 7-10 %) is below the peak and in RESIDUAL_BAND, the critical
  state of frictional spheres without rolling resistance at mu >= 0.5 (phi_cs about 20-26 deg:
  Thornton 2000, Geotechnique 50(1) 43-53; Huang, Hanley, O'Sullivan & Kwok 2014, IJNAG 38
  1276-1297, where phi_cs saturates above mu = 0.5; as recalled, not re-read for this case),
  2 deg lower for the scatter of a 1,100-sphere sample;
- the dense sample dilates: psi > 5 deg and eps_v < 0 at the end;
- its strength and dilatancy agree with each other as Bolton (1986)'s triaxial relation has it,
  phi_peak - phi_crit = 3 I_R with (-d eps_v/d eps_1)_max = 0.3 I_R, i.e. 10 deg per unit of
  the dilation rate: phi_peak - phi_residual within 2.5 deg of 10 x the rate (measured within
  1 deg).
EXPECTED FAILURE: the peak in PEAK_BAND, 30-40 deg, the range 3D DEM studies of dense
assemblies of frictional spheres without rolling resistance (mu 0.5-1) report (the same papers
and Barreto & O'Sullivan 2012, Granular Matter 14 505-521; as recalled, not re-read). The
sample peaks at 23.8 / 25.1 / 26.8 deg (2026-11-26): its critical state, 20.4-21.4 deg, is in
the spheres' range, but it dilates at only 0.34-0.51 (I_R 1.1-1.7), so its peak stands
3-6 deg above it, not 10-20 (docs/validation.md). The check runs and is expected to fail
(unittest.expectedFailure): if it starts passing, the unexpected success fails the test and
this note must go.
The three seeds' angles with their mean and standard deviation are printed and written to
CRATER_TEST_TMP/triaxial/angles.json; the figure (plot_triaxial.py) goes to
CRATER_TEST_TMP/figures/dem_triaxial.png, and to docs/figures/ with CRATER_WRITE_FIGURES=1.
Wall time: 9.9 and 13.8 minutes for the three seeds (two runs on one core beside other jobs, two
cores, load average 4-8): per seed, settling 1,108 spheres (300,000 steps, cached in the scratch directory, so
every fresh test pays it) and 550,000 steps of the test.
"""
import json
import sys
import unittest
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from triaxial_case import (SEEDS, SIDES, SIGMA3_PA, T_CONS_S, angles,  # noqa: E402
                           frame_solid_fractions, reduce, scenario)
from crater_test import crater, scratch  # noqa: E402
from scenario_blocks import write_scenario  # noqa: E402

PEAK_BAND = (30.0, 40.0)
RESIDUAL_BAND = (18.0, 26.0)
BOLTON_DEG = 2.5


def run_seeds(work, seeds=SEEDS, **kw):
    """Runs the triaxial test for each seed; returns {seed: reduced history} (with the solid
    fractions of the frame at the end of consolidation)."""
    out = {}
    for seed in seeds:
        case = work / f"seed{seed}.toml"
        write_scenario(case, scenario(seed, work / "cache", **kw))
        crater("run", case, "--out", work / f"seed{seed}", "--force", "--quiet", timeout=1500)
        out[seed] = reduce(work / f"seed{seed}" / "history.csv")
        out[seed]["solid_fraction"], out[seed]["solid_fraction_interior"] = \
            frame_solid_fractions(work / f"seed{seed}", T_CONS_S)
    return out


def summary(runs, found):
    """The angles per seed and their mean and standard deviation over the seeds."""
    table = {s: {k: v for k, v in a.items() if k != "bins"} for s, a in found.items()}
    for s, r in runs.items():
        table[s]["solid_fraction"] = r["solid_fraction"]
        table[s]["solid_fraction_interior"] = r["solid_fraction_interior"]
        table[s]["s3_shear_mean_pa"] = float(r["s3"].mean())
    for k in ("phi_peak", "phi_residual", "psi", "e1_peak", "dilation_rate", "solid_fraction",
              "solid_fraction_interior"):
        vals = np.array([table[s][k] for s in runs])
        table[f"{k}_mean"] = float(vals.mean())
        table[f"{k}_std"] = float(vals.std(ddof=1)) if len(vals) > 1 else 0.0
    return table


class Triaxial(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("triaxial")
        cls.runs = run_seeds(cls.work)
        cls.angles = {s: angles(r) for s, r in cls.runs.items()}
        table = summary(cls.runs, cls.angles)
        (cls.work / "angles.json").write_text(json.dumps(table, indent=1))
        print(json.dumps(table, indent=1), file=sys.stderr)
        try:
            from plot_triaxial import figure
            figure(cls.runs, cls.angles)
        except ImportError:  # no matplotlib: the figure is skipped (plot_triaxial.py says so)
            pass

    def test_dense_packing(self):
        for seed, r in self.runs.items():
            with self.subTest(seed=seed):
                self.assertGreaterEqual(r["solid_fraction_interior"], 0.60)
                self.assertLess(r["solid_fraction"], r["solid_fraction_interior"])

    def test_servo_holds_sigma3(self):
        for seed, r in self.runs.items():
            with self.subTest(seed=seed):
                self.assertLess(abs(r["s3_consolidated"].mean() / SIGMA3_PA - 1), 0.01)
                self.assertLess(abs(r["s_top_consolidated"].mean() / SIGMA3_PA - 1), 0.01)
                for f in SIDES:
                    self.assertLess(abs(r["s_sides_consolidated"][f].mean() / SIGMA3_PA - 1),
                                    0.01, f)
                    self.assertLess(abs(r["s_sides"][f].mean() / SIGMA3_PA - 1), 0.05, f)
                self.assertLess(abs(r["s3"].mean() / SIGMA3_PA - 1), 0.03)

    @unittest.expectedFailure
    def test_peak_friction_angle_in_the_sphere_band(self):
        for seed, a in self.angles.items():
            with self.subTest(seed=seed):
                self.assertGreaterEqual(a["phi_peak"], PEAK_BAND[0])
                self.assertLessEqual(a["phi_peak"], PEAK_BAND[1])

    def test_residual_below_peak(self):
        for seed, a in self.angles.items():
            with self.subTest(seed=seed):
                self.assertLess(a["phi_residual"], a["phi_peak"])
                self.assertGreaterEqual(a["phi_residual"], RESIDUAL_BAND[0])
                self.assertLessEqual(a["phi_residual"], RESIDUAL_BAND[1])

    def test_dense_sample_dilates(self):
        for seed, a in self.angles.items():
            with self.subTest(seed=seed):
                self.assertGreater(a["psi"], 5.0)
                self.assertLess(a["ev_end"], 0.0)

    def test_strength_follows_dilatancy(self):
        for seed, a in self.angles.items():
            with self.subTest(seed=seed):
                self.assertLess(abs(a["phi_peak"] - a["phi_residual"]
                                    - 10.0 * a["dilation_rate"]), BOLTON_DEG)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
