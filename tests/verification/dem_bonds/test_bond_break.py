"""Parallel bond (Potyondy & Cundall 2004; paper eqs. 17-24) through the whole DEM code path:
two bonded grains, touching at t = 0 (the shortest chain), are pulled apart along the line of
centres at relative speed 2v. Only the bond acts (the grains separate, so the contact is open):
it is a linear spring of stiffness K = k_n A between the reduced mass m* = m/2, so the bond force
is F(t) = 2v sqrt(K m*) sin(w t), w = sqrt(K / m*), until the bond's normal stress F/A reaches
the tensile strength sigma_c, i.e. at the independent reference force

    F_c = sigma_c A,   A = pi R^2 (3D),  A = 2 R x 1 m (2D, per metre of depth),  R = lambda min(r1, r2)

and time t_b = asin(F_c / F_max) / w. The force at break is read from the energy balance, not
from crater's bond state: the bond's stored energy F^2 / (2K) is lost with it, so
F_break = sqrt(2 K (KE_0 - KE_end)) from history.csv (written every step).

Tolerances: F_break within 2 % of sigma_c A; t_b within 2 %; exactly one bond made and broken
(summary.json bonds_initial / bonds_broken, VTU field `bonds` 1 -> 0); energy balance
KE + contact_j = KE_0 within 1e-4 throughout. The step is 0.002 sqrt(m/K) (the force rises by
< 0.5 % of F_c per step). A bond strength check that is off, or a wrong section area, fails it
(sigma_c A is 2 R in 2D vs pi R^2 in 3D).

A second case checks the bond is inert below its strength: with F_max = 0.8 F_c the pair
oscillates and stays bonded (bonds_broken = 0, KE returns to KE_0 within 1e-4).
"""
import csv
import math
import sys
import unittest

import numpy as np

from crater_test import read_pvd, read_vtu, run_scenario, scratch
from scenario_blocks import (ROCK, approaching_pair, box, compose_scenario, domain, output,
                             part, scenario_text, vec)

R, RHO = 1.0e-3, ROCK["rho0_kg_m3"]
KN = 1.0e11  # bond normal stiffness per area [Pa/m]
SIGMA_C = 1.0e6  # tensile strength [Pa]
LAMBDA = 1.0  # bond radius multiplier
STEP_FRACTION = 0.002


def section_area(dim):
    rb = LAMBDA * R
    return 2 * rb * 1.0 if dim == 2 else math.pi * rb * rb


def mass(dim):
    return RHO * (math.pi * R**2 if dim == 2 else 4.0 / 3.0 * math.pi * R**3)


def reference(dim, v):
    """(F_c, F_max, w, t_b) of the bonded pair pulled apart at +-v."""
    a = section_area(dim)
    k = KN * a
    ms = mass(dim) / 2
    w = math.sqrt(k / ms)
    f_max = 2 * v * math.sqrt(k * ms)
    f_c = SIGMA_C * a
    t_b = math.asin(f_c / f_max) / w if f_c < f_max else math.inf
    return f_c, f_max, w, t_b, k


def scenario(dim, v, end):
    bonds = {"enabled": True, "radius_multiplier": LAMBDA, "normal_stiffness_pa_m": KN,
             "tensile_strength_pa": SIGMA_C, "shear_strength_pa": 10 * SIGMA_C}
    return scenario_text(compose_scenario(
        f"bond-break-{dim}d", dim, end, output=output(end / 4, history_every=1),
        domain=domain(vec(dim, -0.01, -0.01, -0.01), vec(dim, 0.01, 0.01, 0.01)),
        materials=[ROCK],
        parts=[part("grains", "dem", "rock", 0.002,
                    box(vec(dim, -0.004, -0.002, -0.01), vec(dim, 0.004, 0.002, 0.01)),
                    dem={"stiffness_step_fraction": STEP_FRACTION, "bonds": bonds},
                    particles=approaching_pair(dim, R, R, -v))]))


def run(dim, v, end, tag):
    d = scratch(f"dem_bonds_{tag}")
    (d / "case.toml").write_text(scenario(dim, v, end))
    summary = run_scenario(d / "case.toml", d / "out", threads=1)
    with open(d / "out" / "history.csv") as f:
        rows = list(csv.DictReader(f))
    return d / "out", summary, rows


def diagnostics(summary):
    for p in summary["parts"]:
        if p["name"] == "grains":
            return p["diagnostics"]
    raise AssertionError("no part 'grains' in summary.json")


class BondBreak(unittest.TestCase):
    def check_break(self, dim):
        v = 2.0
        f_c, f_max, w, t_b, k = reference(dim, v)
        out, summary, rows = run(dim, v, 3 * t_b, f"break{dim}d")
        self.assertEqual(summary["status"], "completed")
        diag = diagnostics(summary)
        self.assertEqual(diag["bonds_initial"], 1)
        self.assertEqual(diag["bonds_broken"], 1)
        t = np.array([float(r["time_s"]) for r in rows])
        ke = np.array([float(r["kinetic_j"]) for r in rows])
        contact = np.array([float(r["contact_j"]) for r in rows])
        ke0 = ke[0]
        # Energy balance: what the pair lost in kinetic energy the bond holds, then released.
        self.assertLess(np.max(np.abs(ke + contact - ke0)) / ke0, 1e-4)
        f_break = math.sqrt(2 * k * (ke0 - ke[-1]))
        # Break time: the last step at which the kinetic energy still changed.
        changing = np.nonzero(np.abs(np.diff(ke)) > 1e-12 * ke0)[0]
        t_break = t[changing[-1] + 1]
        print(f"{dim}D: F_break = {f_break:.5g} N (sigma_c A = {f_c:.5g} N, "
              f"{100 * (f_break / f_c - 1):+.3f} %), t_b = {t_break:.5g} s "
              f"(closed form {t_b:.5g} s, {100 * (t_break / t_b - 1):+.3f} %)", file=sys.stderr)
        self.assertLessEqual(abs(f_break / f_c - 1), 0.02)
        self.assertLessEqual(abs(t_break / t_b - 1), 0.02)
        frames = read_pvd(out / "grains.pvd")
        _, first, _, _ = read_vtu(out / frames[0][1])
        _, last, _, _ = read_vtu(out / frames[-1][1])
        self.assertEqual(list(first["bonds"]), [1, 1])
        self.assertEqual(list(last["bonds"]), [0, 0])

    def test_break_2d(self):
        self.check_break(2)

    def test_break_3d(self):
        self.check_break(3)

    def test_below_strength_holds(self):
        dim = 2
        f_c, _, w, _, _ = reference(dim, 1.0)
        # F_max = 2 v sqrt(K m*) = 0.8 F_c.
        v = 0.8 * f_c / reference(dim, 1.0)[1]
        out, summary, rows = run(dim, v, 2 * math.pi / w, "hold2d")
        self.assertEqual(diagnostics(summary)["bonds_broken"], 0)
        ke = np.array([float(r["kinetic_j"]) for r in rows])
        contact = np.array([float(r["contact_j"]) for r in rows])
        self.assertLess(np.max(np.abs(ke + contact - ke[0])) / ke[0], 1e-4)
        # Half-way through the period the bond is stretched most and the pair at rest.
        self.assertLess(ke.min() / ke[0], 1e-3)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
