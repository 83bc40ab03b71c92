"""Linear spring-dashpot contact (paper eqs. 2-16, `contact = "linear_spring"`) through the whole
DEM code path: two equal grains collide head-on. The normal contact is a damped harmonic
oscillator of the reduced mass m* = m/2 (independent closed form, e.g. Schwager & Poeschel
2007; Cundall & Strack 1979):

    t_c = pi / sqrt((k_n / m*) (1 - zeta^2)),   zeta = -ln e / sqrt(pi^2 + ln^2 e)
    (undamped, e = 1: t_c = pi sqrt(m* / k_n)),   rebound / approach speed = e.

The contact time is read from history.csv (every step) as the span over which the kinetic
energy changes; the step is 0.005 sqrt(m/k) (t_c / 444), so the reading is within 0.25 %.
Tolerance 1 % for t_c (the issue's) and for e, for e = 1 and e = 0.5, disks (2D, per metre of
depth) and spheres (3D). The stable step the part reports is checked too: 0.17 sqrt(m/k_max)
(O'Sullivan & Bray 2004) when stiffness_step_fraction is left at its default.
"""
import csv
import math
import sys
import unittest

import numpy as np

from crater_test import run_scenario, scratch
from scenario_blocks import (approaching_pair, box, compose_scenario, domain, output, part,
                             scenario_text, vec)

R, RHO, NU, V = 0.002, 2650.0, 0.25, 0.5
KN = 1.0e6  # N/m (2D: per metre of depth)
GAP = 1.0e-6
FRACTION = 0.005


def mass(dim):
    return RHO * (math.pi * R**2 if dim == 2 else 4.0 / 3.0 * math.pi * R**3)


def zeta(e):
    if e >= 1:
        return 0.0
    return -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2)


def contact_time(dim, e):
    ms = mass(dim) / 2
    return math.pi / math.sqrt(KN / ms * (1 - zeta(e) ** 2))


def scenario(dim, e, fraction):
    end = GAP / V + 1.5 * contact_time(dim, e)
    glass = {"name": "glass", "model": "granular", "rho0_kg_m3": RHO, "shear_modulus_pa": 1.0e9,
             "poisson_ratio": NU, "friction": 0.5, "restitution": e}
    return scenario_text(compose_scenario(
        f"linear-contact-{dim}d", dim, end, output=output(end / 2, history_every=1),
        domain=domain(vec(dim, -0.02, -0.02, -0.01), vec(dim, 0.02, 0.02, 0.01)),
        materials=[glass],
        parts=[part("grains", "dem", "glass", 0.004,
                    box(vec(dim, -0.008, -0.004, -0.01), vec(dim, 0.008, 0.004, 0.01)),
                    dem={"contact": "linear_spring", "normal_stiffness_n_m": KN,
                         "stiffness_step_fraction": fraction or None},
                    particles=approaching_pair(dim, R + GAP / 2, R, V / 2))]))


def run(dim, e, fraction=FRACTION):
    d = scratch(f"dem_linear_{dim}d_e{e}_{fraction}")
    (d / "case.toml").write_text(scenario(dim, e, fraction))
    summary = run_scenario(d / "case.toml", d / "out", threads=1)
    with open(d / "out" / "history.csv") as f:
        rows = list(csv.DictReader(f))
    return summary, rows


class LinearContact(unittest.TestCase):
    def check(self, dim, e):
        summary, rows = run(dim, e)
        self.assertEqual(summary["status"], "completed")
        t = np.array([float(r["time_s"]) for r in rows])
        ke = np.array([float(r["kinetic_j"]) for r in rows])
        changing = np.nonzero(np.abs(np.diff(ke)) > 1e-12 * ke[0])[0]
        self.assertGreater(len(changing), 100, "the grains never touched")
        # KE changes over steps changing[0] -> changing[0]+1 ... changing[-1] -> changing[-1]+1;
        # contact began inside the first of these steps and ended inside the last: take the
        # middles of both.
        dt = t[1] - t[0]
        tc = t[changing[-1]] - t[changing[0]] + dt
        tc_ref = contact_time(dim, e)
        e_meas = math.sqrt(ke[-1] / ke[0])
        print(f"{dim}D e = {e}: t_c = {tc:.5e} s (closed form {tc_ref:.5e}, "
              f"{100 * (tc / tc_ref - 1):+.3f} %), e = {e_meas:.5f} "
              f"({100 * (e_meas / e - 1):+.3f} %)", file=sys.stderr)
        self.assertLessEqual(abs(tc / tc_ref - 1), 0.01)
        self.assertLessEqual(abs(e_meas / e - 1), 0.01)

    def test_undamped_2d(self):
        self.check(2, 1.0)

    def test_undamped_3d(self):
        self.check(3, 1.0)

    def test_damped_2d(self):
        self.check(2, 0.5)

    def test_damped_3d(self):
        self.check(3, 0.5)

    def test_default_stable_step(self):
        # k_max = max(k_n, k_s); k_s = k_n 2(1 - nu)/(2 - nu) < k_n by default.
        summary, rows = run(2, 1.0, fraction=None)
        dt = float(rows[1]["dt_s"])
        ref = 0.9 * 0.17 * math.sqrt(mass(2) / KN)  # [time] safety_factor 0.9
        self.assertAlmostEqual(dt / ref, 1.0, delta=1e-9)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
