"""FEM parts from Gmsh mesh files (fem.mesh_file): the same plate read from a .msh file and built
by the structured generator gives the same run; malformed meshes and references to what a mesh
does not hold are input errors (exit 2) naming the file, line and key."""
import json
import sys
import unittest

import numpy as np

from crater_test import crater, read_vtu, run_scenario, scratch
from fem_meshes import rectangle_quads, write_msh41
from scenario_blocks import (STEEL_JC, box, boundary, compose_scenario, domain, material, output,
                             part, scenario_text)


def plate(mesh=None, group="clamp_left", top=(0.2, 0.02), spacing_m=None):
    """A clamped steel plate struck in its middle, in a domain [0, 0] to `top`: from the
    structured generator (mesh None) or from the Gmsh file `mesh`, clamped on its left by the
    physical group `group` (and, with spacing_m, a structured spacing as well)."""
    left = boundary("fixed", "left") if mesh is None else boundary("fixed", group=group)
    fem = {"mesh_file": mesh, "boundary": [left, boundary("fixed", "right")]}
    return scenario_text(compose_scenario(
        "fem-mesh", 2, 2e-5, description="a clamped plate struck in its middle",
        output=output(1e-5), domain=domain([0, 0], list(top)),
        materials=[material(STEEL_JC, a_pa=50e6, b_pa=176e6, n=0.52, c=None, m=None)],
        parts=[part("plate", "fem", "steel", 0.005 if mesh is None else spacing_m,
                    box([0, 0], [0.2, 0.02]) if mesh is None else None,
                    zones=[{"region": box([0.09, 0], [0.11, 0.02]), "velocity_m_s": [0, -100.0]}],
                    fem=fem)]))


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
        (cls.work / "structured.toml").write_text(plate())
        (cls.work / "mesh.toml").write_text(plate("plate.msh"))
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
        (self.work / "cw.toml").write_text(plate("cw.msh"))
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
        text = plate("plate.msh")
        line = text.split("\n").index('mesh_file = "plate.msh"') + 1
        self.check_fails(text, f"case.toml:{line}:", "parts[0].fem.mesh_file", "does not exist")

    def test_triangles_are_refused(self):
        self.check_fails(plate("plate.msh"), "plate.msh:", "triangles",
                         mesh=self.good_mesh_text(triangle=True))

    def test_undefined_node_names_the_line(self):
        text = self.good_mesh_text()
        lines = text.split("\n")
        k = lines.index("$Elements") + 3  # the first element
        fields = lines[k].split()
        fields[1] = "99999"
        lines[k] = " ".join(fields)
        self.check_fails(plate("plate.msh"), f"plate.msh:{k + 1}", mesh="\n".join(lines))

    def test_truncated_mesh(self):
        text = self.good_mesh_text()
        self.check_fails(plate("plate.msh"), "plate.msh", mesh=text[: len(text) // 2])

    def test_unknown_group(self):
        self.good_mesh_text()
        err = self.check_fails(plate("plate.msh", group="clamp"),
                               "parts[0].fem.boundary[0].group", "no physical group 'clamp'",
                               "'clamp_left'")
        self.assertIn("case.toml:", err)

    def test_mesh_outside_domain(self):
        self.good_mesh_text()
        self.check_fails(plate("plate.msh", top=(0.1, 0.02)),
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
        self.check_fails(plate("plate.msh"), f"plate.msh:{k + 1}", "parts[0].fem.mesh_file",
                         "degenerate element", mesh="\n".join(lines))

    def test_mesh_and_region_together(self):
        self.good_mesh_text()
        self.check_fails(plate("plate.msh", spacing_m=0.005), "parts[0].spacing_m",
                         "not used with fem.mesh_file")


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
