# ctest-timeout: 600
# ctest-cost: 70
"""The Sedov-Taylor point blast in an ideal gas (gamma = 1.4), cylindrical (2D) and spherical
(3D), against the self-similar solution.

Reference: L. I. Sedov, "Similarity and Dimensional Methods in Mechanics", Academic Press 1959,
ch. IV; G. I. Taylor, Proc. R. Soc. A 201 (1950) 159. The shock is at
R(t) = xi0 (E t^2 / rho0)^(1/(D+2)) (E per metre of depth in 2D); xi0 is computed by
tests/lib/sedov_exact.py, which integrates the self-similar equations and Sedov's energy
integral: xi0 = 1.00402 (cylindrical), 1.03278 (spherical), i.e. alpha = E t^2/(rho0 R^(D+2))
= 0.984074 and 0.851072, against 0.984041 and 0.851060 in J. R. Kamm and F. X. Timmes, "On
efficient generation of numerically robust Sedov solutions", LA-UR-07-2849 (2007). Right
behind the shock the density is rho0 (gamma+1)/(gamma-1) = 6 rho0, the largest of the profile.

Set-up (sedov_case.py): rho0 = 1 kg/m^3, E = 1 J (3D) or 1 J/m (2D). A quadrant (2D) or octant
(3D) [0, 1 m]^D with free-slip walls on every face: those through the origin are mirror planes,
so the model is a quarter / eighth of the blast (run whole without walls, the 2D blast has the
same radii to four digits); the far ones are never reached. The model's share E/2^D sits in a
[[parts.zones]] disk / sphere of radius 3 dx about the origin (8 / 17 particles, pressure p_b
from that count; the first frame is checked); the ambient gas is at rest at p_0 = 1e-6 p_b,
3.8e-4 (2D) / 2.6e-4 (3D) of the pressure behind the shock at the last frame: the strong-shock
limit. 100 particles per edge in 2D (dx = 10 mm, 10,000 particles), 30 in 3D (dx = 33 mm,
27,000). Numerics: crater's defaults (Wendland C2, h = 1.3 dx, variable h, Monaghan alpha = 1,
beta = 2, cfl 0.3) but for two keys, SPH = {density = "summation", conductivity_alpha = 1}:
the density summed over the neighbours with h solved with it and the grad-h pressure terms
(Springel & Hernquist 2002; Price 2012, J. Comput. Phys. 231, 759), and Price's (2008)
artificial conductivity: the formulation Price (2012) reviews. Frames at
t_k = k t_last / 10, k = 1..10 (a decade in time), t_last when the exact shock is at 0.8 m:
R = 25 ... 80 dx in 2D, 9.6 ... 24 dx in 3D, far beyond the deposition's 3 dx.

Measured per frame: the particle densities averaged over shells of width dx about the origin;
the shock radius is the radius of the largest shell mean (refined by a parabola through it and
its two neighbours). Why the peak and not the outer crossing of (rho_max + rho0)/2: the exact
density is largest at the shock itself, and the peak's radius does not depend on the peak's
height, which the kernel lowers from 6 to 2-5.5 at these resolutions, whereas the half-height
crossing moves outwards as the peak drops: on the exact profile smoothed across the front by
the kernel it lies 1.8 to 7.1 % beyond R in 3D (2D: 0.3 to 1.6 %). On that smoothed profile
(the best an SPH solution at this dx can show; test_measurement_on_the_exact_solution) the peak
lies 1.8-3.4 % (0.9-1.4 dx) inside R in 2D, 1.1-3.0 % (0.1-0.6 dx) in 3D: the floor of the
measurement. (The half-height crossings are printed too.)

Tolerances (the issue's acceptance): at every frame |r_peak / R - 1| <= 5 % and
|r_peak - R| <= 2 dx.

Measured (2026-11-27), peak radius over the ten frames: 2D -2.35 ... -0.72 % (-0.73 ... -0.47 dx),
3D -0.33 ... +0.35 % (within 0.08 dx). With the default continuity density the shock lagged
by -14.6 ... -25.4 % (2D) and -11.0 ... -16.1 % (3D), more and more over the decade: the
particles of the deposition, pushed out to the edge of their neighbours' kernels, kept their
continuity density and with it 57 % of the blast's energy (docs/validation.md has that study
and the rows of each remedy: conductivity alone, summation without the grad-h terms, both).
The blast scenes keep the continuity density: a summed density reads low at a free surface,
the charge's edge.

The other checks pass: the energy deposited, its conservation (summary.json balance), no
particle reflected at a wall, and the measurement itself on the smoothed exact solution.
The figure (profiles and R(t)) goes to CRATER_TEST_TMP/figures/sph_sedov.png, and to
docs/figures/sph_sedov.png with CRATER_WRITE_FIGURES=1.
"""
import sys
import unittest

import numpy as np

import sedov_exact
from sedov_case import (COUNTER, ENERGY, GAMMA, H_FACTOR, R_LAST, RHO0, frame_times, measure,
                        run_case, smoothed_exact_profile, zone_count)
from sph_profiles import pyplot, save_figure

CASES = {2: (100, 3.0), 3: (30, 3.0)}  # dimension: (particles per edge, zone radius in dx)
SPH = {"density": "summation", "conductivity_alpha": 1.0}  # [parts.sph] keys (docstring)
RADIUS_TOL = 0.05                      # |r_peak / R - 1|
PEAK_TOL_DX = 2.0                      # |r_peak - R| / dx
BALANCE_TOL = 0.005                    # summary.json energy.balance_error
KINETIC_EXACT = {2: 0.2088, 3: 0.2187}  # K / E of the self-similar solution (sedov_exact)


class SedovTaylor(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.runs = {d: run_case(d, n, rz, f"{d}d", SPH) for d, (n, rz) in CASES.items()}
        for d, r in cls.runs.items():
            s = r["summary"]
            fin = s["energy"]["final"]
            kin = fin["kinetic_j"] / s["energy"]["initial"]["total_j"]
            print(f"sedov {d}D: {s['parts'][0]['count']} particles (dx = {1e3 * r['dx']:.1f} mm),"
                  f" {s['steps']} steps, {r['wall_s']:.1f} s; E = {r['energy']:.9f}; kinetic "
                  f"energy at t_last {100 * kin:.1f} % of the model's (exact "
                  f"{100 * KINETIC_EXACT[d]:.1f} %)", file=sys.stderr)
            for w in r["rows"]:
                print(f"  t = {w['t']:.4f} s: R = {w['R']:.4f} m, peak {w['r_peak']:.4f} m "
                      f"({100 * w['err']:+.2f} %, {w['peak_dx']:+.2f} dx, rho_max "
                      f"{w['rho_max']:.2f}), half height {w['r_half']:.4f} m "
                      f"({100 * w['half_err']:+.2f} %)", file=sys.stderr)
        cls._figure()

    @classmethod
    def _figure(cls):
        plt = pyplot()
        if plt is None:
            return
        fig, axes = plt.subplots(2, 2, figsize=(12, 8))
        for row, (d, r) in enumerate(sorted(cls.runs.items())):
            ax = axes[row][0]
            for k, c in ((0, "C0"), (3, "C1"), (9, "C2")):
                t, rc, rho = r["profiles"][k]
                ax.plot(rc, rho, ".-", ms=3, lw=0.8, color=c, label=f"SPH, t = {t:.3f} s")
                rs = np.linspace(0.0, 1.0, 4001)
                ax.plot(rs, sedov_exact.profile(rs, t, r["energy"], RHO0, d, GAMMA)[0], "-",
                        lw=0.8, color=c, alpha=0.5)
                xs, sm = smoothed_exact_profile(d, t, r["energy"], r["dx"], H_FACTOR * r["dx"])
                ax.plot(xs, sm, "--", lw=0.8, color=c)
            ax.set_xlim(0.0, 1.0)
            ax.set_ylim(0.0, 6.5)
            ax.set_xlabel("r [m]")
            ax.set_ylabel("density [kg/m^3]")
            ax.set_title(f"{d}D, {r['n']} per edge: shell means (dots), exact (light), "
                         "exact smoothed by the kernel (dashed)", fontsize=8)
            ax.legend(fontsize=7, loc="upper left")
            ax = axes[row][1]
            ts = np.array([w["t"] for w in r["rows"]])
            tt = np.geomspace(ts[0], ts[-1], 100)
            ax.loglog(tt, sedov_exact.shock_radius(tt, r["energy"], RHO0, d, GAMMA), "k-",
                      lw=1, label=f"R(t), xi0 = {sedov_exact.xi0(d, GAMMA):.4f}")
            ax.loglog(ts, [w["r_peak"] for w in r["rows"]], "o", ms=4, label="SPH density peak")
            ax.loglog(ts, [w["r_half"] for w in r["rows"]], "s", ms=3, mfc="none",
                      label="SPH half-height crossing")
            ax.set_xlabel("t [s]")
            ax.set_ylabel("shock radius [m]")
            ax.legend(fontsize=7)
            ax.grid(True, which="both", lw=0.3)
        fig.suptitle("Sedov-Taylor blast, gamma = 1.4: SPH (summation density, conductivity) "
                     "against the self-similar solution", fontsize=10)
        fig.tight_layout()
        save_figure(fig, "sph_sedov")
        plt.close(fig)

    # --- the set-up -----------------------------------------------------------------------

    def test_blast_energy(self):
        """The zone holds E/2^D above the ambient, in the expected particles."""
        for d, r in self.runs.items():
            with self.subTest(dim=d):
                self.assertAlmostEqual(r["energy"] / ENERGY, 1.0, delta=1e-9)
                f0 = r["frame0"]
                hot = np.count_nonzero(f0["pressure"] > 0.5 * f0["pressure"].max())
                self.assertEqual(hot, zone_count(d, r["r_zone"]))
                self.assertAlmostEqual(r["p_0"] / f0["pressure"].max(), COUNTER, delta=1e-12)

    def test_strong_shock(self):
        """The counter-pressure is negligible behind the shock until the last frame."""
        for d, r in self.runs.items():
            t_last = frame_times(d)[-1]
            u_shock = 2.0 / (d + 2) * R_LAST / t_last
            p_shock = 2.0 / (GAMMA + 1) * RHO0 * u_shock ** 2
            self.assertLess(r["p_0"] / p_shock, 1e-3, f"{d}D")

    def test_frames(self):
        for d, r in self.runs.items():
            got = [w["t"] for w in r["rows"]]
            np.testing.assert_allclose(got, frame_times(d), rtol=1e-9, err_msg=f"{d}D")

    def test_energy_conserved(self):
        for d, r in self.runs.items():
            self.assertLessEqual(abs(r["summary"]["energy"]["balance_error"]), BALANCE_TOL,
                                 f"{d}D")

    def test_walls_hold_the_gas(self):
        """Mirror planes hold the gas: no particle is ever reflected at a face."""
        for d, r in self.runs.items():
            diag = r["summary"]["parts"][0]["diagnostics"]
            self.assertEqual(diag["wall_reflections"], 0, f"{d}D")

    def test_measurement_on_the_exact_solution(self):
        """The shell means of the exact profile, smoothed across the front by the kernel at
        h = 1.3 dx, put the peak within the tolerances at every frame: a solution as good as
        the resolution allows passes."""
        for d, r in self.runs.items():
            for t in frame_times(d):
                rc, rho = smoothed_exact_profile(d, t, ENERGY, r["dx"], H_FACTOR * r["dx"])
                r_peak = measure(rc, rho)[0]
                big_r = float(sedov_exact.shock_radius(t, ENERGY, RHO0, d, GAMMA))
                with self.subTest(dim=d, t=t):
                    self.assertLessEqual(abs(r_peak / big_r - 1), RADIUS_TOL)
                    self.assertLessEqual(abs(r_peak - big_r) / r["dx"], PEAK_TOL_DX)

    # --- the acceptance ----------------------------------------------------------------------

    def _radius(self, d):
        bad = [f"t = {w['t']:.4f} s: {100 * w['err']:+.2f} %" for w in self.runs[d]["rows"]
               if not abs(w["err"]) <= RADIUS_TOL]
        self.assertFalse(bad, f"{d}D shock radius off by more than {100 * RADIUS_TOL:g} %: "
                              + "; ".join(bad))

    def _peak(self, d):
        bad = [f"t = {w['t']:.4f} s: {w['peak_dx']:+.2f} dx" for w in self.runs[d]["rows"]
               if not abs(w["peak_dx"]) <= PEAK_TOL_DX]
        self.assertFalse(bad, f"{d}D density peak farther than {PEAK_TOL_DX:g} dx from R: "
                              + "; ".join(bad))

    def test_shock_radius_2d(self):
        self._radius(2)

    def test_peak_position_2d(self):
        self._peak(2)

    def test_shock_radius_3d(self):
        self._radius(3)

    def test_peak_position_3d(self):
        self._peak(3)

if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
