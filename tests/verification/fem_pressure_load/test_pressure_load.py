"""A pressure load ([[parts.fem.loads]] type = "pressure") on the end of an elastic column.

Setup: a steel column 0.4 m high, 20 mm wide (2D plane strain; 3D: 20 mm x 20 mm), elements of
5 mm, symmetry (roller) sides, so that the wave is one of uniaxial strain. The bottom face
carries p(t): a ramp from 0 to p0 = 100 MPa over 2 us, then p0 (the table's last time is
beyond the run). A compressive wave runs up at c_p; behind its front (Kolsky 1963, ch. 1):

    sigma_yy = -p0,   v_y = p0 / (rho c_p),   c_p = sqrt(M / rho),
    M = E (1 - nu) / ((1 + nu)(1 - 2 nu)),    pressure = p0 (1 + nu) / (3 (1 - nu))

At t = 50 us the front is at 0.29 m; the column between 0.02 m and 0.2 m is behind it.

Checks (VTU frames read with VTK's reader; summary.json):
- the mean element pressure and node velocity v_y there match the closed forms to 3 %
  (bulk viscosity smears the front; it does not change the plateau);
- momentum: sum m v_y equals the impulse A (p0 t - p0 t_ramp / 2), A the face area (2D: width
  x 1 m), to 1e-6 relative. The step is fixed (time.fixed_dt_s) so that the table's corner
  at 2 us is a step time: the velocity-Verlet kicks integrate the piecewise-linear p(t)
  exactly (trapezoidal rule), and only rounding is left;
- the energy balance (external work = the load's work, trapezoidal in the force) closes to
  1e-3 of the work done.
- a load limited to half the face by a region box delivers half the impulse (2D), to 2e-3:
  there the loaded faces tilt and stretch with the column (strains of order p0 / M = 4e-4),
  and the load follows the current faces.
"""
import sys
import unittest

import numpy as np

from crater_test import read_vtu, read_vtu_cells, run_scenario, scratch
from scenario_blocks import (STEEL, box, compose_scenario, domain, output, part, scenario_text,
                             symmetry, vec)

RHO, E, NU = STEEL["rho0_kg_m3"], STEEL["youngs_modulus_pa"], STEEL["poisson_ratio"]
P0 = 1e8
M = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU))
C_P = (M / RHO) ** 0.5
T_END, T_RAMP, WIDTH = 5e-5, 2e-6, 0.02


def case(work, dim, half=False):
    lo, hi = vec(dim, 0, 0, 0), vec(dim, WIDTH, 0.4, WIDTH)
    sides = ["left", "right"] + (["back", "front"] if dim == 3 else [])
    load = {"type": "pressure", "face": "bottom",
            "region": box([0.0, -1.0], [0.01, 1.0]) if half else None,
            "time_s": [0.0, T_RAMP, 1.0], "pressure_pa": [0.0, P0, P0]}
    text = scenario_text(compose_scenario(
        f"fem-pressure-{dim}d", dim, T_END,
        description="pressure step on the end of an elastic column",
        time={"fixed_dt_s": 2.5e-7}, output=output(2.5e-5), domain=domain(lo, hi),
        materials=[STEEL],
        parts=[part("column", "fem", "steel", 0.005, box(lo, hi),
                    fem={"boundary": symmetry(*sides), "loads": [load]})]))
    tag = f"{dim}d{'_half' if half else ''}"
    path = work / f"column{tag}.toml"
    path.write_text(text)
    out = work / tag
    return run_scenario(path, out), out


class PressureLoad(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("fem_pressure_load")

    def check(self, dim):
        s, out = case(self.work, dim)
        pts, a, _, t = read_vtu(out / "column_000002.vtu")
        self.assertAlmostEqual(t, T_END, delta=1e-12)
        area = WIDTH * (WIDTH if dim == 3 else 1.0)
        impulse = area * P0 * (T_END - T_RAMP / 2)
        momentum = (a["velocity"][:, 1] * a["node_mass"]).sum()
        rel = abs(momentum - impulse) / impulse
        behind = (pts[:, 1] > 0.02) & (pts[:, 1] < 0.2)
        v = a["velocity"][behind, 1].mean()
        v_exact = P0 / (RHO * C_P)
        cells = read_vtu_cells(out / "column_000002.vtu")
        centre_y = self.cell_centres_y(out / "column_000002.vtu")
        inside = (centre_y > 0.02) & (centre_y < 0.2)
        p = cells["pressure"][inside].mean()
        p_exact = P0 * (1 + NU) / (3 * (1 - NU))
        work = s["energy"]
        print(f"{dim}D: momentum {momentum:.9e} vs impulse {impulse:.9e} (rel {rel:.1e}); "
              f"v_y {v:.4f} vs {v_exact:.4f} m/s ({v / v_exact - 1:+.2%}); pressure "
              f"{p / 1e6:.3f} vs {p_exact / 1e6:.3f} MPa ({p / p_exact - 1:+.2%}); energy "
              f"balance {work['balance_error']:.2e}")
        self.assertLess(rel, 1e-6)
        self.assertLess(abs(v / v_exact - 1), 0.03)
        self.assertLess(abs(p / p_exact - 1), 0.03)
        self.assertLess(abs(work["balance_error"]), 1e-3)
        return momentum

    @staticmethod
    def cell_centres_y(path):
        # vtkmodules, as tests/lib/crater_test.py: python3-vtk9 and ParaView's Python both have it
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkFiltersCore import vtkCellCenters
        from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
        reader = vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(path))
        reader.Update()
        f = vtkCellCenters()
        f.SetInputData(reader.GetOutput())
        f.Update()
        return vtk_to_numpy(f.GetOutput().GetPoints().GetData())[:, 1]

    def test_column_2d(self):
        self.check(2)

    def test_column_3d(self):
        self.check(3)

    def test_region_loads_half_the_face(self):
        _, out = case(self.work, 2, half=True)
        _, a, _, _ = read_vtu(out / "column_000002.vtu")
        momentum = (a["velocity"][:, 1] * a["node_mass"]).sum()
        impulse = 0.5 * WIDTH * P0 * (T_END - T_RAMP / 2)
        print(f"half face: momentum {momentum:.9e} vs impulse {impulse:.9e}")
        self.assertLess(abs(momentum - impulse) / impulse, 2e-3)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
