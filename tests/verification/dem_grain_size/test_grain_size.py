# ctest-labels: slow
# ctest-timeout: 5400
"""The bed's friction angle, density and P-wave speed do not depend on grain size (issue 26:
the 3D quarter model's grains, 45-112.5 mm at its demo level and 30-75 mm at its coarse
level, are 11.25 and 7.5 times the paper's coarse 4-10 mm). The
argument and the measured table: docs/validation.md, "DEM: the bed's properties do not depend
on grain size (issue 26)".

Similarity. Multiply every length by lam (grains, sample, walls), every time by lam (stages,
frames; the strain rate / lam), keep stresses, densities and moduli: velocities are unchanged,
accelerations / lam; a grain's mass grows as lam^3, its Hertz-Mindlin contact forces as lam^2
(F_n ~ E* sqrt(R) delta^(3/2), k_t ~ G* sqrt(R delta) times a displacement, mu F_n, the
restitution dashpot ~ sqrt(k_n m) v_n), so m a ~ lam^2 as well; torques lam^3 against inertia
lam^5 and angular accelerations lam^-2; Cundall's local damping alpha |F| is a fraction of the
force; the servo's wall speed, gain x excess force / (k dt), lam^2 / lam^2; the stable step
~ R sqrt(rho/G) ~ lam, so the same number of steps. Only gravity breaks it (m g against lam^2:
g / lam keeps it) and rate-dependent friction (the contact rate |v_n|/(r1 + r2) falls by lam),
which the calibration cases do not use. So a scaled case is the same case; the inertial number
I = eps_rate d sqrt(rho/p) is the same, and the angles, solid fraction and wave speed must be.

What the test runs (seed 1 everywhere):
- the triaxial test (tests/verification/dem_triaxial, triaxial_case.py) at its 4-10 mm,
  and scaled (triaxial_case.scaled: lengths and times x lam, g / lam) to lam = 8 (32-80 mm),
  lam = 7.5 (30-75 mm, paper-3d's coarse level's grains) and lam = 11.25 (45-112.5 mm, its demo
  level's). lam = 8 scales every length by a power of
  two, so the packing generator lays exactly the scaled bed and the run is the unscaled one's
  x 8 (measured: the centres / 8 of every frame, settled to sheared, equal the 4-10 mm bed's
  to the last bit; asserted at the last frame within 1e-9 r). At lam = 7.5 the rounding
  of x 7.5 flips a tie of the deposition at the second grain, so the bed is another packing of
  the same generator (1,115 spheres against 1,108): it can only agree within the scatter of
  packings (so is lam = 11.25's). Asserted: solid fractions within SOLID_FRACTION_TOL of the
  4-10 mm bed's (all three); peak and residual friction angles within ANGLE_TOL_SAME_BED
  (lam = 8) and ANGLE_TOL_OTHER_BED (lam = 7.5, 11.25) degrees;
- the bed's P-wave speed (tests/verification/dem_pwave, pwave_case.py, a column of 8-20 mm
  disks settled under gravity: the confinement is the overburden, so g / lam too, which keeps
  the stress at the scaled depth) at lam = 1, at 0.5 (4-10 mm, the paper's coarse range) and
  at 3.75 (30-75 mm) and 5.625 (45-112.5 mm): the speed over the scaled depths 0.3-1.7 m within
  C_TOL_SAME_BED (lam = 0.5, a power of two) and C_TOL_OTHER_BED (lam = 3.75 and 5.625, held to
  what another packing may give, although the 2D deposition happens to lay the same bed there)
  of lam = 1's.
The numbers go to CRATER_TEST_TMP/grain_size/grain_size.json and stderr; the tolerances'
reasons are where they are set. Wall time: 17 minutes on one core beside other jobs with three
triaxial runs (each of 550,000 steps, settling its bed first) and three P-wave runs; with four
and four, 50 minutes on a machine running four jobs on its two cores (2026-11-27).
"""
import json
import sys
import unittest
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "dem_triaxial"))
sys.path.insert(0, str(HERE.parent / "dem_pwave"))
from triaxial_case import (T_CONS_S, angles, frame_solid_fractions, reduce,  # noqa: E402
                           scaled, scenario)
from crater_test import crater, read_pvd, read_vtu, scratch  # noqa: E402
from scenario_blocks import write_scenario  # noqa: E402
import pwave_case  # noqa: E402

SEED = 1
TRIAXIAL_SCALES = (1.0, 8.0, 7.5, 11.25)
PWAVE_SCALES = (1.0, 0.5, 3.75, 5.625)
# Solid fraction (whole sample and interior, at the end of consolidation): 0.01, issue 26's
# bound (three packings of 4-10 mm: 0.584-0.588 whole, 0.634-0.640 interior).
SOLID_FRACTION_TOL = 0.01
# The same bed (lam = 8, the centres checked equal): any change of trajectory, even by one
# rounding, grows under shearing into another sample whose angles differ by the packings'
# scatter (1-2 deg), so 0.01 deg admits only the same trajectory (measured: equal to the last
# bit).
ANGLE_TOL_SAME_BED = 0.01
# Another packing (lam = 7.5): three standard deviations of the difference of two packings,
# 3 sqrt(2) sigma, sigma the scatter of the 4-10 mm case's three packings (docs/validation.md,
# "DEM: triaxial test": peak 1.5 deg, residual 0.5 deg).
ANGLE_TOL_OTHER_BED = {"phi_peak": 3 * np.sqrt(2) * 1.5, "phi_residual": 3 * np.sqrt(2) * 0.5}
# P-wave speed. lam = 0.5 scales by a power of two: the same bed, to rounding (the same bed
# scaled by 3.75, its settled centres within 5e-6 r of the scaled ones, differs by 1.4e-6).
# lam = 3.75 held to what another packing may give: 3 sqrt(2) sigma, sigma = 1.0 m/s (0.22 %)
# the scatter of the three packings of tests/verification/dem_pwave (444.3-446.2 m/s): 0.93 %,
# rounded up to 1 %.
C_TOL_SAME_BED = 1e-5
C_TOL_OTHER_BED = 0.01


def triaxial(work, lam, seed=SEED):
    """One triaxial run at scale lam: its angles and solid fractions, and the grains' centres
    / lam in its last frame (the end of shearing)."""
    name = f"triaxial_x{lam:g}" + (f"_seed{seed}" if seed != SEED else "")
    kw = scaled(lam) if lam != 1.0 else {}
    case = write_scenario(work / f"{name}.toml", scenario(seed, work / "cache", **kw))
    out = work / name
    crater("run", case, "--out", out, "--force", "--quiet", timeout=3000)
    r = reduce(out / "history.csv", T_CONS_S * lam)
    a = {k: v for k, v in angles(r).items() if k != "bins"}
    a["solid_fraction"], a["solid_fraction_interior"] = frame_solid_fractions(
        out, T_CONS_S * lam, 0.01 * lam, 5e-4 * lam)
    _, last = read_pvd(out / "soil.pvd")[-1]
    pts, _, _, _ = read_vtu(out / last)
    a["grains"] = len(pts)
    a["s3_shear_mean_pa"] = float(r["s3"].mean())
    return a, pts / lam


class GrainSize(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        work = scratch("grain_size")
        cls.tri, cls.last = {}, {}
        for lam in TRIAXIAL_SCALES:
            cls.tri[lam], cls.last[lam] = triaxial(work, lam)
        cls.c = {}
        for lam in PWAVE_SCALES:
            sub = work / f"pwave_x{lam:g}"
            sub.mkdir()
            cls.c[lam] = float(pwave_case.run_seed(SEED, sub, scale=lam)[0])
        table = {"triaxial": {f"x{k:g}": v for k, v in cls.tri.items()},
                 "p_wave_m_s": {f"x{k:g}": v for k, v in cls.c.items()}}
        (work / "grain_size.json").write_text(json.dumps(table, indent=1))
        print(json.dumps(table, indent=1), file=sys.stderr)

    def test_power_of_two_scale_is_the_same_bed(self):
        """lam = 8: the packing generator and the DEM see only numbers scaled by a power of
        two, rounded alike; at the end of shearing the grains must stand where the 4-10 mm
        bed's stand, x 8 (measured: equal to the last bit)."""
        self.assertEqual(self.tri[8.0]["grains"], self.tri[1.0]["grains"])
        r_mean = 0.007
        self.assertLess(np.abs(self.last[8.0] - self.last[1.0]).max(), 1e-9 * r_mean)

    def test_friction_angle_same_bed(self):
        for key in ("phi_peak", "phi_residual"):
            with self.subTest(key=key):
                self.assertLess(abs(self.tri[8.0][key] - self.tri[1.0][key]), ANGLE_TOL_SAME_BED)

    def test_friction_angle_other_bed(self):
        for lam in (7.5, 11.25):
            for key in ("phi_peak", "phi_residual"):
                with self.subTest(lam=lam, key=key):
                    self.assertLess(abs(self.tri[lam][key] - self.tri[1.0][key]),
                                    ANGLE_TOL_OTHER_BED[key])

    def test_solid_fraction(self):
        for lam in (8.0, 7.5, 11.25):
            for key in ("solid_fraction", "solid_fraction_interior"):
                with self.subTest(lam=lam, key=key):
                    self.assertLess(abs(self.tri[lam][key] - self.tri[1.0][key]),
                                    SOLID_FRACTION_TOL)

    def test_p_wave_speed(self):
        c1 = self.c[1.0]
        with self.subTest(lam=0.5):
            self.assertLess(abs(self.c[0.5] / c1 - 1), C_TOL_SAME_BED)
        for lam in (3.75, 5.625):
            with self.subTest(lam=lam):
                self.assertLess(abs(self.c[lam] / c1 - 1), C_TOL_OTHER_BED)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
