"""FEM parts from Gmsh mesh files (fem.mesh_file): the same plate read from a .msh file and built
by the structured generator gives the same run; malformed meshes and references to what a mesh
does not hold are input errors (exit 2) naming the file, line and key."""
import json
import sys
import unittest

import numpy as np

from crater_test import crater, read_vtu, run_scenario, scratch
from fem_meshes import rectangle_quads, write_msh41

HEAD = """
[scenario]
name = "fem-mesh"
description = "a clamped plate struck in its middle"
dimension = 2
end_time_s = 2e-5
[output]
interval_s = 1e-5
[domain]
min_m = [0, 0]
max_m = [0.2, 0.02]
[[materials]]
name = "steel"
model = "johnson_cook"
rho0_kg_m3 = 7850
youngs_modulus_pa = 200e9
poisson_ratio = 0.3
a_pa = 50e6
b_pa = 176e6
n = 0.52
[[parts]]
name = "plate"
method = "fem"
material = "steel"
"""
STRUCTURED = """spacing_m = 0.005
region = { type = "box", min_m = [0, 0], max_m = [0.2, 0.02] }
[[parts.zones]]
region = { type = "box", min_m = [0.09, 0], max_m = [0.11, 0.02] }
velocity_m_s = [0, -100.0]
[[parts.fem.boundary]]
type = "fixed"
face = "left"
[[parts.fem.boundary]]
type = "fixed"
face = "right"
"""
FROM_MESH = """[[parts.zones]]
region = { type = "box", min_m = [0.09, 0], max_m = [0.11, 0.02] }
velocity_m_s = [0, -100.0]
[parts.fem]
mesh_file = "plate.msh"
[[parts.fem.boundary]]
type = "fixed"
group = "clamp_left"
[[parts.fem.boundary]]
type = "fixed"
face = "right"
"""


def write_plate(path, clockwise=False, triangle=False):
    nodes, quads, sides = rectangle_quads((0, 0), (0.2, 0.02), (40, 4), clockwise=clockwise)
    blocks = [(2, 3, "plate", quads), (1, 1, "clamp_left", sides["left"])]
    if triangle:
        blocks.append((2, 2, "plate", [quads[0][:3]]))
    write_msh41(path, nodes, blocks)


class MeshFileRuns(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("fem_mesh_input")
        (cls.work / "structured.toml").write_text(HEAD + STRUCTURED)
        (cls.work / "mesh.toml").write_text(HEAD + FROM_MESH)
        write_plate(cls.work / "plate.msh")

    def test_mesh_file_equals_structured_mesh(self):
        a = run_scenario(self.work / "structured.toml", self.work / "a")
        b = run_scenario(self.work / "mesh.toml", self.work / "b")
        self.assertEqual(a["parts"][0]["count"], b["parts"][0]["count"])
        pa, va, _, _ = read_vtu(self.work / "a" / "plate_000002.vtu")
        pb, vb, _, _ = read_vtu(self.work / "b" / "plate_000002.vtu")
        # Same node numbering (row by row) in both: compare node by node.
        scale = np.abs(va["displacement"]).max()
        diff = np.abs(va["displacement"] - vb["displacement"]).max() / scale
        print(f"largest displacement {scale:.3e} m; mesh file vs structured: {diff:.1e} relative")
        self.assertGreater(scale, 1e-5)
        self.assertLess(diff, 1e-9)
        self.assertAlmostEqual(a["energy"]["final"]["internal_j"] / b["energy"]["final"]["internal_j"],
                               1.0, delta=1e-9)

    def test_clockwise_quads_are_reordered_with_a_warning(self):
        write_plate(self.work / "cw.msh", clockwise=True)
        (self.work / "cw.toml").write_text(HEAD + FROM_MESH.replace("plate.msh", "cw.msh"))
        proc = crater("check", self.work / "cw.toml")
        self.assertIn("numbered clockwise", proc.stderr + proc.stdout)
        b = run_scenario(self.work / "cw.toml", self.work / "cw")
        self.assertEqual(b["status"], "completed")


class MeshFileErrors(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("fem_mesh_errors")

    def check_fails(self, scenario_text, *fragments, mesh=None):
        path = self.work / "case.toml"
        path.write_text(scenario_text)
        if mesh is not None:
            (self.work / "plate.msh").write_text(mesh)
        proc = crater("check", path, check=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        for fr in fragments:
            self.assertIn(fr, proc.stderr)
        self.assertNotIn("terminate called", proc.stderr)
        return proc.stderr

    def good_mesh_text(self, **kw):
        write_plate(self.work / "plate.msh", **kw)
        return (self.work / "plate.msh").read_text()

    def test_missing_mesh_file(self):
        (self.work / "plate.msh").unlink(missing_ok=True)
        text = HEAD + FROM_MESH
        line = text.split("\n").index('mesh_file = "plate.msh"') + 1
        self.check_fails(text, f"case.toml:{line}:", "parts[0].fem.mesh_file", "does not exist")

    def test_triangles_are_refused(self):
        self.check_fails(HEAD + FROM_MESH, "plate.msh:", "triangles", mesh=self.good_mesh_text(triangle=True))

    def test_undefined_node_names_the_line(self):
        text = self.good_mesh_text()
        lines = text.split("\n")
        k = lines.index("$Elements") + 3  # the first element
        fields = lines[k].split()
        fields[1] = "99999"
        lines[k] = " ".join(fields)
        self.check_fails(HEAD + FROM_MESH, f"plate.msh:{k + 1}", mesh="\n".join(lines))

    def test_truncated_mesh(self):
        text = self.good_mesh_text()
        self.check_fails(HEAD + FROM_MESH, "plate.msh", mesh=text[: len(text) // 2])

    def test_unknown_group(self):
        self.good_mesh_text()
        err = self.check_fails(HEAD + FROM_MESH.replace('group = "clamp_left"', 'group = "clamp"'),
                               "parts[0].fem.boundary[0].group", "no physical group 'clamp'",
                               "'clamp_left'")
        self.assertIn("case.toml:", err)

    def test_mesh_outside_domain(self):
        self.good_mesh_text()
        self.check_fails(HEAD.replace("max_m = [0.2, 0.02]", "max_m = [0.1, 0.02]", 1) + FROM_MESH,
                         "parts[0].fem.mesh_file", "inside the domain")

    def test_degenerate_element_names_its_line(self):
        # The first element's first node moved onto its third: zero area. Found when the part
        # is built from the mesh (after the scenario is read), still an input error naming the
        # element's line and the scenario's key.
        text = self.good_mesh_text()
        lines = text.split("\n")
        k = lines.index("$Elements") + 3  # the first element: tag n0 n1 n2 n3
        fields = lines[k].split()
        fields[1] = fields[3]
        lines[k] = " ".join(fields)
        self.check_fails(HEAD + FROM_MESH, f"plate.msh:{k + 1}", "parts[0].fem.mesh_file",
                         "degenerate element", mesh="\n".join(lines))

    def test_mesh_and_region_together(self):
        self.good_mesh_text()
        self.check_fails(HEAD + "spacing_m = 0.005\n" + FROM_MESH, "parts[0].spacing_m",
                         "not used with fem.mesh_file")


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
