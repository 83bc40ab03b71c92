# ctest-timeout: 300
# ctest-cost: 14
"""Sod's shock tube in a 2D strip against the exact Riemann solution.

Reference: G. A. Sod, "A survey of several finite difference methods for systems of nonlinear
hyperbolic conservation laws", J. Comput. Phys. 27 (1978) 1-31; exact solution after E. F. Toro,
"Riemann Solvers and Numerical Methods for Fluid Dynamics", 3rd ed., Springer 2009, ch. 4
(tests/lib/exact_riemann.py, checked there against Toro's Table 4.3).

Set-up (sod_case.py): ideal gas gamma = 1.4 in the tube x in [0, 1], a strip of 12 particle rows;
left state rho = 1, p = 1, right state rho = 0.125, p = 0.1, at rest, diaphragm at x = 0.5.
One SPH part fills the strip with the left state and a [[parts.zones]] box x >= 0.5 holds the
right state (same spacing, particle mass = rho dx^2). Free-slip Adami walls on all four faces:
top and bottom keep the flow 1D; the end walls are never reached by t = 0.2 (rarefaction head at
0.5 - 1.183 x 0.2 = 0.263, shock at 0.5 + 1.752 x 0.2 = 0.850). Default SPH numerics
(Wendland C2, h = 1.3 dx, Monaghan viscosity alpha = 1, beta = 2).

Measured at t = 0.2: the density averaged across the strip in bins of 2 dx, and its L1 error
E = int_0^1 |rho - rho_exact| dx / int_0^1 rho_exact dx.

Tolerances:
- E <= 5 % at dx = 1/400;
- E decreases when dx halves (1/400 -> 1/800);
- the zone set the initial state: particle densities and pressures of the first frame equal the
  two states exactly (to 1e-12) and the part mass is (1 x 0.5 + 0.125 x 0.5) x height.
(test_sod_convergence.py, label slow, checks the order over four resolutions.)

The figure (density, velocity and pressure against the exact solution at dx = 1/400) goes to
CRATER_TEST_TMP/figures/sph_sod.png, and to docs/figures/sph_sod.png with CRATER_WRITE_FIGURES=1.
"""
import sys
import unittest

import numpy as np

from sod_case import LEFT, RIGHT, T_END, X0, describe, exact, run_case
from sph_profiles import profile, pyplot, save_figure

DX = 1.0 / 400
L1_TOL = 0.05


class SodShockTube(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.coarse = run_case(DX, "dx400")
        cls.fine = run_case(DX / 2, "dx800")
        for r in (cls.coarse, cls.fine):
            print(f"sod {describe(r)}; {r['summary']['parts'][0]['count']} particles",
                  file=sys.stderr)
        cls._figure()

    @classmethod
    def _figure(cls):
        plt = pyplot()
        if plt is None:
            return
        r = cls.coarse
        f = r["frame"]
        x = f["x"][:, 0]
        xs = np.linspace(0.0, 1.0, 2001)
        rho_e, u_e, p_e, _ = exact(xs)
        fig, axes = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
        for ax, name, vals, ex in ((axes[0], "density", f["density"], rho_e),
                                   (axes[1], "velocity x", f["velocity"][:, 0], u_e),
                                   (axes[2], "pressure", f["pressure"], p_e)):
            ax.plot(x, vals, ".", ms=1.5, color="0.6", label="SPH particles")
            edges = np.linspace(0.0, 1.0, int(round(1.0 / (2 * r["dx"]))) + 1)
            xc, prof = profile(x, vals, edges)
            ax.plot(xc, prof, "-", lw=1.2, color="C0", label="SPH, strip average")
            ax.plot(xs, ex, "-", lw=1.0, color="k", label="exact (Toro 2009)")
            ax.set_ylabel(name)
        axes[0].set_title(f"Sod shock tube, t = {T_END}, dx = 1/{1 / r['dx']:.0f}: "
                          f"L1 density error {100 * r['l1']:.2f} %")
        axes[0].legend(loc="upper right", fontsize=8)
        axes[2].set_xlabel("x")
        save_figure(fig, "sph_sod")
        plt.close(fig)

    def test_initial_state_from_zone(self):
        for r in (self.coarse, self.fine):
            f0 = r["frame0"]
            x = f0["x"][:, 0]
            right = x > X0
            self.assertTrue(right.any() and (~right).any())
            np.testing.assert_allclose(f0["density"][~right], LEFT[0], rtol=1e-12)
            np.testing.assert_allclose(f0["density"][right], RIGHT[0], rtol=1e-12)
            np.testing.assert_allclose(f0["pressure"][~right], LEFT[2], rtol=1e-12)
            np.testing.assert_allclose(f0["pressure"][right], RIGHT[2], rtol=1e-12)
            mass = (LEFT[0] * X0 + RIGHT[0] * (1 - X0)) * r["height"]
            self.assertAlmostEqual(r["summary"]["parts"][0]["mass_kg"] / mass, 1.0, delta=1e-9)

    def test_final_frame_time(self):
        self.assertAlmostEqual(self.coarse["frame"]["time"], T_END, delta=1e-12)

    def test_l1_density_error(self):
        self.assertLessEqual(self.coarse["l1"], L1_TOL,
                             f"L1 density error {100 * self.coarse['l1']:.3f} % at dx = 1/400")

    def test_error_decreases_with_resolution(self):
        e1, e2 = self.coarse["l1"], self.fine["l1"]
        self.assertLess(e2, e1, f"L1 error {100 * e1:.3f} % (dx = 1/400) -> {100 * e2:.3f} % "
                                f"(dx = 1/800)")

    def test_walls_hold_the_gas(self):
        """Free-slip walls are mirror planes (docs/theory.md): the images' pressure must keep
        the gas off the wall faces, so crater never has to reflect a particle."""
        for r in (self.coarse, self.fine):
            self.assertEqual(r["summary"]["parts"][0]["diagnostics"]["wall_reflections"], 0)

    def test_gas_stays_in_the_tube(self):
        for r in (self.coarse, self.fine):
            p = r["frame"]["x"]
            self.assertTrue(np.all((p[:, 0] >= 0) & (p[:, 0] <= 1)))
            self.assertTrue(np.all((p[:, 1] >= 0) & (p[:, 1] <= r["height"])))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
