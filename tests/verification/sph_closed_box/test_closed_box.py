# ctest-timeout: 300
# ctest-cost: 32
"""Energy conservation of SPH with Adami walls: blasts in closed boxes.

Reference: the Euler equations conserve total energy (kinetic + internal) in a closed,
rigid, adiabatic box; fixed free-slip walls do no work. crater's SPH equations (docs/theory.md:
continuity, momentum and the symmetric energy equation, Monaghan viscosity) conserve it in the
continuous-time limit; the walls are fixed dummy particles after S. Adami, X. Y. Hu and
N. A. Adams, "A generalized wall boundary condition for smoothed particle hydrodynamics",
J. Comput. Phys. 231 (2012) 7057-7075.

Cases (walls on all four faces of the domain, free slip; the gas fills the box up to them):
1. Ideal gas, gamma = 1.4, box [0, 1]^2 m, dx = 1/50 m: at rest, rho = 1 kg/m^3, p = 0.1 Pa,
   and a [[parts.zones]] disk (centre (0.35, 0.40) m, r = 0.15 m) at p = 1 Pa. Run to t = 6 s:
   about three crossings of the box at the final sound speed (c = 0.48 m/s; the blast wave
   is faster), so the shock reflects off every wall several times.
2. TNT detonation products (JWL, standard set; all particles lit at t = 0, no detonation
   points): box [0, 0.2]^2 m, dx = 4 mm, the products at 0.25 rho0 (p ~ 0.6 GPa) and a
   [[parts.zones]] disk (centre (0.09, 0.11) m, r = 0.04 m) at rho0 (p ~ 8 GPa). Run to
   t = 200 us: about five crossings at c ~ 5 km/s.
3. Both again with the artificial conductivity on (conductivity_alpha = 1, Price 2008,
   J. Comput. Phys. 227, 10040): it moves internal energy between the particles of a pair, so the
   total must stay conserved with it as well.
4. Both again with density = "summation" (the summed density, h solved with it, the grad-h
   pressure terms; docs/theory.md section 2), and the ideal gas once more with no-slip walls
   (dummy particles, whose share of each pair's work the fluid particle books): the grad-h
   equations conserve the total pair by pair as the continuity form's do. Their first frame
   holds the summed density, so the zone is checked on the specific energy (ideal gas) and
   the particle masses (JWL) instead.

Measured: the total energy E = K + U (+ the ledger terms of summary.json) from history.csv
(total_j, every 10 steps) and summary.json energy.balance_error.

Tolerances:
- max_t |E(t) - E(0)| / E(0) <= 0.5 % over the whole run (history.csv total_j);
- |energy.balance_error| <= 0.5 % (summary.json);
- the zone set the initial state (first frame: the two pressures / densities, to 1e-9);
- something happened: the peak kinetic energy is >= 1 % of E(0); all particles stay in the box.
"""
import math
import sys
import unittest

import numpy as np

from crater_test import scratch
from scenario_blocks import AIR, TNT, box, disk, write_scenario
from sph_profiles import frames, load_frame, read_history, run

DRIFT_TOL = 0.005
WALLS = ["left", "right", "bottom", "top"]


def ideal_gas_box():
    side, dx = 1.0, 1.0 / 50
    return side, dx, {
        "scenario": {"name": "sph-closed-box-gas", "dimension": 2, "end_time_s": 6.0,
                     "description": "2D blast (ideal gas) in a closed box with Adami walls"},
        "output": {"interval_s": 1.0, "history_every": 10},
        "domain": {"min_m": [0.0, 0.0], "max_m": [side, side]},
        "materials": [dict(AIR)],
        "parts": [{
            "name": "gas", "method": "sph", "material": "air", "spacing_m": dx,
            "region": box([0.0, 0.0], [side, side]),
            "initial": {"density_kg_m3": 1.0, "pressure_pa": 0.1},
            "sph": {"walls": WALLS, "wall_slip": "free"},
            "zones": [{"region": disk([0.35, 0.40], 0.15), "pressure_pa": 1.0}],
        }],
    }


def jwl_box():
    side, dx = 0.2, 0.004
    rho0 = TNT["rho0_kg_m3"]
    return side, dx, {
        "scenario": {"name": "sph-closed-box-jwl", "dimension": 2, "end_time_s": 200e-6,
                     "description": "TNT products (JWL) in a closed box with Adami walls"},
        "output": {"interval_s": 20e-6, "history_every": 10},
        "domain": {"min_m": [0.0, 0.0], "max_m": [side, side]},
        "materials": [dict(TNT)],
        "parts": [{
            "name": "products", "method": "sph", "material": "tnt", "spacing_m": dx,
            "region": box([0.0, 0.0], [side, side]),
            "initial": {"density_kg_m3": 0.25 * rho0},
            "sph": {"walls": WALLS, "wall_slip": "free"},
            "zones": [{"region": disk([0.09, 0.11], 0.04), "density_kg_m3": rho0}],
        }],
    }


def with_conductivity(case, alpha=1.0):
    """A case of the above with [parts.sph] conductivity_alpha = alpha."""
    side, dx, sc = case
    sc["parts"][0]["sph"]["conductivity_alpha"] = alpha
    sc["scenario"]["name"] += "-conductivity"
    return side, dx, sc


def with_summation(case, wall_slip="free"):
    """A case of the above with [parts.sph] density = "summation" (and the walls' slip)."""
    side, dx, sc = case
    sc["parts"][0]["sph"]["density"] = "summation"
    sc["parts"][0]["sph"]["wall_slip"] = wall_slip
    sc["scenario"]["name"] += f"-summation-{wall_slip}-slip"
    return side, dx, sc


class ClosedBox(unittest.TestCase):
    results = {}

    def _run(self, tag, make):
        side, dx, sc = make()
        d = scratch(f"sph_closed_box_{tag}")
        path = write_scenario(d / "box.toml", sc, comment=f"closed box, {tag}")
        summary, wall = run(path, d / "out")
        h = read_history(d / "out")
        e = h["total_j"]
        drift = np.abs(e - e[0]) / e[0]
        part = sc["parts"][0]["name"]
        fr = [(t, load_frame(p)) for t, p in frames(d / "out", part)]
        print(f"closed box {tag}: {summary['parts'][0]['count']} particles, {summary['steps']} "
              f"steps, {wall:.1f} s; max drift {100 * drift.max():.4f} % "
              f"(at t = {h['time_s'][np.argmax(drift)]:.4g} s), final "
              f"{100 * (e[-1] - e[0]) / e[0]:+.4f} %, balance_error "
              f"{100 * summary['energy']['balance_error']:+.4f} %, peak K / E0 "
              f"{h['kinetic_j'].max() / e[0]:.4f}", file=sys.stderr)
        return side, dx, summary, h, drift, fr

    def _check(self, tag, make, expect0):
        side, dx, summary, h, drift, fr = self._run(tag, make)
        with self.subTest(case=tag, what="history drift"):
            self.assertLessEqual(drift.max(), DRIFT_TOL,
                                 f"max |E - E0| / E0 = {100 * drift.max():.4f} %")
        with self.subTest(case=tag, what="balance_error"):
            self.assertLessEqual(abs(summary["energy"]["balance_error"]), DRIFT_TOL)
        with self.subTest(case=tag, what="history spans the run"):
            self.assertTrue(math.isclose(h["time_s"][-1], summary["scenario"]["end_time_s"],
                                         rel_tol=1e-9))
        with self.subTest(case=tag, what="something moved"):
            self.assertGreaterEqual(h["kinetic_j"].max(), 0.01 * h["total_j"][0])
        with self.subTest(case=tag, what="in the box"):
            for t, f in fr:
                x = f["x"]
                self.assertTrue(np.all((x[:, :2] >= 0.0) & (x[:, :2] <= side)), f"t = {t}")
        with self.subTest(case=tag, what="initial state"):
            f0 = fr[0][1]
            self.assertEqual(fr[0][0], 0.0)
            key, lo, hi = expect0
            vals = f0[key]
            either = np.isclose(vals, lo, rtol=1e-9) | np.isclose(vals, hi, rtol=1e-9)
            self.assertTrue(np.all(either), f"{key} at t = 0 not in {{{lo}, {hi}}}")
            self.assertTrue(np.any(np.isclose(vals, hi, rtol=1e-9)), "zone not applied")

    def test_ideal_gas(self):
        self._check("ideal_gas", ideal_gas_box, ("pressure", 0.1, 1.0))

    def test_jwl_products(self):
        self._check("jwl", jwl_box, ("density", 0.25 * TNT["rho0_kg_m3"], TNT["rho0_kg_m3"]))

    def test_ideal_gas_conductivity(self):
        self._check("ideal_gas_conductivity", lambda: with_conductivity(ideal_gas_box()),
                    ("pressure", 0.1, 1.0))

    def test_jwl_products_conductivity(self):
        self._check("jwl_conductivity", lambda: with_conductivity(jwl_box()),
                    ("density", 0.25 * TNT["rho0_kg_m3"], TNT["rho0_kg_m3"]))

    def test_ideal_gas_summation(self):
        # e = p / ((gamma - 1) rho0): 0.25 and 2.5 J/kg.
        self._check("ideal_gas_summation", lambda: with_summation(ideal_gas_box()),
                    ("specific_energy", 0.25, 2.5))

    def test_ideal_gas_summation_no_slip(self):
        self._check("ideal_gas_summation_no_slip",
                    lambda: with_summation(ideal_gas_box(), wall_slip="no"),
                    ("specific_energy", 0.25, 2.5))

    def test_jwl_products_summation(self):
        m = TNT["rho0_kg_m3"] * 0.004 ** 2
        self._check("jwl_summation", lambda: with_summation(jwl_box()), ("mass", 0.25 * m, m))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
