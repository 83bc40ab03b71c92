"""[parts.sph] density = "summation": the density and smoothing length crater writes for a
particle set at rest, against the same definition evaluated here, independently, by brute
force over every pair and every mirror image.

Definition (docs/theory.md, "Summation density"): rho_i = sum_j m_j W(|x_i - x_j|, h_i) over the
particle itself, the other particles and their mirror images in the free-slip walls (each face
and, at a corner, both), with h_i = h_factor (m_i / rho_i)^(1/D), at most 3 h_factor
(m_i / rho0)^(1/D). The test solves that pair of equations per particle by bisection on h
(to 1e-13) with numpy; crater uses Newton on its neighbour lists and stops at
|rho_sum - m (h_factor/h)^D| <= 1e-6 of the latter, which puts h within about 1e-6 / D of
the root: tolerance 1e-5 relative on both h and rho.

Cases (a 12 x 9 lattice of 10 mm at 1 kg/m^3, an ideal gas at rest, 2D; a 6 x 5 x 4 lattice
in 3D):
  walls:  free-slip walls on every face: the images complete every kernel, so every particle
          sees the infinite lattice and all densities are equal (spread checked: 1e-9), and
          equal to the brute-force sum: rho0 x 1.0109 (2D) and 1.0098 (3D), the lattice sum's
          own excess at h = 1.3 dx (the Wendland kernels' self-contribution bias, Dehnen & Aly
          2012, MNRAS 425, 1068, sec. 5);
  free:   no walls, open domain: a free surface, where the summation reads low (a corner
          particle at a fraction of rho0) and h grows to the cap; equal to the brute force.
The written frame at t = 0 holds the state of the first force stage (rho and h from the sum).
"""
import sys
import unittest

import numpy as np

from crater_test import scratch
from scenario_blocks import AIR, box, material, write_scenario
from sph_profiles import frames, load_frame, run

H_FACTOR = 1.3
H_CAP = 3.0
DX = 0.01
RHO0 = 1.0
TOL = 1e-5
SIZES = {2: (12, 9), 3: (6, 5, 4)}


def wendland(r, h, dim):
    sigma = 7.0 / (4 * np.pi) if dim == 2 else 21.0 / (16 * np.pi)
    q = np.minimum(r / h, 2.0)
    return sigma / h ** dim * (1 - q / 2) ** 4 * (2 * q + 1)


def images(x, lo, hi, walls):
    """x and its mirror images in the walled faces: each face, and every combination of
    faces on different axes (corners)."""
    pts = [x]
    for axis in range(x.shape[1]):
        new = []
        for face in (lo[axis], hi[axis]) if walls else ():
            for p in pts:
                q = p.copy()
                q[:, axis] = 2 * face - q[:, axis]
                new.append(q)
        pts += new
    return np.concatenate(pts)


def reference(x, m, dim, lo, hi, walls):
    """(rho, h) per particle by bisection on g(h) = sum_j m W(r_ij, h) - m (h_factor/h)^D."""
    src = images(x, lo, hi, walls)
    cap = H_CAP * H_FACTOR * (m / RHO0) ** (1.0 / dim)
    rho, hs = np.empty(len(x)), np.empty(len(x))
    for i, xi in enumerate(x):
        r = np.linalg.norm(src - xi, axis=1)

        def g(h):
            return m * wendland(r, h, dim).sum() - m * (H_FACTOR / h) ** dim

        a, b = 0.2 * H_FACTOR * DX, cap
        if g(b) < 0:  # no root below the cap: the cap holds
            h = b
        else:
            for _ in range(200):
                c = 0.5 * (a + b)
                if g(c) < 0:
                    a = c
                else:
                    b = c
                if b - a < 1e-13 * b:
                    break
            h = 0.5 * (a + b)
        hs[i] = h
        rho[i] = m * wendland(r, h, dim).sum()
    return rho, hs


def case(dim, walls):
    n = SIZES[dim]
    hi = [k * DX for k in n]
    margin = 0.0 if walls else 0.2
    faces = ["left", "right", "bottom", "top", "back", "front"][:2 * dim]
    scen = {
        "scenario": {"name": f"summation-{dim}d", "dimension": dim, "end_time_s": 1e-9},
        "output": {"interval_s": 1e-9},
        "domain": {"min_m": [-margin] * dim, "max_m": [h + margin for h in hi]},
        "materials": [material(AIR, name="gas", rho0_kg_m3=RHO0)],
        "parts": [{
            "name": "gas", "method": "sph", "material": "gas", "spacing_m": DX,
            "region": box([0.0] * dim, hi),
            "initial": {"density_kg_m3": RHO0, "pressure_pa": 1.0},
            "sph": {"density": "summation", "h_factor": H_FACTOR,
                    **({"walls": faces, "wall_slip": "free"} if walls else {})},
        }],
    }
    d = scratch(f"sph_summation_{dim}d_{'walls' if walls else 'free'}")
    path = write_scenario(d / "s.toml", scen, comment="summation density (tests/verification/"
                                                      "sph_summation)")
    run(path, d / "out")
    f = load_frame(frames(d / "out", "gas")[0][1])
    x = f["x"][:, :dim]
    m = float(f["mass"][0])
    rho, h = reference(x, m, dim, np.zeros(dim), np.array(hi), walls)
    return f, rho, h


class SummationDensity(unittest.TestCase):
    def check(self, dim, walls):
        f, rho, h = case(dim, walls)
        err_rho = np.max(np.abs(f["density"] / rho - 1))
        err_h = np.max(np.abs(f["smoothing_length"] / h - 1))
        print(f"{dim}D {'walls' if walls else 'free surface'}: rho {f['density'].min():.5f}"
              f"-{f['density'].max():.5f} kg/m^3 (reference {rho.min():.5f}-{rho.max():.5f}), "
              f"h/dx {h.min() / DX:.4f}-{h.max() / DX:.4f}; largest differences rho "
              f"{err_rho:.2e}, h {err_h:.2e}", file=sys.stderr)
        self.assertLessEqual(err_rho, TOL)
        self.assertLessEqual(err_h, TOL)
        return f, rho, h

    def test_walls_2d(self):
        f, _, _ = self.check(2, True)
        self.assertLessEqual(np.ptp(f["density"]) / np.mean(f["density"]), 1e-9)

    def test_walls_3d(self):
        f, _, _ = self.check(3, True)
        self.assertLessEqual(np.ptp(f["density"]) / np.mean(f["density"]), 1e-9)

    def test_free_surface_2d(self):
        f, rho, h = self.check(2, False)
        self.assertLess(rho.min(), 0.5 * RHO0)  # a corner reads low: the documented limitation

    def test_free_surface_3d(self):
        self.check(3, False)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
