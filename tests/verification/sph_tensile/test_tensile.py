# ctest-timeout: 120
"""Monaghan's (2000) tensile-instability correction (paper eq. 38): the artificial pressure's
force on a cluster of particles by hand, and the instability it removes.

crater (docs/theory.md, SPH; src/sph/pair_terms.hpp tensile_correction) adds to the momentum
equation (eq. 34)
    dv_i/dt += -sum_j m_j R_ij f_ij^4 grad_i W_ij,   f_ij = W(r_ij, hbar) / W(dx, hbar),
    R_ij = R_i + R_j,   R_i = eps |p_i| / rho_i^2 where p_i < 0, else 0
(J. J. Monaghan, "SPH without a tensile instability", J. Comput. Phys. 159 (2000) 290-311; the
paper's printed eq. 38 has p/rho for p/rho^2), with dx the part's spacing_m and eps =
tensile_epsilon. It is repulsive (grad_i W_ij points from i towards j), where the pressure
term under tension attracts.

1. Cluster (quantitative). Six particles, a 3 x 2 block of the lattice (dx = 0.01 m) alone in
   the domain, at rest, all at density rho: their pairs lie at dx, sqrt(2) dx, 2 dx and
   sqrt(5) dx, all within the support 2h = 2.6 dx (f = 1, 0.377, 0.032, 0.005: the exponent
   n = 4 matters). Every particle has m = rho dx^2 and V = dx^2 (crater lays m = rho pitch^D) and
   the Tait pressure p = B ((rho/rho0)^7 - 1), B = rho0 c0^2 / 7; with v = 0 the artificial
   viscosity is 0, so eq. 34 with the correction gives, by hand,
       a_i = -(2 p dx^2 / rho) sum_j (1 - eps' f_ij^4) grad_i W_ij,
   eps' = eps for p < 0 and 0 for p > 0, with the Wendland C2 kernel written out below
   (paper eq. 28). Three runs of one fixed step dt = 1e-4 s (stable step ~4e-4 s): rho = 990
   kg/m^3 (p = -970.5 Pa) with eps = 0.2 and with eps = 0, and rho = 1010 kg/m^3 (p = +1030.5
   Pa) with eps = 0.2. From rest, a step moves a particle by a dt^2 / 2 exactly (velocity
   Verlet), so a_i = 2 (x_i(dt) - x_i(0)) / dt^2 is crater's acceleration at t = 0.
   Tolerances: each run's a_i within 1e-6 of max |a| of the formula; the correction alone,
   a(eps = 0.2) - a(eps = 0), within 1e-6 of max |its formula| (rounding is ~1e-11: 1e-6 m
   displacements of 0.02 m positions); under positive pressure the correction is exactly 0
   (a(eps = 0.2) equals the formula without it to 1e-6). Against the formula, max |a| error of
   a correction that is missing or twice as large: 12.6 %; of the wrong sign: 25 %; with R_i
   alone for R_i + R_j: 6.3 %; with f^2 for f^4: 1.2 % (f^3: 0.34 %); with W(h) for W(dx):
   167 %; with p/rho for p/rho^2: 1.2e4 %; acting under positive pressure too: 11 % there.

2. Lattice under tension (the classical behaviour, Monaghan 2000 section 5; qualitative, with
   a control). A 30 x 30 lattice (dx = 0.01 m) fills a box with free-slip (mirror) walls on all
   four faces at rho = 990 kg/m^3 (p = -970 Pa, uniform: the lattice is in equilibrium), Tait
   c0 = 10 m/s, default numerics (Wendland C2, h = 1.3 dx, artificial viscosity 1 / 2), every
   particle given a random velocity of up to 0.1 m/s per component (seeded, one
   [[parts.zones]] entry per particle). Without the correction the tensile instability clumps
   the particles (Swegle et al. 1995: the nearest neighbour sits at q = 0.77, past the
   kernel's inflection q = 0.5); with eps = 0.2 the lattice stays regular. Measured at
   t = 0.2 s (200 dx / c0): the nearest-neighbour distance of every particle, in dx.
   Tolerances: eps = 0: the smallest below 0.8 dx (it reaches 0.670); eps = 0.2: the smallest
   above 0.9 dx (0.967) and the standard deviation below 0.02 dx (0.0062). The correction slows
   the instability rather than removing it for good here: run on, the spread keeps growing
   slowly (smallest 0.927 dx, standard deviation 0.021 dx at 0.6 s); under 4.4 times the
   tension (rho = 950 kg/m^3, p = -4.3 kPa) the uncorrected lattice clumps by 0.05 s (0.36 dx)
   and the corrected one by 0.2 s with eps = 0.2 (0.73 dx), 0.3 s with 0.3 or 0.5 (0.70, 0.67).
   Energy: crater books no work for the correction (it is not in the energy equation; see
   tests/unit/sph/test_pair_terms.cpp), so the energy balance of the corrected run drifts
   (+4.3 % at 0.2 s, +34 % at 0.6 s; the uncorrected run: -0.4 %): the energy guard is off in
   the lattice runs (time.energy_stop_error = 0). The cluster's step ends -7.3 % off balance
   with eps = 0.2 (0.07 % with eps = 0), within the default guard.
"""
import math
import sys
import unittest

import numpy as np

from crater_test import scratch
from scenario_blocks import box, write_scenario
from sph_profiles import frames, load_frame, run

DX = 0.01          # m, lattice pitch (spacing_m)
H = 1.3 * DX       # m, smoothing length (h_factor 1.3, the default)
RHO0 = 1000.0      # kg/m^3
C0 = 10.0          # m/s
GAMMA = 7.0
EPS = 0.2          # tensile_epsilon (Monaghan's value)
DT = 1e-4          # s, the cluster's one step
TOL = 1e-6         # relative, cluster
N_LATTICE = 30     # particles per side of the lattice under tension
T_LATTICE = 0.2    # s
V_NOISE = 0.1      # m/s, the largest initial velocity component
NN_CLUMPED = 0.8   # dx: without the correction the smallest neighbour distance falls below
NN_REGULAR = 0.9   # dx: with it the smallest stays above
NN_SPREAD = 0.02   # dx: with it the standard deviation stays below


def tait_pressure(rho):
    return RHO0 * C0 * C0 / GAMMA * ((rho / RHO0) ** GAMMA - 1.0)


def w(r, h=H):
    """2D Wendland C2 kernel (paper eq. 28) [1/m^2]."""
    q = r / h
    return 7.0 / (4.0 * math.pi * h * h) * max(0.0, 1.0 - 0.5 * q) ** 4 * (2.0 * q + 1.0)


def dw_dr(r, h=H):
    """Its radial derivative [1/m^3]."""
    q = r / h
    return -5.0 * 7.0 / (4.0 * math.pi * h * h) / h * q * max(0.0, 1.0 - 0.5 * q) ** 3


def cluster_acceleration(x, rho, eps):
    """Eq. 34 with the correction, by hand, for equal particles at rest at density rho
    (m = rho dx^2, V = dx^2): (pressure part, correction part) of a_i [m/s^2], N x 2 each."""
    p = tait_pressure(rho)
    r_art = eps * abs(p) / rho ** 2 if p < 0 else 0.0  # R_i, the same for all
    m, vol = rho * DX * DX, DX * DX
    a_p, a_t = np.zeros((len(x), 2)), np.zeros((len(x), 2))
    for i in range(len(x)):
        for j in range(len(x)):
            if i == j:
                continue
            rij = x[i] - x[j]
            r = math.hypot(*rij)
            if r >= 2 * H:
                continue
            grad = dw_dr(r) / r * rij
            f = w(r) / w(DX)
            a_p[i] -= vol * (p + p) / rho * grad
            a_t[i] -= m * (2 * r_art) * f ** 4 * grad
    return a_p, a_t


def by_id(f):
    order = np.argsort(f["id"])
    return {k: (v[order] if isinstance(v, np.ndarray) and len(v) == len(order) else v)
            for k, v in f.items()}


def cluster_scenario(rho, eps):
    return {
        "scenario": {"name": "sph-tensile-cluster", "dimension": 2, "end_time_s": DT,
                     "description": "six particles under uniform pressure, one step"},
        "time": {"fixed_dt_s": DT},
        "output": {"interval_s": DT, "history_every": 1},
        "domain": {"min_m": [-0.05, -0.05], "max_m": [0.08, 0.07]},
        "materials": [{"name": "water", "model": "tait", "rho0_kg_m3": RHO0, "c0_m_s": C0,
                       "gamma": GAMMA}],
        "parts": [{
            "name": "water", "method": "sph", "material": "water", "spacing_m": DX,
            "region": box([0.0, 0.0], [3 * DX, 2 * DX]),
            "initial": {"density_kg_m3": rho},
            "sph": {"tensile_epsilon": eps},
        }],
    }


def run_cluster(rho, eps, tag):
    """crater's accelerations at t = 0 (from the one step), positions, pressures, step count."""
    d = scratch(f"sph_tensile_{tag}")
    path = write_scenario(d / "cluster.toml", cluster_scenario(rho, eps),
                          comment="tensile correction, cluster (tests/verification/sph_tensile)")
    summary, wall = run(path, d / "out")
    fr = [by_id(load_frame(p)) for _, p in frames(d / "out", "water")]
    f0, f1 = fr[0], fr[-1]
    dt = f1["time"] - f0["time"]
    a = 2.0 * (f1["x"][:, :2] - f0["x"][:, :2]) / (dt * dt)
    return {"a": a, "x": f0["x"][:, :2], "p": f0["pressure"], "steps": summary["steps"],
            "dt": dt, "wall": wall}


def lattice_scenario(eps):
    rng = np.random.RandomState(20000290)  # J. Comput. Phys. 159, 290
    centres = (np.arange(N_LATTICE) + 0.5) * DX
    zones = []
    for yc in centres:
        for xc in centres:
            v = rng.uniform(-V_NOISE, V_NOISE, 2)
            zones.append({"region": box([xc - 0.25 * DX, yc - 0.25 * DX],
                                        [xc + 0.25 * DX, yc + 0.25 * DX]),
                          "velocity_m_s": [float(v[0]), float(v[1])]})
    side = N_LATTICE * DX
    return {
        "scenario": {"name": "sph-tensile-lattice", "dimension": 2, "end_time_s": T_LATTICE,
                     "description": "a lattice under uniform tension in a walled box"},
        "time": {"energy_stop_error": 0.0},
        "output": {"interval_s": T_LATTICE / 4, "history_every": 10},
        "domain": {"min_m": [0.0, 0.0], "max_m": [side, side]},
        "materials": [{"name": "water", "model": "tait", "rho0_kg_m3": RHO0, "c0_m_s": C0,
                       "gamma": GAMMA}],
        "parts": [{
            "name": "water", "method": "sph", "material": "water", "spacing_m": DX,
            "region": box([0.0, 0.0], [side, side]),
            "initial": {"density_kg_m3": 990.0},
            "sph": {"walls": ["left", "right", "bottom", "top"], "tensile_epsilon": eps},
            "zones": zones,
        }],
    }


def nearest_neighbour(x):
    """Each particle's distance to its nearest neighbour [m] (brute force; N <= 900)."""
    d = np.hypot(x[:, None, 0] - x[None, :, 0], x[:, None, 1] - x[None, :, 1])
    np.fill_diagonal(d, np.inf)
    return d.min(axis=1)


def run_lattice(eps, tag):
    d = scratch(f"sph_tensile_{tag}")
    path = write_scenario(d / "lattice.toml", lattice_scenario(eps),
                          comment="lattice under tension (tests/verification/sph_tensile)")
    summary, wall = run(path, d / "out")
    rows = []
    for t, p in frames(d / "out", "water"):
        f = load_frame(p)
        nn = nearest_neighbour(f["x"][:, :2]) / DX
        rows.append((t, float(nn.min()), float(nn.std()), float(f["pressure"].mean())))
    return summary, wall, rows


class Cluster(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tension = run_cluster(990.0, EPS, "tension")
        cls.control = run_cluster(990.0, 0.0, "tension_off")
        cls.compression = run_cluster(1010.0, EPS, "compression")
        cls.ref_p, cls.ref_t = cluster_acceleration(cls.tension["x"], 990.0, EPS)
        cls.ref_c, ref_c_t = cluster_acceleration(cls.compression["x"], 1010.0, EPS)
        assert not ref_c_t.any()
        cls.err_tension = cls.rel(cls.tension["a"], cls.ref_p + cls.ref_t)
        cls.err_control = cls.rel(cls.control["a"], cls.ref_p)
        cls.err_correction = cls.rel(cls.tension["a"] - cls.control["a"], cls.ref_t)
        cls.err_compression = cls.rel(cls.compression["a"], cls.ref_c)
        share = np.abs(cls.ref_t).max() / np.abs(cls.ref_p).max()
        wall = cls.tension["wall"] + cls.control["wall"] + cls.compression["wall"]
        print(f"cluster: crater {wall:.2f} s for 3 runs; p = {cls.tension['p'][0]:.2f} / "
              f"{cls.compression['p'][0]:.2f} Pa; "
              f"correction / pressure term (max) = {share:.4f}\n"
              f"  max |a - formula| / max |formula|: eps 0.2 under tension {cls.err_tension:.2e}, "
              f"eps 0 {cls.err_control:.2e}, the correction alone {cls.err_correction:.2e}, "
              f"eps 0.2 under compression {cls.err_compression:.2e}", file=sys.stderr)
        for i, (a, ref) in enumerate(zip(cls.tension["a"] - cls.control["a"], cls.ref_t)):
            print(f"  particle {i} at ({cls.tension['x'][i][0] / DX:.1f}, "
                  f"{cls.tension['x'][i][1] / DX:.1f}) dx: correction ({a[0]:+.6e}, {a[1]:+.6e}) "
                  f"m/s^2, formula ({ref[0]:+.6e}, {ref[1]:+.6e})", file=sys.stderr)

    @staticmethod
    def rel(a, ref):
        return float(np.abs(a - ref).max() / np.abs(ref).max())

    def test_setup(self):
        for run_ in (self.tension, self.control, self.compression):
            self.assertEqual(run_["steps"], 1)
            self.assertTrue(math.isclose(run_["dt"], DT, rel_tol=1e-12))
            self.assertEqual(len(run_["x"]), 6)
        self.assertTrue(np.allclose(self.tension["p"], tait_pressure(990.0), rtol=1e-12))
        self.assertTrue(np.allclose(self.compression["p"], tait_pressure(1010.0), rtol=1e-12))
        self.assertLess(self.tension["p"][0], 0)
        self.assertGreater(self.compression["p"][0], 0)

    def test_under_tension(self):
        self.assertLessEqual(self.err_tension, TOL)
        self.assertLessEqual(self.err_control, TOL)

    def test_correction_alone(self):
        self.assertLessEqual(self.err_correction, TOL)

    def test_none_under_compression(self):
        self.assertLessEqual(self.err_compression, TOL)


class Lattice(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.off = run_lattice(0.0, "lattice_off")
        cls.on = run_lattice(EPS, "lattice_on")
        for name, (summary, wall, rows) in (("eps 0", cls.off), (f"eps {EPS}", cls.on)):
            print(f"lattice, {name}: {summary['parts'][0]['count']} particles, "
                  f"{summary['steps']} steps, {wall:.2f} s, energy balance "
                  f"{100 * summary['energy']['balance_error']:+.2f} %", file=sys.stderr)
            for t, nn_min, nn_std, p in rows:
                print(f"  t = {t:.3f} s: nearest neighbour min {nn_min:.3f} dx, std "
                      f"{nn_std:.4f} dx; mean p {p:.1f} Pa", file=sys.stderr)

    def test_clumps_without(self):
        t, nn_min, _, _ = self.off[2][-1]
        self.assertTrue(math.isclose(t, T_LATTICE, rel_tol=1e-9))
        self.assertLess(nn_min, NN_CLUMPED, "the control run did not clump: the case does "
                                            "not show the instability")

    def test_regular_with(self):
        t, nn_min, nn_std, _ = self.on[2][-1]
        self.assertTrue(math.isclose(t, T_LATTICE, rel_tol=1e-9))
        self.assertGreater(nn_min, NN_REGULAR)
        self.assertLess(nn_std, NN_SPREAD)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
