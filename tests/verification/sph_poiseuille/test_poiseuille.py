# ctest-timeout: 300
"""Laminar viscosity with no-slip walls: start-up of plane Poiseuille flow (2D SPH).

Reference: J. P. Morris, P. J. Fox and Y. Zhu, "Modeling low Reynolds number incompressible
flows using SPH", J. Comput. Phys. 136 (1997) 214-226, eq. 21: fluid at rest between fixed
plates y = 0 and y = H, driven from t = 0 by a body force g along them,
  u(y, t) = g/(2 nu) y (H - y)
            - sum_{n>=0} 4 g H^2 / (nu pi^3 (2n+1)^3) sin((2n+1) pi y / H)
                         exp(-(2n+1)^2 pi^2 nu t / H^2),
which tends to the steady profile, centreline velocity u_c = g H^2 / (8 nu).

crater has no periodic boundaries, so the channel is a finite slug of fluid, L = 12 H long,
with free ends: gravity along x, Adami no-slip walls (wall_slip = "no") on the bottom and top
faces only, laid along the whole domain box (which reaches H beyond each end). Far from the
ends the flow is the infinite channel's; Re = u_c H / nu = 0.025, so the centreline moves by
2 % of H by t_end. The profile is measured on the particles within H of the slug's middle at
t = 0 (800 particles, followed by id). The ends do reach in slowly: with L = 6 H the middle's
error at t = 1 s is 1.34 % (0.66 % here), and it grows past steady state (3.2 % at 3 s, 1.3 %
with 12 H), while the slug's mean velocity stays 1.0 % above the exact mean.

Case (Morris et al.'s parameters): H = 1 mm, nu = 1e-6 m^2/s (mu = 1e-3 Pa s, rho0 = 1000
kg/m^3), g = 2e-4 m/s^2, so u_c = 2.5e-5 m/s; 20 particles across (dx = 50 um), 240 x 20 =
4800 particles; cubic spline, h = 1.3 dx; Tait EOS, c0 = 0.01 m/s (Morris et al.'s bound
c^2 >= g H / 0.01 = 2e-5 m^2/s^2; Mach 2.5e-3), gamma = 7; no artificial viscosity
(av_alpha = av_beta = 0), no XSPH. The step is crater's own: here the viscous limit
0.125 h^2 / nu (Morris et al. eq. 12) times the safety factor 0.9, 4.75e-4 s, sets it; without
that limit (the CFL step alone, 7.4e-4 s) this run blew up (energy guard, t = 0.09 s), so the
test verifies the limit too. Run to t = 1 s = H^2/nu (the
slowest transient mode is then down to 5e-5 of u_c), frames every 0.1 s.

Kernel: the laminar term (eq. 36) summed over a square lattice gives a Laplacian of y^2 that is
0.963 of the exact one for Wendland C2 at h = 1.3 dx (the default; 0.985 at 2.0 dx) and 1.000
for the cubic spline at 1.3 dx, both with the 0.01 hbar^2 regulariser; with the default kernel
this case's steady centreline is 4.2 % fast (max error 4.4 % at 1 s), so the test uses the cubic
spline (docs/validation.md has both).

Measured: for each frame, the particle velocities u_x in the window against the series at
their own y (60 terms); error = max over the particles |u_sph - u| / u_c (max norm over the
channel, relative to the steady centreline velocity); also max |u_y| / u_c.

Tolerances (the issue's acceptance): max error <= 2 % of u_c at t = 0.1, 0.2, 0.5 and 1 s
(transient and steady); max |u_y| <= 1 % of u_c.
"""
import math
import sys
import unittest

import numpy as np

from crater_test import scratch
from scenario_blocks import box, write_scenario
from sph_profiles import frames, load_frame, run

H = 1e-3              # m, channel width (walls at y = 0 and y = H)
L = 12 * H            # m, slug length
NU = 1e-6             # m^2/s
RHO0 = 1000.0         # kg/m^3
MU = NU * RHO0        # Pa s
G = 2e-4              # m/s^2, along +x
C0 = 0.01             # m/s
N_ACROSS = 20
H_FACTOR = 1.3
KERNEL = "cubic_spline"
T_END = 1.0           # s
DT_OUT = 0.1          # s
U_C = G * H * H / (8 * NU)
CHECK_TIMES = (0.1, 0.2, 0.5, 1.0)
TOL = 0.02            # max |u - u_exact| / u_c
TOL_UY = 0.01         # max |u_y| / u_c


def exact(y, t, terms=60):
    """Morris, Fox & Zhu (1997) eq. 21: u(y, t) of the start-up flow between plates 0 and H."""
    y = np.asarray(y, float)
    u = G / (2 * NU) * y * (H - y)
    for n in range(terms):
        k = 2 * n + 1
        u -= (4 * G * H * H / (NU * math.pi ** 3 * k ** 3) * np.sin(k * math.pi * y / H)
              * math.exp(-k * k * math.pi ** 2 * NU * t / (H * H)))
    return u


def scenario(mu=MU, n_across=N_ACROSS, kernel=KERNEL, h_factor=H_FACTOR, c0=C0, length=L,
             t_end=T_END):
    dx = H / n_across
    h = h_factor * dx
    return {
        "scenario": {"name": "sph-poiseuille", "dimension": 2, "end_time_s": t_end,
                     "description": "start-up of plane Poiseuille flow (Morris et al. 1997)"},
        "output": {"interval_s": DT_OUT, "history_every": 100},
        "domain": {"min_m": [-H, 0.0], "max_m": [length + H, H], "gravity_m_s2": [G, 0.0]},
        "materials": [{"name": "water", "model": "tait", "rho0_kg_m3": RHO0, "c0_m_s": c0,
                       "gamma": 7.0, "background_pa": 0.0}],
        "parts": [{
            "name": "water", "method": "sph", "material": "water", "spacing_m": dx,
            "region": box([0.0, 0.0], [length, H]),
            "sph": {"walls": ["bottom", "top"], "wall_slip": "no", "viscosity_pa_s": mu,
                    "kernel": kernel, "h_factor": h_factor, "av_alpha": 0.0, "av_beta": 0.0},
        }],
    }


def run_case(tag="poiseuille", **case):
    """Runs the case; returns (summary, wall seconds, [(t, max error / u_c, max |u_y| / u_c,
    window's u_max / u(H/2, t), particles in the window)] per frame)."""
    d = scratch(f"sph_poiseuille_{tag}")
    path = write_scenario(d / "poiseuille.toml", scenario(**case),
                          comment="start-up of plane Poiseuille flow "
                                  "(tests/verification/sph_poiseuille)")
    summary, wall = run(path, d / "out")
    fr = [(t, load_frame(p)) for t, p in frames(d / "out", "water")]
    # The window: the particles within H of the slug's middle at t = 0, by id.
    f0 = fr[0][1]
    x0 = f0["x"][:, 0]
    mid = 0.5 * (x0.min() + x0.max())
    ids = f0["id"][np.abs(x0 - mid) <= H]
    rows = []
    for t, f in fr:
        sel = np.isin(f["id"], ids)
        y = f["x"][sel, 1]
        ux, uy = f["velocity"][sel, 0], f["velocity"][sel, 1]
        e = np.abs(ux - exact(y, t)) / U_C
        uc_t = float(exact(0.5 * H, t))
        rows.append((t, float(e.max()), float(np.abs(uy).max() / U_C),
                     float(ux.max() / uc_t) if uc_t > 0 else 0.0, int(sel.sum())))
    return summary, wall, rows


class Poiseuille(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.summary, cls.wall, cls.rows = run_case()
        print(f"poiseuille: {cls.summary['parts'][0]['count']} particles, "
              f"{cls.summary['steps']} steps, {cls.wall:.1f} s", file=sys.stderr)
        for t, e, ey, r, n in cls.rows:
            print(f"  t = {t:.2f} s: max |u - u_exact| / u_c = {100 * e:.3f} %, "
                  f"max |u_y| / u_c = {100 * ey:.3f} %, u_max / u_exact(H/2) = {r:.4f} "
                  f"({n} particles)", file=sys.stderr)

    def test_profile(self):
        by_t = {round(t, 9): (e, ey) for t, e, ey, _, _ in self.rows}
        for tc in CHECK_TIMES:
            with self.subTest(t=tc):
                self.assertIn(round(tc, 9), by_t, f"no frame at t = {tc} s")
                e, ey = by_t[round(tc, 9)]
                self.assertLessEqual(e, TOL, f"t = {tc} s: max |u - u_exact| / u_c = "
                                             f"{100 * e:.3f} % > {100 * TOL:g} %")
                self.assertLessEqual(ey, TOL_UY, f"t = {tc} s: max |u_y| / u_c = "
                                                 f"{100 * ey:.3f} % > {100 * TOL_UY:g} %")

    def test_window(self):
        t, _, _, _, n = self.rows[-1]
        self.assertTrue(math.isclose(t, T_END, rel_tol=1e-9), f"last frame at t = {t} s")
        self.assertEqual(n, 2 * N_ACROSS * N_ACROSS, "particles in the window at t_end")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
