# ctest-timeout: 300
"""Collapse of a water column (dam break) against the experiments of Martin & Moyce (1952).

Reference: J. C. Martin and W. J. Moyce, "Part IV. An experimental study of the collapse of
liquid columns on a rigid horizontal plane", Phil. Trans. R. Soc. Lond. A 244 (1952) 312-324:
column of width a = 2 1/4 in = 0.05715 m and height 2a (n^2 = 2), surge front Z = z/a against
T = t sqrt(2 g / a). The measured points (T <= 2.5) and their provenance are in
dam_break_case.py.

Set-up (dam_break_case.py): weakly compressible SPH, Tait EOS (rho0 = 1000 kg/m^3,
c0 = 15 m/s >= 10 sqrt(2 g H), gamma = 7), gravity -9.81 m/s^2, the column in the corner of a
6a x 3a box with Adami walls (free slip) on the left, right and bottom faces (open top),
hydrostatic initial density (one [[parts.zones]] per particle row), Monaghan viscosity
alpha = 0.1, beta = 0; dx = a/20 here (800 particles), a/40 in test_dam_break_fine.py (slow).

Time shift: the simulated front at T - 0.175 is compared with the measurement at T. Martin &
Moyce's column was released by removing a restraint, which takes a finite time, so the
experiment lags an instantaneous release at early T and simulations run ahead of the data;
0.175 is the correction Lethe applies to the same data (dam_break_case.py has the sources),
taken unchanged, not fitted here. The unshifted errors are printed too (crater at dx = a/20:
up to +14 % at T = 1.19 without the shift).

Tolerances:
- surge front within 10 % of every measured point with T <= 2.5 (simulated front, shifted by
  0.175 in T, interpolated linearly between frames written every 0.05 in T);
- no particle crosses a wall: every frame has 0 <= x <= 6a and y >= 0 (y <= 3a, the domain);
- Z = 1 at T = 0 (the front is the last particle centre + dx/2);
- weakly compressible: |rho / rho0 - 1| <= 3 % in every frame (c0 = 10 v_max gives density
  variations of order (v_max / c0)^2 = 1 %, Monaghan 1994, J. Comput. Phys. 110, 399).
"""
import sys
import unittest

import numpy as np

from dam_break_case import (A, BOX_H, BOX_W, MM_T, MM_Z, RHO0, T_SHIFT, front_errors,
                             run_case)
from sph_profiles import pyplot, save_figure

FRONT_TOL = 0.10
DX = A / 20


def figure(result, name):
    plt = pyplot()
    if plt is None:
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(result["T"] + T_SHIFT, result["Z"], "-",
            label=f"crater SPH, dx = a/{A / result['dx']:.0f}, T + {T_SHIFT}")
    ax.plot(result["T"], result["Z"], ":", color="C0", lw=0.8, label="crater SPH, unshifted")
    ax.plot(MM_T, MM_Z, "o", label="Martin & Moyce 1952 (n² = 2, a = 2.25 in)")
    ax.fill_between(MM_T, 0.9 * MM_Z, 1.1 * MM_Z, color="C1", alpha=0.2, label="±10 %")
    ax.set_xlabel("T = t √(2g/a)")
    ax.set_ylabel("Z = front / a")
    ax.legend(fontsize=8)
    save_figure(fig, name)
    plt.close(fig)


class DamBreakChecks:
    """Checks shared with the fine (slow) variant; subclasses set `result` in setUpClass."""

    def test_surge_front(self):
        z_sim, err = front_errors(self.result["T"], self.result["Z"])
        for t, zm, zs, e in zip(MM_T, MM_Z, z_sim, err):
            with self.subTest(T=t):
                self.assertLessEqual(
                    abs(e), FRONT_TOL,
                    f"T = {t}: Z(T - {T_SHIFT}) = {zs:.3f} vs measured {zm} ({100 * e:+.1f} %)")

    def test_no_particle_crosses_a_wall(self):
        # Free-slip walls are mirror planes: a particle that crosses one within a step is
        # reflected back (the symmetry condition; counted in summary.json). The images' pressure
        # must hold the water: at most a round-off-sized dip by a particle sliding on the floor
        # at the free surface, where the pressure is about zero (1e-3 dx; a particle driven
        # into the wall crosses by a good fraction of dx in a step).
        diags = self.result["summary"]["parts"][0]["diagnostics"]
        dx = self.result["dx"]
        self.assertLessEqual(diags["wall_max_penetration_m"], 1e-3 * dx,
                             f"{diags['wall_reflections']:.0f} reflections, deepest "
                             f"{diags['wall_max_penetration_m']:.3g} m (dx = {dx:g} m)")
        for t, f in self.result["frames"]:
            x = f["x"]
            self.assertTrue(np.all((x[:, 0] >= 0.0) & (x[:, 0] <= BOX_W)), f"t = {t}")
            self.assertTrue(np.all((x[:, 1] >= 0.0) & (x[:, 1] <= BOX_H)), f"t = {t}")

    def test_weakly_compressible(self):
        dev = max(np.abs(f["density"] / RHO0 - 1).max() for _, f in self.result["frames"])
        self.assertLessEqual(dev, 0.03, f"max |rho/rho0 - 1| = {100 * dev:.2f} %")

    def test_initial_front(self):
        self.assertEqual(self.result["T"][0], 0.0)
        self.assertAlmostEqual(self.result["Z"][0], 1.0, delta=1e-9)


def report(result):
    z_sim, err = front_errors(result["T"], result["Z"])
    z_raw, err_raw = front_errors(result["T"], result["Z"], shift=0.0)
    s = result["summary"]
    print(f"dam break dx = a/{A / result['dx']:.0f}: {s['parts'][0]['count']} particles, "
          f"{s['steps']} steps, {result['wall_s']:.1f} s", file=sys.stderr)
    for t, zm, zs, e, zr, er in zip(MM_T, MM_Z, z_sim, err, z_raw, err_raw):
        print(f"  T = {t:4.2f}: measured {zm:4.2f}; Z(T - {T_SHIFT}) = {zs:5.3f} "
              f"({100 * e:+5.1f} %); unshifted Z(T) = {zr:5.3f} ({100 * er:+5.1f} %)",
              file=sys.stderr)


class DamBreak(DamBreakChecks, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.result = run_case(DX, "a20")
        report(cls.result)
        figure(cls.result, "sph_dam_break")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
