# ctest-cost: 4
"""The resultant on an FEM face ([[gauges]] face = ..., issue 28), against the exact 1D solution.

The scene of crater verify's case fem-held-bar (verify/fem-held-bar.toml): an elastic steel bar
(L = 0.1 m, H = 5 mm, plane strain with Poisson's ratio 0: exactly a 1D bar, c = sqrt(E / rho) =
5047.5 m/s) moves at v0 = 10 m/s towards its left face, which a symmetry condition holds in x
from t = 0. A compression front sigma = rho c v0 leaves the held face and the support pushes back
with rho c v0 H per metre of depth (1.981e6 N/m) until the front, reflected at the free right
end, returns at 2L/c (39.6 us); for the next 2L/c the support holds the bar, which now moves
away, with the opposite force (e.g. Graff, "Wave Motion in Elastic Solids", 1975, section 1.4).
The gauge sums the nodes' reaction_force over the left face.

Asserted:
- the mean of the face's resultant reaction over t in [0.25, 0.75] x 2L/c is rho c v0 H within
  2 % (the front spreads over a few elements and rings behind, which the bulk viscosity damps;
  the mean over half the plateau averages the ringing), and over [1.25, 1.75] x 2L/c it is the
  opposite within 2 %;
- its y component is 0 (the symmetry plane holds x only), to 1e-9 of the x component;
- Newton's third law: the elements' forces on all nodes (internal_force summed over every node,
  a `sum = true` gauge over ids) add up to 0, to 1e-9 of the reaction, at every row;
- the gauge's sum at a frame's step equals the sum of the reaction_force that VTK's reader finds
  in that frame's VTU file at the face's nodes (x = 0 at t = 0), to 1e-9.
"""
import csv
import sys
import unittest

import numpy as np

from crater_test import SOURCE_DIR, read_pvd, read_vtu, run_scenario, scratch

E, RHO, V0 = 200e9, 7850.0, 10.0
L, H, DX = 0.1, 0.005, 0.001
C_BAR = (E / RHO) ** 0.5
T2 = 2 * L / C_BAR
NODES = int(round(L / DX) + 1) * int(round(H / DX) + 1)

# The scene is crater verify's case fem-held-bar (verify/fem-held-bar.toml, one 2L/c), run here
# over two 2L/c, with a second gauge: the elements' forces summed over every node.
SCENE = (SOURCE_DIR / "verify" / "fem-held-bar.toml").read_text() + f"""
[[gauges]]
name = "all"
part = "bar"
ids = [{", ".join(str(i) for i in range(NODES))}]
sum = true
fields = ["internal_force"]
"""
SETS = [f"scenario.end_time_s={2 * T2!r}", f"output.interval_s={T2 / 2!r}"]


class FaceResultant(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        d = scratch("fem_face_resultant")
        d.mkdir(parents=True, exist_ok=True)
        (d / "bar.toml").write_text(SCENE)
        cls.out = d / "out"
        run_scenario(d / "bar.toml", cls.out, threads=1, sets=SETS)
        with open(cls.out / "gauges.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        cls.header = list(rows[0])
        cls.t = np.array([float(r["time_s"]) for r in rows])
        cls.step = np.array([int(r["step"]) for r in rows])
        cls.rx = np.array([float(r["support.sum.reaction_force_x"]) for r in rows])
        cls.ry = np.array([float(r["support.sum.reaction_force_y"]) for r in rows])
        cls.fx = np.array([float(r["all.sum.internal_force_x"]) for r in rows])
        cls.fy = np.array([float(r["all.sum.internal_force_y"]) for r in rows])

    def test_columns(self):
        self.assertEqual(self.header, ["step", "time_s", "support.sum.reaction_force_x",
                                       "support.sum.reaction_force_y", "all.sum.internal_force_x",
                                       "all.sum.internal_force_y"])

    def test_support_force_is_rho_c_v0_area(self):
        expected = RHO * C_BAR * V0 * H
        for lo, hi, sign in ((0.25, 0.75, 1.0), (1.25, 1.75, -1.0)):
            window = (self.t >= lo * T2) & (self.t <= hi * T2)
            mean = self.rx[window].mean()
            print(f"t in [{lo}, {hi}] 2L/c: mean reaction {mean:.6g} N/m, rho c v0 H = "
                  f"{sign * expected:.6g} ({(mean / (sign * expected) - 1) * 100:+.3f} %), "
                  f"spread {self.rx[window].min():.4g} .. {self.rx[window].max():.4g}",
                  file=sys.stderr)
            self.assertAlmostEqual(mean / (sign * expected), 1.0, delta=0.02)
        self.assertLessEqual(np.abs(self.ry).max(), 1e-9 * np.abs(self.rx).max())

    def test_internal_forces_add_up_to_zero(self):
        scale = np.abs(self.rx).max()
        worst = max(np.abs(self.fx).max(), np.abs(self.fy).max())
        print(f"largest sum of the elements' nodal forces {worst:.3g} N/m "
              f"({worst / scale:.2e} of the reaction)", file=sys.stderr)
        self.assertLessEqual(worst, 1e-9 * scale)

    def test_gauge_sum_equals_the_frames(self):
        frames = read_pvd(self.out / "bar.pvd")
        pts0, _, _, _ = read_vtu(self.out / frames[0][1])
        face = np.abs(pts0[:, 0]) <= 1e-12
        self.assertEqual(int(face.sum()), int(round(H / DX)) + 1)
        checked = 0
        for t_frame, name in frames[1:]:
            _, arrays, _, _ = read_vtu(self.out / name)
            k = int(np.argmin(np.abs(self.t - t_frame)))
            self.assertLess(abs(self.t[k] - t_frame), 1e-12)
            total = arrays["reaction_force"][face, :2].sum(axis=0)
            scale = max(abs(self.rx[k]), 1.0)
            self.assertLessEqual(abs(total[0] - self.rx[k]), 1e-9 * scale, name)
            self.assertLessEqual(abs(total[1] - self.ry[k]), 1e-9 * scale, name)
            checked += 1
        self.assertGreaterEqual(checked, 3)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
