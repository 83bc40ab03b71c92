# ctest-timeout: 120
"""XSPH (paper eq. 39; Monaghan 1989): the position update's smoothing velocity against its
closed form for a quadratic velocity field on a square lattice.

crater (docs/theory.md, SPH; src/sph/pair_terms.hpp xsph_velocity, sph_part.cpp advance) moves
a particle with
    dx_i/dt = v_i + dv_i,   dv_i = eps sum_j m_j / rhobar_ij (v_j - v_i) W_ij,
and leaves the velocity itself alone: dv_i is added to the drift of the position only.

Reference. For a velocity field v = (a_x y' + b_x y'^2, a_y x' + b_y x'^2) (x', y' measured
from the lattice's centre), uniform density rho and particle volume m/rho = dx^2, a particle
whose kernel support lies wholly inside the lattice has
    v_j - v_i = (a_x dy + b_x (dy^2 + 2 y'_i dy), a_y dx + b_y (dx^2 + 2 x'_i dx)),
dx, dy = x_j - x_i, y_j - y_i; the odd moments of the lattice vanish (it is symmetric about
every particle), so
    dv_i = eps (b_x, b_y) S2,   S2 = sum_j dx^2 W(r_ij) dy_ij^2   (the same for dx_ij^2):
the linear parts of the field (a_x, a_y) and the position of the particle drop out, and only
the curvature is smoothed. In the continuum S2 is the kernel's second moment,
    S2 -> int y^2 W dA = 1/2 int r^2 W dA = (5/18) h^2
for 2D Wendland C2 (W = 7/(4 pi h^2) (1 - q/2)^4 (2q + 1): pi/2 int_0^2h r^3 W dr with the
Beta integrals B(5,5) = 1/630, B(4,5) = 1/280). On the square lattice at h = 1.3 dx (crater's
default), summed exactly here from the kernel formula over an 11 x 11 patch (the support is
2.6 dx), S2 / ((5/18) h^2) = 0.98598 (the lattice factor; 0.9947 at 1.2 dx, 0.9995 at 2 dx).

Case: Tait water (rho0 = 1000 kg/m^3, c0 = 10 m/s), a 20 x 20 lattice, dx = 0.01 m, Wendland
C2 at h = 1.3 dx (the defaults), no artificial viscosity (av_alpha = av_beta = 0), eps = 0.5;
one particle per [[parts.zones]] entry, so that every particle starts with the field's exact
value at its centre; a_x = 30 /s, b_x = 1500 /(m s), a_y = -20 /s, b_y = -800 /(m s) (opposite
curvatures: both signs, both components). One fixed step dt = 1e-5 s (the stable step is about
3e-4 s). At t = 0 the density is rho0 everywhere, so the Tait pressure is exactly 0 and so is
the acceleration (no viscosity, no gravity): the step moves every particle by exactly
dt (v_i + dv_i), and the velocity does not change where the density stayed rho0 at the end of
the step (the continuity sum vanishes by symmetry more than 2h from the edges; its first
pressures appear at the edges).

Measured: dv = (x(dt) - x(0)) / dt - v(0) for the particles at least 3 dx from every edge (their
support, 2.6 dx, lies wholly in the lattice: 14 x 14 = 196), against eps (b_x, b_y) S2;
v(dt) - v(0) for those at least 6 dx from every edge (their neighbours' supports lie in the
lattice too: 8 x 8 = 64).

Tolerances:
- dv against the lattice sum: 1e-6 relative to eps |b| S2 (each particle, each component).
  The arithmetic is exact up to round-off (positions of 0.1 m moved by 3e-7 m: ~1e-10), so
  1e-6 leaves room for another compiler's summation order and nothing for a wrong term;
- dv against the continuum moment (5/18) h^2 (the analytic value, independent of any particle
  sum): 2 %, which holds the lattice factor (-1.40 %) and nothing more. A term that is missing
  (error 100 %), of the wrong sign (200 %) or twice as large (100 %) fails both;
- the velocity: |v(dt) - v(0)| <= 1e-6 eps |b| S2; XSPH added to the velocity instead (or as
  well) would move it by eps |b| S2 (0.035 m/s in x).
The position check also holds the linear part of the field to zero: a smoothing that saw v_i or
v_j alone, or the particle's position, would not cancel it (with v_i + v_j for v_j - v_i the
error is 165 eps |b| S2).

Second case, the density weight m_j / rhobar_ij, rhobar_ij = (rho_i + rho_j)/2 (which the
uniform lattice cannot tell from rho_i or rho_j): the same lattice with a density gradient,
rho = rho0 (1 + K y'), K = 1 /m (+-9.5 % over the block; m_j = rho_j dx^2, crater's mass of a
lattice particle), and a linear field v = (A_G y', 0), A_G = 50 /s. Then v_j - v_i = A_G dy and
m_j / rhobar_ij = dx^2 2 rho_j / (rho_i + rho_j) = dx^2 (1 + rho0 K dy / (2 rho_i) + O(dy^2)), so
    dv_i = eps A_G rho0 K / (2 rho_i) S2 (1 + O((K h)^2)),   dv_y = 0,
half of what m_j / rho_i would give and nothing for m_j / rho_j (the O(dy^2) term multiplies an
odd moment; the next is O((K h)^2): the closed form is off by 1.400 % where the lattice
factor alone gives 1.402 %). The Tait pressure is not uniform now, so the step also
moves the particles by a dt^2 / 2: the smoothing is measured as the difference of two runs,
eps = 0.5 and eps = 0 (same forces, the same step), dv = (x_on(dt) - x_off(dt)) / dt, at the same
196 particles. Tolerances as above: 1e-6 (relative to the largest expected dv) against the
lattice sum of 2 rho_j / (rho_i + rho_j) W dy over the same 11 x 11 patch, and 2 % against the
first-order closed form with the continuum moment; |dv_y| <= 1e-6 of it.
"""
import math
import sys
import time
import unittest

import numpy as np

from crater_test import scratch
from scenario_blocks import box, write_scenario
from sph_profiles import frames, load_frame, run

DX = 0.01             # m, lattice pitch
N = 20                # particles per side
H = 1.3 * DX          # m, smoothing length (h_factor 1.3, the default)
RHO0 = 1000.0         # kg/m^3
C0 = 10.0             # m/s
EPS = 0.5             # xsph_epsilon
A_X, B_X = 30.0, 1500.0    # v_x = A_X y' + B_X y'^2 [m/s]
A_Y, B_Y = -20.0, -800.0   # v_y = A_Y x' + B_Y x'^2 [m/s]
DT = 1e-5             # s, the one step
TOL_LATTICE = 1e-6    # relative to EPS |b| S2
TOL_CONTINUUM = 0.02  # relative to the continuum value
TOL_VELOCITY = 1e-6   # relative to EPS |b| S2
CENTRE = 0.5 * N * DX  # m, the lattice's centre (both axes); the block is [0, N DX]^2
A_G = 50.0            # /s, second case: v_x = A_G y'
K_G = 1.0             # /m, second case: rho = RHO0 (1 + K_G y')


def wendland_c2(r, h):
    """2D Wendland C2 kernel (paper eq. 28), support 2h [1/m^2]."""
    q = np.asarray(r, float) / h
    a = np.clip(1.0 - 0.5 * q, 0.0, None)
    return 7.0 / (4.0 * math.pi * h * h) * a ** 4 * (2.0 * q + 1.0)


def lattice_moment(h=H, dx=DX):
    """S2 = sum_j dx^2 W(r_ij) dy_ij^2 over an infinite square lattice (exact: the support is
    2h < 5 dx, so an 11 x 11 patch holds it) [m^2]."""
    k = np.arange(-5, 6) * dx
    x, y = np.meshgrid(k, k)
    return float(np.sum(dx * dx * wendland_c2(np.hypot(x, y), h) * y * y))


CONTINUUM_MOMENT = 5.0 / 18.0 * H * H  # int y^2 W dA for 2D Wendland C2 [m^2]


def field(x, y):
    """The prescribed velocity at (x, y) [m/s]."""
    xp, yp = x - CENTRE, y - CENTRE
    return A_X * yp + B_X * yp * yp, A_Y * xp + B_Y * xp * xp


def density_weight_sum(rho_i, h=H, dx=DX):
    """Second case: sum_j dx^2 2 rho_j / (rho_i + rho_j) W(r_ij) dy_ij over the lattice, for
    rho_j = rho_i + RHO0 K_G dy_ij [m]."""
    k = np.arange(-5, 6) * dx
    x, y = np.meshgrid(k, k)
    rho_j = rho_i + RHO0 * K_G * y
    return float(np.sum(dx * dx * 2 * rho_j / (rho_i + rho_j) * wendland_c2(np.hypot(x, y), h) * y))


def scenario(eps=EPS, gradient=False):
    centres = (np.arange(N) + 0.5) * DX
    zones = []
    for yc in centres:
        for xc in centres:
            zone = {"region": box([xc - 0.25 * DX, yc - 0.25 * DX],
                                  [xc + 0.25 * DX, yc + 0.25 * DX])}
            if gradient:
                zone["velocity_m_s"] = [A_G * (yc - CENTRE), 0.0]
                zone["density_kg_m3"] = RHO0 * (1.0 + K_G * (yc - CENTRE))
            else:
                vx, vy = field(xc, yc)
                zone["velocity_m_s"] = [float(vx), float(vy)]
            zones.append(zone)
    return {
        "scenario": {"name": "sph-xsph", "dimension": 2, "end_time_s": DT,
                     "description": "XSPH of a quadratic velocity field, one step"},
        "time": {"fixed_dt_s": DT},
        "output": {"interval_s": DT, "history_every": 1},
        "domain": {"min_m": [-0.05, -0.05], "max_m": [N * DX + 0.05, N * DX + 0.05]},
        "materials": [{"name": "water", "model": "tait", "rho0_kg_m3": RHO0, "c0_m_s": C0,
                       "gamma": 7.0}],
        "parts": [{
            "name": "water", "method": "sph", "material": "water", "spacing_m": DX,
            "region": box([0.0, 0.0], [N * DX, N * DX]),
            "sph": {"xsph_epsilon": eps, "av_alpha": 0.0, "av_beta": 0.0},
            "zones": zones,
        }],
    }


def by_id(f):
    order = np.argsort(f["id"])
    return {k: (v[order] if isinstance(v, np.ndarray) and len(v) == len(order) else v)
            for k, v in f.items()}


def interior(x, margin):
    """Particles whose centres lie at least `margin` inside every edge of the block."""
    lo, hi = margin, N * DX - margin
    return np.all((x[:, :2] > lo - 1e-9) & (x[:, :2] < hi + 1e-9), axis=1)


def run_case(eps=EPS, tag="xsph", gradient=False):
    """Runs the case; returns (summary, wall seconds, frame at 0, frame at DT), ordered by id."""
    d = scratch(f"sph_xsph_{tag}")
    path = write_scenario(d / "xsph.toml", scenario(eps, gradient),
                          comment="XSPH smoothing velocity (tests/verification/sph_xsph)")
    summary, wall = run(path, d / "out")
    fr = [load_frame(p) for _, p in frames(d / "out", "water")]
    return summary, wall, by_id(fr[0]), by_id(fr[-1])


class Xsph(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        t0 = time.monotonic()
        cls.summary, cls.wall, cls.f0, cls.f1 = run_case()
        cls.s2 = lattice_moment()
        cls.scale = EPS * max(abs(B_X), abs(B_Y)) * cls.s2
        x0, x1 = cls.f0["x"], cls.f1["x"]
        cls.dt = cls.f1["time"] - cls.f0["time"]
        cls.dv = (x1[:, :2] - x0[:, :2]) / cls.dt - cls.f0["velocity"][:, :2]
        cls.inner = interior(x0, 3 * DX)
        cls.deep = interior(x0, 6 * DX)
        expect = EPS * np.array([B_X, B_Y]) * cls.s2
        err = (cls.dv[cls.inner] - expect) / cls.scale
        cls.err_lattice = float(np.abs(err).max())
        mean = cls.dv[cls.inner].mean(axis=0)
        cls.err_continuum = (mean / (EPS * np.array([B_X, B_Y]) * CONTINUUM_MOMENT) - 1.0)
        dvel = cls.f1["velocity"][:, :2] - cls.f0["velocity"][:, :2]
        cls.err_velocity = float(np.abs(dvel[cls.deep]).max() / cls.scale)
        print(f"xsph: {cls.summary['parts'][0]['count']} particles, {cls.summary['steps']} "
              f"step(s), crater {cls.wall:.2f} s, test {time.monotonic() - t0:.2f} s\n"
              f"  S2 = {cls.s2:.6e} m^2 (lattice), continuum (5/18) h^2 = "
              f"{CONTINUUM_MOMENT:.6e} m^2, factor {cls.s2 / CONTINUUM_MOMENT:.5f}\n"
              f"  dv mean over {int(cls.inner.sum())} particles = ({mean[0]:.6e}, "
              f"{mean[1]:.6e}) m/s; expected ({expect[0]:.6e}, {expect[1]:.6e}) m/s\n"
              f"  max |dv - lattice| / (eps |b| S2) = {cls.err_lattice:.2e}\n"
              f"  mean dv / continuum - 1 = ({100 * cls.err_continuum[0]:+.3f} %, "
              f"{100 * cls.err_continuum[1]:+.3f} %)\n"
              f"  max |v(dt) - v(0)| / (eps |b| S2) over {int(cls.deep.sum())} particles = "
              f"{cls.err_velocity:.2e}", file=sys.stderr)

    def test_one_step(self):
        self.assertEqual(self.summary["steps"], 1)
        self.assertTrue(math.isclose(self.dt, DT, rel_tol=1e-12), f"step {self.dt} s")
        self.assertEqual(int(self.inner.sum()), (N - 6) ** 2)
        self.assertEqual(int(self.deep.sum()), (N - 12) ** 2)

    def test_initial_field(self):
        # The zones gave every particle the field's value at its centre.
        x0 = self.f0["x"]
        vx, vy = field(x0[:, 0], x0[:, 1])
        v = self.f0["velocity"]
        self.assertLess(np.abs(v[:, 0] - vx).max(), 1e-9 * np.abs(vx).max())
        self.assertLess(np.abs(v[:, 1] - vy).max(), 1e-9 * np.abs(vy).max())

    def test_against_lattice_sum(self):
        self.assertLessEqual(self.err_lattice, TOL_LATTICE,
                             f"max |dv - eps b S2| / (eps |b| S2) = {self.err_lattice:.3e}")

    def test_against_continuum_moment(self):
        for k, e in zip("xy", self.err_continuum):
            with self.subTest(component=k):
                self.assertLessEqual(abs(e), TOL_CONTINUUM,
                                     f"dv_{k} / (eps b (5/18) h^2) - 1 = {100 * e:+.3f} %")

    def test_velocity_unchanged(self):
        self.assertLessEqual(self.err_velocity, TOL_VELOCITY,
                             f"max |v(dt) - v(0)| / (eps |b| S2) = {self.err_velocity:.3e}")


class XsphDensityWeight(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        t0 = time.monotonic()
        cls.summary, wall_on, cls.f0, cls.on = run_case(EPS, "gradient_on", gradient=True)
        _, wall_off, f0_off, cls.off = run_case(0.0, "gradient_off", gradient=True)
        assert np.array_equal(cls.f0["x"], f0_off["x"])
        x0 = cls.f0["x"]
        cls.dt = cls.on["time"] - cls.f0["time"]
        cls.dv = (cls.on["x"][:, :2] - cls.off["x"][:, :2]) / cls.dt
        cls.inner = interior(x0, 3 * DX)
        rho = cls.f0["density"]
        lattice = np.array([EPS * A_G * density_weight_sum(r) for r in rho])
        closed = EPS * A_G * RHO0 * K_G / (2 * rho) * CONTINUUM_MOMENT
        cls.scale = float(np.abs(lattice[cls.inner]).max())
        cls.err_lattice = float(np.abs(cls.dv[cls.inner, 0] - lattice[cls.inner]).max()
                                / cls.scale)
        cls.err_closed = float(np.abs(cls.dv[cls.inner, 0] / closed[cls.inner] - 1).max())
        cls.err_y = float(np.abs(cls.dv[cls.inner, 1]).max() / cls.scale)
        print(f"xsph, density weight: crater {wall_on + wall_off:.2f} s for 2 runs, test "
              f"{time.monotonic() - t0:.2f} s; rho {rho[cls.inner].min():.1f} ... "
              f"{rho[cls.inner].max():.1f} kg/m^3 in the interior\n"
              f"  dv_x {cls.dv[cls.inner, 0].min():.6e} ... {cls.dv[cls.inner, 0].max():.6e} m/s\n"
              f"  max |dv_x - lattice| / max |lattice| = {cls.err_lattice:.2e}\n"
              f"  max |dv_x / (eps A K rho0 / (2 rho) (5/18) h^2) - 1| = "
              f"{100 * cls.err_closed:.3f} %\n"
              f"  max |dv_y| / max |lattice| = {cls.err_y:.2e}", file=sys.stderr)

    def test_setup(self):
        self.assertEqual(self.summary["steps"], 1)
        self.assertTrue(math.isclose(self.dt, DT, rel_tol=1e-12), f"step {self.dt} s")
        rho = RHO0 * (1 + K_G * (self.f0["x"][:, 1] - CENTRE))
        self.assertLess(np.abs(self.f0["density"] / rho - 1).max(), 1e-12)

    def test_against_lattice_sum(self):
        self.assertLessEqual(self.err_lattice, TOL_LATTICE)
        self.assertLessEqual(self.err_y, TOL_LATTICE)

    def test_against_closed_form(self):
        self.assertLessEqual(self.err_closed, TOL_CONTINUUM)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
