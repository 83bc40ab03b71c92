# ctest-processors: 2
"""The paper-tunnel draft (issue 27; scenarios/drafts/paper-tunnel.toml): it loads, and its
first steps are the same on one and two threads.

- `crater check` accepts it: the lining and soil parts from the Gmsh file, their boundary
  conditions by physical group, the charge inside the ring (a mesh part's body is its nodes and
  elements, not its bounding box, for the overlap check);
- 60 steps (50 us) on 1 and 2 threads (nothing else running beside them: a 2-thread run
  beside another test waits at its barriers) write bit-identical frames, history and summary,
  with the lining probe's columns in history.csv.
- the crown line (probes.lining_soil): crown_line.csv lists the soil's nodes on the vertical
  above the crown, from the lining's outer wall (z = 3.75 m) to the ground (13.75 m), and its
  last displacements are those VTK's reader finds at the same nodes in the last soil frame;
  the history's interface and surface columns end on them, and each node's extremes bound its
  history. A crown line with no soil node on it exits 2 naming the key. The lining-soil contact carries the ground's
  weight from the first step; the products reach the lining only at 0.77 ms (step 900), so the
  charge-lining contact is not exercised here (test_thread_determinism covers sph-fem).
The whole run to 20 ms and its metrics are in docs/validation.md ("paper-tunnel").
"""
import csv
import os
import sys
import unittest
from pathlib import Path

import numpy as np

from crater_test import assert_bit_identical_runs, crater, read_pvd, read_vtu, scratch

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SCENARIO = SOURCE / "scenarios" / "drafts" / "paper-tunnel.toml"


class PaperTunnel(unittest.TestCase):
    def test_check(self):
        p = crater("check", SCENARIO)
        self.assertIn("lining", p.stdout)
        self.assertIn("soil", p.stdout)

    def test_first_steps_same_on_one_and_two_threads(self):
        work = scratch("paper_tunnel_threads")
        names = assert_bit_identical_runs(
            SCENARIO, work, sets=["scenario.end_time_s=5e-5", "output.interval_s=2.5e-5"])
        self.assertIn("history.csv", names)
        self.assertIn("crown_line.csv", names)
        out = Path(work) / "threads1"
        with open(out / "history.csv") as f:
            rows = list(csv.DictReader(f))
        self.assertIn("lining_crown_radial_m", rows[0])
        # The lining-soil contact acts (the soil's geostatic load on the lining).
        self.assertTrue(any(float(r["force_lining-soil_z"]) != 0 for r in rows))
        self.check_crown_line(out, rows)

    def check_crown_line(self, out, rows):
        with open(out / "crown_line.csv") as f:
            line = list(csv.DictReader(f))
        z = np.array([float(r["z_m"]) for r in line])
        self.assertAlmostEqual(z[0], 3.75, places=9)  # the lining's outer wall
        self.assertAlmostEqual(z[-1], 13.75, places=9)  # the ground
        self.assertTrue(np.all(np.diff(z) > 0))
        frames = read_pvd(out / "soil.pvd")
        pts, arrays, _, t = read_vtu(out / frames[-1][1])
        self.assertAlmostEqual(t, float(rows[-1]["time_s"]), places=12)
        x0 = pts - arrays["displacement"]
        for r, zk in zip(line, z):
            k = int(np.argmin(np.linalg.norm(x0 - np.array([0.0, 0.0, zk]), axis=1)))
            self.assertLess(np.linalg.norm(x0[k] - np.array([0.0, 0.0, zk])), 1e-9)
            self.assertEqual(k, int(r["node"]))
            self.assertAlmostEqual(float(r["up_displacement_m"]), arrays["displacement"][k][2],
                                   delta=1e-15)
        for col, r in (("soil_crown_line_interface_up_m", line[0]),
                       ("soil_crown_line_surface_up_m", line[-1])):
            h = np.array([float(row[col]) for row in rows])
            self.assertEqual(h[-1], float(r["up_displacement_m"]))
            self.assertLessEqual(h.max(), float(r["up_displacement_max_m"]))
            self.assertGreaterEqual(h.min(), float(r["up_displacement_min_m"]))
        # The lining carries the soil's weight: the interface settles.
        self.assertLess(float(line[0]["up_displacement_min_m"]), 0)

    def test_crown_line_without_soil_node_exits_2(self):
        # A 2D lining box whose crown has no node of the other part above it.
        work = scratch("paper_tunnel_no_crown_line")
        scenario = work / "no_line.toml"
        scenario.write_text(NO_LINE)
        p = crater("run", scenario, "--out", work / "out", "--force", "--quiet", check=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("probes.lining_soil", p.stderr)
        self.assertIn("no node on the crown line", p.stderr)


NO_LINE = """
[scenario]
name = "no-crown-line"
dimension = 2
end_time_s = 1.0e-6

[domain]
min_m = [-1.0, -2.0]
max_m = [4.0, 2.0]

[[materials]]
name = "steel"
model = "elastic"
rho0_kg_m3 = 7850
youngs_modulus_pa = 200e9
poisson_ratio = 0.3

[[parts]]
name = "lining"
method = "fem"
material = "steel"
spacing_m = 0.1
region = { type = "box", min_m = [0.0, 0.0], max_m = [1.0, 0.2] }

[[parts]]
name = "soil"
method = "fem"
material = "steel"
spacing_m = 0.1
region = { type = "box", min_m = [2.0, 0.0], max_m = [3.0, 0.2] }

[probes]
lining = "lining"
lining_axis_point_m = [0.5, -1.0]
lining_soil = "soil"
"""


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
