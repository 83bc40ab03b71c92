"""Head-on impact of two equal grains through the whole DEM code path (scenario -> DEM part ->
time loop -> history.csv / VTU), against the closed-form Hertz solution (Johnson 1985,
Contact Mechanics, section 11.4):

    delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5)
    t_c       = 2.87 (m*^2 / (R* E*^2 v))^(1/5)          (2.87 = 2.9432 / (15/16)^(2/5))

with v the approach speed, m* = m/2, R* = R/2, E* = E / (2 (1 - nu^2)), E = 2 G (1 + nu).
Grains: the paper's sand (R = 2.5 mm, rho = 1920 kg/m^3, G = 29 GPa, nu = 0.2), v = 1 m/s.
Spheres in 3D; disks in 2D (mass per metre of depth). With hertz_2d = "single_sphere" (the
default; the law as LIGGGHTS and LAMMPS apply it in 2D) the same closed form holds with the
disk's mass. With hertz_2d = "row_of_spheres" the disk is a row of spheres along the depth,
pitch p = r_1 + r_2 = 2R, the force per metre the sphere contact's divided by p for a sphere
carrying m* p (docs/theory.md, DEM): the closed form with m* p in place of m* (delta_max and t_c
(2R)^(2/5) = 0.12 times the single_sphere values).

Tolerance 2 % (issue 3/6 of DEM): the contact duration is read from history.csv rows written
every step (dt = 0.02 x the Rayleigh step, 0.3 % of t_c); the overlap from VTU frames every
t_c/100 around the peak, where the overlap varies by < 0.1 % between frames.

Normal restitution: with damping from e (Tsuji form, as LIGGGHTS), the rebound/approach speed
ratio from the kinetic energy after the impact is within 2 % of e for e = 0.3, 0.5, 0.9.
"""
import csv
import math
import sys
import unittest
from pathlib import Path

import numpy as np

from crater_test import read_pvd, read_vtu, run_scenario, scratch
from scenario_blocks import (SAND, approaching_pair, box, compose_scenario, domain, material,
                             output, part, scenario_text, vec)

R, V = 0.0025, 1.0
RHO, G, NU = SAND["rho0_kg_m3"], SAND["shear_modulus_pa"], SAND["poisson_ratio"]
GAP = 1.0e-5  # initial gap between the surfaces [m]


def scenario(dim, restitution, frame_interval, rows=False):
    end = GAP / V + 2.5 * hertz(dim, rows)[1]
    return scenario_text(compose_scenario(
        f"hertz-impact-{dim}d", dim, end, output=output(frame_interval, history_every=1),
        domain=domain(vec(dim, -0.02, -0.02, -0.02), vec(dim, 0.02, 0.02, 0.02)),
        materials=[material(SAND, restitution=restitution)],
        parts=[part("grains", "dem", "sand", 0.005,
                    box(vec(dim, -0.01, -0.005, -0.005), vec(dim, 0.01, 0.005, 0.005)),
                    dem={"rayleigh_fraction": 0.02,
                         "hertz_2d": "row_of_spheres" if rows else None},
                    particles=approaching_pair(dim, R + GAP / 2, R, V / 2))]))


def hertz(dim, rows=False):
    m = RHO * (math.pi * R**2 if dim == 2 else 4.0 / 3.0 * math.pi * R**3)
    ms, rs = m / 2, R / 2
    if rows:
        ms *= 2 * R  # one sphere of the row: the pitch r_1 + r_2 times the disks' m*
    es = 2 * G * (1 + NU) / (2 * (1 - NU**2))
    dmax = (15 * ms * V**2 / (16 * es * math.sqrt(rs))) ** 0.4
    tc = 2.87 * (ms**2 / (rs * es**2 * V)) ** 0.2
    return dmax, tc


def run(dim, restitution, frame_interval, tag, rows=False):
    d = scratch(f"dem_hertz_{tag}")
    path = d / "case.toml"
    path.write_text(scenario(dim, restitution, frame_interval, rows))
    summary = run_scenario(path, d / "out", threads=1)
    with open(d / "out" / "history.csv") as f:
        rows = list(csv.DictReader(f))
    return d / "out", summary, rows


class HertzImpact(unittest.TestCase):
    def check(self, dim, row_of_spheres=False):
        dmax_ref, tc_ref = hertz(dim, row_of_spheres)
        tag = f"{dim}d" + ("_rows" if row_of_spheres else "")
        out, summary, rows = run(dim, 1.0, tc_ref / 100, tag, row_of_spheres)
        self.assertEqual(summary["status"], "completed")
        # Contact duration: rows where the springs hold energy.
        t = np.array([float(r["time_s"]) for r in rows])
        e = np.array([float(r["contact_j"]) for r in rows])
        ke0 = float(rows[0]["kinetic_j"])
        touching = t[e > 1e-12 * ke0]
        self.assertGreater(len(touching), 10, "the grains never touched")
        tc = touching[-1] - touching[0]
        # Largest overlap over the frames (VTK's reader).
        overlap = 0.0
        for _, f in read_pvd(out / "grains.pvd"):
            pts, arrays, _, _ = read_vtu(out / f)
            dist = np.linalg.norm(pts[0] - pts[1])
            overlap = max(overlap, arrays["radius"].sum() - dist)
        print(f"{tag}: t_c = {tc:.4e} s (Hertz {tc_ref:.4e}, {100 * (tc / tc_ref - 1):+.2f} %), "
              f"delta_max = {overlap:.4e} m (Hertz {dmax_ref:.4e}, "
              f"{100 * (overlap / dmax_ref - 1):+.2f} %)", file=sys.stderr)
        self.assertLessEqual(abs(tc / tc_ref - 1), 0.02)
        self.assertLessEqual(abs(overlap / dmax_ref - 1), 0.02)
        # Elastic impact: kinetic energy returns, energy balance holds.
        self.assertAlmostEqual(float(rows[-1]["kinetic_j"]) / ke0, 1.0, delta=1e-6)

    def test_spheres_3d(self):
        self.check(3)

    def test_disks_2d(self):
        self.check(2)

    def test_disks_2d_row_of_spheres(self):
        self.check(2, row_of_spheres=True)

    def test_restitution(self):
        for e in (0.3, 0.5, 0.9):
            with self.subTest(e=e):
                _, _, rows = run(3, e, 1.0, f"e{e}")
                measured = math.sqrt(float(rows[-1]["kinetic_j"]) / float(rows[0]["kinetic_j"]))
                print(f"restitution {e}: measured {measured:.5f} ({100 * (measured / e - 1):+.3f} %)",
                      file=sys.stderr)
                self.assertLessEqual(abs(measured / e - 1), 0.02)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
