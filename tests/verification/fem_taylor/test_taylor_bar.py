"""Taylor bar impact in 3D (Hex8, Johnson-Cook with adiabatic heating), against the published
Johnson-Cook results of the same test.

Reference: O. Pantale, DynELA finite element code documentation, chapter "DynELA impact
sample cases", section "3D Taylor impact" (github.com/pantale/DynELA-v.-4.0,
Documentation/Samples-Impacts.tex; the code is described in O. Pantale et al., J. Comput.
Appl. Math. 168 (2004) 341-351). A 42CrMo4 steel rod, length 32.4 mm, radius 3.2 mm, hits a
rigid frictionless wall at 287 m/s; Johnson-Cook: E = 206.9 GPa, nu = 0.3, A = 806 MPa,
B = 614 MPa, C = 0.0089, n = 0.168, m = 1.1, rho = 7830 kg/m^3, c_p = 460 J/(kg K),
Taylor-Quinney 0.9, reference rate 1/s, T_0 = 20 C, T_m = 1540 C. At t = 80 us:
    Abaqus/Explicit:  L_f = 26.55 mm, D_f = 11.22 mm  (DynELA: 26.52 mm, 11.18 mm)
with D_f the diameter of the impact face.

crater's model: a quarter of the rod (symmetry planes x = 0 and z = 0), an O-grid of
48 hexahedra per section x 40 layers (1920 elements; tests/lib/fem_meshes.py writes it as a
Gmsh 4.1 file, read through fem.mesh_file), the wall as a symmetry condition on the impact face
(y = 0), which is how both references model the frictionless rigid wall.

Acceptance (issue 4/6 of FEM): L_f and D_f within 5 % of the Abaqus figures. The VTU frame at
80 us is read with VTK's reader.
"""
import sys
import unittest

import numpy as np

from crater_test import read_vtu, read_vtu_cells, run_scenario, scratch
from scenario_blocks import compose_scenario, domain, output, part, scenario_text, symmetry
from fem_meshes import quarter_cylinder_hex, write_msh41

L0, R0, V0 = 32.4e-3, 3.2e-3, 287.0
REF_L, REF_D = 26.55e-3, 11.22e-3

# 42CrMo4 (the references' Johnson-Cook set, see above), with adiabatic heating.
CRMO4 = {
    "name": "42CrMo4", "model": "johnson_cook", "rho0_kg_m3": 7830, "youngs_modulus_pa": 206.9e9,
    "poisson_ratio": 0.3, "a_pa": 806e6, "b_pa": 614e6, "n": 0.168, "c": 0.0089, "m": 1.1,
    "reference_strain_rate_1_s": 1.0, "thermal_softening": True, "room_temperature_k": 293.15,
    "melt_temperature_k": 1813.15, "specific_heat_j_kg_k": 460, "taylor_quinney": 0.9,
}

SCENARIO = scenario_text(compose_scenario(
    "taylor-bar", 3, 8e-5,
    description="Taylor impact of a 42CrMo4 rod at 287 m/s (DynELA / Abaqus benchmark)",
    output=output(2e-5), domain=domain([0, 0, 0], [0.004, 0.0325, 0.004]), materials=[CRMO4],
    parts=[part("rod", "fem", "42CrMo4", initial={"velocity_m_s": [0, -V0, 0]},
                fem={"mesh_file": "rod.msh", "boundary": symmetry("bottom", "left", "back")})]))


def write_case(work, core=4, ring=4, layers=40):
    nodes, hexes = quarter_cylinder_hex(R0, L0, core, ring, layers)
    write_msh41(work / "rod.msh", nodes, [(3, 5, "rod", hexes)])
    (work / "taylor.toml").write_text(SCENARIO)
    return work / "taylor.toml"


class TaylorBar(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("fem_taylor")
        cls.summary = run_scenario(write_case(cls.work), cls.work / "out")
        cls.points, _, _, cls.time = read_vtu(cls.work / "out" / "rod_000004.vtu")

    def test_final_length(self):
        length = self.points[:, 1].max()
        err = length / REF_L - 1
        print(f"t = {self.time * 1e6:.1f} us: final length {length * 1e3:.3f} mm, Abaqus "
              f"{REF_L * 1e3:.2f} mm ({100 * err:+.2f} %)")
        self.assertAlmostEqual(self.time, 8e-5, delta=1e-12)
        self.assertLess(abs(err), 0.05)

    def test_impact_face_diameter(self):
        face = self.points[np.abs(self.points[:, 1]) < 1e-9]
        diameter = 2 * np.hypot(face[:, 0], face[:, 2]).max()
        err = diameter / REF_D - 1
        print(f"impact face diameter {diameter * 1e3:.3f} mm, Abaqus {REF_D * 1e3:.2f} mm "
              f"({100 * err:+.2f} %)")
        self.assertLess(abs(err), 0.05)

    def test_energy_balance_and_hourglass(self):
        e = self.summary["energy"]
        final = e["final"]
        print(f"balance error {e['balance_error']:.2e}, hourglass / internal "
              f"{final['hourglass_j'] / final['internal_j']:.3f}, max plastic strain "
              f"{self.summary['parts'][0]['diagnostics']['max_plastic_strain']:.3f}")
        self.assertLess(abs(e["balance_error"]), 0.01)
        self.assertLess(final["hourglass_j"], 0.1 * final["internal_j"])


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
