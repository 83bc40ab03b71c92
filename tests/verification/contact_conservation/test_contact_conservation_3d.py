# ctest-timeout: 600
# ctest-cost: 25
"""Contacts between parts in 3D (issue 26): the 2D cases of test_contact_conservation.py, in 3D,
with the same references and tolerances.

- An SPH gas blob (ideal gas, 100 kg/m^3, 1e5 Pa; 0.06 x 0.038 x 0.06 m, 6 mm pitch) hitting a
  free steel plate (0.2 x 0.01 x 0.2 m, 1 cm hexahedra) at 200 m/s: the total momentum of both
  parts (VTU frames read with VTK's reader: SPH mass x velocity, FEM node mass x velocity) stays
  at its initial value to 1e-10 relative (the contact forces are equal and opposite); the energy
  balance closes to 1 %; the plate takes more than half the blob's momentum.
- The same blob at 100 m/s onto a bed of sand spheres (6 x 2 x 6 grains of 5 mm, free):
  momentum to 1e-10, energy 1 %, the grains pushed down.
- A gas column (ideal gas, 1000 kg/m^3, 100 MPa; a 5 cm cube at 5 mm pitch) held by free-slip
  SPH walls on its four sides and top and an FEM plate below (fixed at its bottom): the force
  the contact transmits to the plate, averaged over the second half of the run
  (history.csv, force_gas-plate_y), is p A (A = 0.05^2 m^2) within 5 % (momentum balance of the
  gas at rest).
Measured (2026-11-26): blob on the plate: momentum drift 2.9e-15, balance 1.1e-3, the plate
took 2.75 of 2.59 kg m/s; blob on spheres: drift 2.7e-15, balance 2.3e-4.

The gas column: 0.965 of p A (0.92-1.04 over 1-2 ms). Before the particle-surface search
required a centre behind a face to project onto it (src/contact/face_search.cpp), the 36
particles of the column's bottom edge fell through the plate within 20 us: each lay behind the
plane of the plate's side face, within r of it, and was pushed sideways by an overlap r - s.
"""
import csv
import sys
import unittest

import numpy as np

from crater_test import read_vtu, run_scenario, scratch
from scenario_blocks import (SAND, STEEL, box, boundary, compose_scenario, contact, domain,
                             output, part, scenario_text)
from test_contact_conservation import GAS, momentum_drift, material

BLOB_3D = compose_scenario(
    "sph-fem-3d", 3, 2e-4, description="gas blob hits a free plate (3D)",
    output=output(5e-5, history_every=10),
    domain=domain([-0.2, -0.1, -0.2], [0.2, 0.3, 0.2]),
    materials=[STEEL, GAS],
    parts=[part("plate", "fem", "steel", 0.01, box([-0.1, 0.0, -0.1], [0.1, 0.01, 0.1])),
           part("blob", "sph", "gas", 0.006, box([-0.03, 0.012, -0.03], [0.03, 0.05, 0.03]),
                initial={"pressure_pa": 1e5, "velocity_m_s": [0, -200.0, 0]})],
    contacts=[contact("blob", "plate", penalty_scale=0.1)])

SPH_DEM_3D = compose_scenario(
    "sph-dem-3d", 3, 2e-4, description="a gas blob hits a few spheres (3D)",
    output=output(5e-5), domain=domain([-0.1, -0.1, -0.1], [0.1, 0.2, 0.1]),
    materials=[GAS, SAND],
    parts=[part("blob", "sph", "gas", 0.006, box([-0.03, 0.012, -0.03], [0.03, 0.05, 0.03]),
                initial={"pressure_pa": 1e5, "velocity_m_s": [0, -100.0, 0]}),
           part("grains", "dem", "sand", 0.01, box([-0.03, -0.01, -0.03], [0.03, 0.01, 0.03]))],
    contacts=[contact("blob", "grains")])

COLUMN_3D = compose_scenario(
    "gas-column-3d", 3, 2e-3, description="a gas column at pressure p on a plate (3D)",
    output=output(5e-4, history_every=20),
    domain=domain([0, -0.01, 0], [0.05, 0.05, 0.05]),
    materials=[STEEL, material(GAS, rho0_kg_m3=1000)],
    parts=[part("plate", "fem", "steel", 0.005, box([0, -0.01, 0], [0.05, 0.0, 0.05]),
                fem={"boundary": [boundary("fixed", "bottom")]}),
           part("gas", "sph", "gas", 0.005, box([0, 0, 0], [0.05, 0.05, 0.05]),
                initial={"pressure_pa": 1e8},
                sph={"walls": ["left", "right", "top", "back", "front"]})],
    contacts=[contact("gas", "plate", penalty_scale=0.1)])


class Contacts3d(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("contact_3d")

    def run_case(self, name, scenario):
        path = self.work / f"{name}.toml"
        path.write_text(scenario_text(scenario))
        out = self.work / name
        return out, run_scenario(path, out)

    def test_blob_on_free_plate_conserves_momentum(self):
        out, s = self.run_case("blob", BLOB_3D)
        drift, p0 = momentum_drift(out, (("plate", "node_mass"), ("blob", "mass")), 5)
        _, a, _, _ = read_vtu(out / "plate_000004.vtu")
        plate = (a["velocity"] * a["node_mass"][:, None]).sum(axis=0)
        print(f"3D blob on a free plate: momentum drift {drift:.1e} of |p0| = "
              f"{np.linalg.norm(p0):.2f} kg m/s; the plate took {plate[1]:.2f} kg m/s; energy "
              f"balance {s['energy']['balance_error']:.2e}", file=sys.stderr)
        self.assertGreater(abs(plate[1]), 0.5 * np.linalg.norm(p0))  # the blob hit the plate
        self.assertLess(drift, 1e-10)
        self.assertLess(abs(s["energy"]["balance_error"]), 0.01)

    def test_blob_on_grains_conserves_momentum(self):
        out, s = self.run_case("sph_dem", SPH_DEM_3D)
        drift, p0 = momentum_drift(out, (("blob", "mass"), ("grains", "mass")), 5)
        _, a, _, _ = read_vtu(out / "grains_000004.vtu")
        grains = (a["velocity"] * a["mass"][:, None]).sum(axis=0)
        print(f"3D blob on spheres: momentum drift {drift:.1e}; grains took {grains[1]:.3f} of "
              f"{p0[1]:.3f} kg m/s; energy balance {s['energy']['balance_error']:.2e}",
              file=sys.stderr)
        self.assertLess(grains[1], 0.1 * p0[1])  # the grains were pushed down
        self.assertLess(drift, 1e-10)
        self.assertLess(abs(s["energy"]["balance_error"]), 0.01)

    def test_gas_column_transmits_pressure(self):
        out, _ = self.run_case("column", COLUMN_3D)
        with open(out / "history.csv") as f:
            rows = list(csv.DictReader(f))
        t = np.array([float(r["time_s"]) for r in rows])
        fy = np.array([float(r["force_gas-plate_y"]) for r in rows])
        late = t >= 1e-3
        pa = -1e8 * 0.05 * 0.05
        ratio = fy[late].mean() / pa
        r = np.sort(fy[late] / pa)
        print(f"3D plate force / (p A) = {ratio:.4f} (mean over 1-2 ms), range "
              f"{r[0]:.4f} .. {r[-1]:.4f}", file=sys.stderr)
        self.assertLess(abs(ratio - 1), 0.05)


if __name__ == "__main__":
    unittest.main()
