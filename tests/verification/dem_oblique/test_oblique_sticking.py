"""Oblique impact of a grain on a wall, no-slip (sticking) regime: Maw, Barber & Fawcett's
(1976, Wear 38, 101) limit of infinite friction, as in Thornton, Cummins & Cleary (2011,
Powder Technol. 210, 189) and test 7 of Chung & Ooi (2011, Granular Matter 13, 643).

With no slip, the contact's tangential compliance governs the rebound: the contact point's
tangential velocity u = v_t + R omega oscillates under the Mindlin stiffness while the Hertz
contact lasts, so it can come out reversed (the grain "bounces back" at small incidence). No
closed form exists; the reference is the contact-mechanics model integrated here,
independently of crater, with 4th-order Runge-Kutta over 40,000 steps of the contact:

    m y''      = F_n = (4/3) E* sqrt(R) delta^(3/2),     delta = R - y       (Hertz)
    xi'        = u,   F_t = -k_t xi,   k_t = 8 G* sqrt(R delta)             (Mindlin, no slip)
    m v_t'     = F_t,   I omega' = a F_t,   u = v_t + a omega,   a = R - delta

for a grain on a wall of its own material (E* = E / (2 (1 - nu^2)), G* = G / (2 (2 - nu))),
restitution 1 (no dashpot), friction 1e6 (never reached: F_t / F_n stays finite while the
contact is firm, and F_t = k_t xi -> 0 as delta -> 0). Sphere (I = 2/5 m R^2) and disk
(I = 1/2 m R^2, the same Hertz law as crater applies it in 2D; with hertz_2d =
"row_of_spheres" m and I are the disk's times the row's pitch 2R, docs/theory.md, DEM),
incidence 5 to 45 degrees at 1 m/s.

The spin after a sticking impact is a near-cancellation: the tangential force swings through
almost a whole oscillation, and the net impulse that spins the grain is a few per cent of its
swing. It is therefore sensitive to everything: the lever arm (a = R - delta, crater's and
LIGGGHTS' contact point; with a = R, as in rigid-body theory, the reference spin is 6 % higher
at every angle) and the time step (at 0.02 x the Rayleigh step crater's spin is 13-20 % high,
at 0.005 x within 3 %, at 0.00125 x within 0.1 %). The test runs at 0.004 x. Production runs
use 0.2-0.25 x: single impacts at that step resolve the sticking spin only roughly.

Tolerances (5 %, as the acceptance of issue 4 asks): the spin after impact within 5 % of the
reference, and the contact point's tangential velocity after impact within 5 % of its
incident value (it passes through zero in this range, so a relative error of its own would
mean nothing there).
"""
import math
import sys
import unittest

from crater_test import read_pvd, read_vtu, run_scenario, scratch
from scenario_blocks import (SAND, box, compose_scenario, domain, material, output,
                             part, particle, scenario_text, vec)

R, V = 0.0025, 1.0
RHO, G, NU = SAND["rho0_kg_m3"], SAND["shear_modulus_pa"], SAND["poisson_ratio"]
E_MOD = 2 * G * (1 + NU)
E_STAR = E_MOD / (2 * (1 - NU ** 2))
G_STAR = G / (2 * (2 - NU))
ANGLES = (5, 15, 30, 45)
GAP = 1e-6
FRACTION = 0.004  # time step: this x the Rayleigh step


def grain(dim, rows=False):
    m = RHO * math.pi * R * R if dim == 2 else RHO * 4 / 3 * math.pi * R ** 3
    if rows:  # hertz_2d = "row_of_spheres": one sphere of the row, the disk's times the pitch 2R
        m *= 2 * R
    inertia = (0.5 if dim == 2 else 0.4) * m * R * R
    return m, inertia


def reference(dim, theta, rows=False):
    """(u_out, omega_out, vn_out) of the no-slip model, by RK4 from first touch to separation."""
    m, inertia = grain(dim, rows)
    vn, vt = V * math.cos(theta), V * math.sin(theta)
    h = contact_time(dim, vn, rows) / 40000

    def rates(s):
        delta, ddelta, xi, vt_, w = s
        d = max(delta, 0.0)
        fn = 4 / 3 * E_STAR * math.sqrt(R) * d ** 1.5
        ft = -8 * G_STAR * math.sqrt(R * d) * xi
        a = R - d
        return (ddelta, -fn / m, vt_ + a * w, ft / m, a * ft / inertia)

    s = (0.0, vn, 0.0, vt, 0.0)
    while True:
        k1 = rates(s)
        k2 = rates(tuple(a + 0.5 * h * b for a, b in zip(s, k1)))
        k3 = rates(tuple(a + 0.5 * h * b for a, b in zip(s, k2)))
        k4 = rates(tuple(a + h * b for a, b in zip(s, k3)))
        s = tuple(a + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4)
                  for a, b1, b2, b3, b4 in zip(s, k1, k2, k3, k4))
        if s[0] <= 0 and s[1] < 0:
            break
    _, ddelta, _, vt_out, w_out = s
    return vt_out + R * w_out, w_out, -ddelta


def contact_time(dim, vn, rows=False):
    m, _ = grain(dim, rows)
    return 2.87 * (m * m / (R * E_STAR ** 2 * vn)) ** 0.2  # Hertz (Johnson 1985, section 11.4)


def scenario(dim, theta, fraction, rows=False):
    vt, vn = V * math.sin(theta), -V * math.cos(theta)
    end = GAP / -vn + 1.5 * contact_time(dim, -vn, rows)
    return scenario_text(compose_scenario(
        f"oblique-sticking-{dim}d", dim, end, output=output(end),
        domain=domain(vec(dim, -0.02, 0.0, -0.02), vec(dim, 0.02, 0.02, 0.02)),
        materials=[material(SAND, restitution=1.0)],
        parts=[part("grain", "dem", "sand", 0.005,
                    box(vec(dim, -0.01, 0.0, -0.02), vec(dim, 0.01, 0.01, 0.02)),
                    dem={"walls": ["bottom"], "wall_friction": 1.0e6, "wall_restitution": 1.0,
                         "rayleigh_fraction": fraction,
                         "hertz_2d": "row_of_spheres" if rows else None},
                    particles=[particle(vec(dim, -0.005, R + GAP), R, vec(dim, vt, vn))])]))


class ObliqueSticking(unittest.TestCase):
    def check(self, dim, theta_deg, fraction=FRACTION, rows=False):
        theta = math.radians(theta_deg)
        u_ref, w_ref, vn_ref = reference(dim, theta, rows)
        d = scratch(f"dem_oblique_sticking_{dim}d_{theta_deg}" + ("_rows" if rows else ""))
        (d / "case.toml").write_text(scenario(dim, theta, fraction, rows))
        run_scenario(d / "case.toml", d / "out", threads=1)
        _, last = read_pvd(d / "out" / "grain.pvd")[-1]
        _, arrays, _, _ = read_vtu(d / "out" / last)
        v = arrays["velocity"][0]
        w = arrays["angular_velocity"][0]
        # Spin about z; the contact point (below the centre) moves at v_x + R omega_z.
        wz = float(w) if dim == 2 else float(w[2])
        u = v[0] + R * wz
        u_in = V * math.sin(theta)
        print(f"{dim}D {theta_deg:2d} deg: u'/u = {u / u_in:+.4f} (ref {u_ref / u_in:+.4f}), "
              f"spin {wz:+9.3f} rad/s (ref {w_ref:+9.3f}), v_n' {v[1]:.4f} "
              f"(ref {vn_ref:.4f}) m/s", file=sys.stderr)
        self.assertGreater(v[1], 0, "the grain did not rebound")
        self.assertLessEqual(abs(u - u_ref) / u_in, 0.05)
        self.assertLessEqual(abs(wz / w_ref - 1), 0.05)

    def test_sphere(self):
        for theta in ANGLES:
            with self.subTest(theta=theta):
                self.check(3, theta)

    def test_disk(self):
        for theta in ANGLES:
            with self.subTest(theta=theta):
                self.check(2, theta)

    def test_disk_row_of_spheres(self):
        for theta in ANGLES:
            with self.subTest(theta=theta):
                self.check(2, theta, rows=True)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
