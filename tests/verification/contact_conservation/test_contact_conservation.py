"""Contacts between parts (issue 5/6 of coupling): conservation through the whole code path.

- An SPH gas blob hitting a free steel plate at 200 m/s (2D): the total momentum of both parts
  (read from the VTU frames with VTK's reader: SPH mass x velocity, FEM node mass x velocity)
  stays at its initial value to 1e-10 relative (the contact forces are equal and opposite);
  the energy balance closes to 1 %.
- A gas column at pressure p (ideal gas, 1000 kg/m^3, 100 MPa) held by free-slip SPH walls on
  three sides and an FEM plate below: the force the contact transmits to the plate, averaged
  over the second half of the run (history.csv, force_gas-plate_y), is p x width within 5 %
  (momentum balance of the gas at rest: the plate carries what the opposite wall pushes).
"""
import csv
import sys
import unittest

import numpy as np

from crater_test import read_vtu, run_scenario, scratch
from scenario_blocks import (AIR, SAND, STEEL, STEEL_JC, box, boundary, compose_scenario, contact,
                             domain, material, output, part, particle, scenario_text, vec)

GAS = material(AIR, name="gas", rho0_kg_m3=100)

BLOB = scenario_text(compose_scenario(
    "sph-fem", 2, 2e-4, description="gas blob hits a free plate",
    output=output(5e-5, history_every=10), domain=domain([-0.2, -0.1], [0.2, 0.3]),
    materials=[STEEL, GAS],
    parts=[part("plate", "fem", "steel", 0.005, box([-0.1, 0.0], [0.1, 0.01])),
           part("blob", "sph", "gas", 0.004, box([-0.03, 0.012], [0.03, 0.05]),
                initial={"pressure_pa": 1e5, "velocity_m_s": [0, -200.0]})],
    contacts=[contact("blob", "plate", penalty_scale=0.1)]))

COLUMN = scenario_text(compose_scenario(
    "gas-column", 2, 2e-3, description="a gas column at pressure p on a plate",
    output=output(5e-4, history_every=20), domain=domain([0, -0.01], [0.05, 0.05]),
    materials=[STEEL, material(GAS, rho0_kg_m3=1000)],
    parts=[part("plate", "fem", "steel", 0.0025, box([0, -0.01], [0.05, 0.0]),
                fem={"boundary": [boundary("fixed", "bottom")]}),
           part("gas", "sph", "gas", 0.0025, box([0, 0], [0.05, 0.05]),
                initial={"pressure_pa": 1e8}, sph={"walls": ["left", "right", "top"]})],
    contacts=[contact("gas", "plate", penalty_scale=0.1)]))


def momentum(out, parts, frame):
    total = np.zeros(3)
    for name, mass in parts:
        _, a, _, _ = read_vtu(out / f"{name}_{frame:06d}.vtu")
        total += (a["velocity"] * a[mass][:, None]).sum(axis=0)
    return total


def momentum_drift(out, parts, frames):
    p0 = momentum(out, parts, 0)
    worst = max(np.abs(momentum(out, parts, k) - p0).max() for k in range(1, frames))
    return worst / np.linalg.norm(p0), p0


class SphFem(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("contact_sph_fem")
        (cls.work / "blob.toml").write_text(BLOB)
        (cls.work / "column.toml").write_text(COLUMN)

    def test_blob_on_free_plate_conserves_momentum(self):
        out = self.work / "blob"
        s = run_scenario(self.work / "blob.toml", out)
        drift, p0 = momentum_drift(out, (("plate", "node_mass"), ("blob", "mass")), 5)
        _, a, _, _ = read_vtu(out / "plate_000004.vtu")
        plate = (a["velocity"] * a["node_mass"][:, None]).sum(axis=0)
        print(f"momentum drift {drift:.1e} of |p0| = {np.linalg.norm(p0):.2f} kg m/s; the plate "
              f"took {plate[1]:.2f} kg m/s; energy balance {s['energy']['balance_error']:.2e}")
        self.assertGreater(abs(plate[1]), 0.5 * np.linalg.norm(p0))  # the blob did hit the plate
        self.assertLess(drift, 1e-10)
        self.assertLess(abs(s["energy"]["balance_error"]), 0.01)

    def test_gas_column_transmits_pressure(self):
        out = self.work / "column"
        run_scenario(self.work / "column.toml", out)
        with open(out / "history.csv") as f:
            rows = list(csv.DictReader(f))
        t = np.array([float(r["time_s"]) for r in rows])
        fy = np.array([float(r["force_gas-plate_y"]) for r in rows])
        late = t >= 1e-3
        ratio = fy[late].mean() / (-1e8 * 0.05)
        print(f"plate force / (p A) = {ratio:.4f} (mean over 1-2 ms), range "
              f"{fy[late].min() / -5e6:.4f} .. {fy[late].max() / -5e6:.4f}")
        self.assertLess(abs(ratio - 1), 0.05)
        # Each part's own total energy (history.csv) adds up to the run's total.
        for r in rows:
            parts = float(r["energy_gas_j"]) + float(r["energy_plate_j"])
            self.assertAlmostEqual(parts, float(r["total_j"]),
                                   delta=1e-12 * abs(float(r["total_j"])))



def fixed_bottom(fixed=True):
    """[parts.fem] of a part whose bottom face is clamped (None: a free part)."""
    return {"boundary": [boundary("fixed", "bottom")]} if fixed else None


def grain_case(work, tag, dim=2, end=2e-4, frame=5e-5, g=0.0, y0=0.0026, vx=0.0, vy=-5.0,
               fixed=False):
    """A sand grain (r = 2.5 mm) at height y0 moving at (vx, vy) onto a steel plate."""
    text = scenario_text(compose_scenario(
        f"dem-fem-{tag}", dim, end, description="grains on a steel plate",
        output=output(frame, history_every=10),
        domain=domain(vec(dim, -0.05, -0.01, -0.02), vec(dim, 0.05, 0.05, 0.02),
                      gravity=vec(dim, 0, g, 0)),
        materials=[STEEL, SAND],
        parts=[part("plate", "fem", "steel", 0.0025,
                    box(vec(dim, -0.01, -0.005, -0.01), vec(dim, 0.01, 0.0, 0.01)),
                    fem=fixed_bottom(fixed)),
               part("grains", "dem", "sand", 0.005,
                    box(vec(dim, -0.02, 0.001, -0.02), vec(dim, 0.02, 0.04, 0.02)),
                    particles=[particle(vec(dim, 0, y0, 0), 0.0025, vec(dim, vx, vy, 0))])],
        contacts=[contact("grains", "plate", friction=0.4)]))
    path = work / f"{tag}.toml"
    path.write_text(text)
    return path


class DemFem(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("contact_dem_fem")

    def check_momentum(self, dim):
        out = self.work / f"oblique{dim}d"
        s = run_scenario(grain_case(self.work, f"oblique{dim}d", dim=dim, vx=2.0), out)
        drift, p0 = momentum_drift(out, (("plate", "node_mass"), ("grains", "mass")), 5)
        _, a, _, _ = read_vtu(out / "grains_000004.vtu")
        print(f"{dim}D grain on a free plate: momentum drift {drift:.1e}; rebound v = "
              f"{a['velocity'][0][:2]}, spin {a['angular_velocity'][0]}; energy balance "
              f"{s['energy']['balance_error']:.2e}")
        self.assertGreater(a["velocity"][0][1], 0)  # it bounced
        self.assertLess(drift, 1e-10)
        self.assertLess(abs(s["energy"]["balance_error"]), 0.01)

    def test_grain_on_free_plate_conserves_momentum_2d(self):
        self.check_momentum(2)

    def test_grain_on_free_plate_conserves_momentum_3d(self):
        self.check_momentum(3)

    def test_grain_resting_on_plate_carries_its_weight(self):
        out = self.work / "resting"
        s = run_scenario(grain_case(self.work, "resting", end=2e-3, frame=1e-3, g=-9.81,
                                    y0=0.0025, vy=0.0, fixed=True), out)
        with open(out / "history.csv") as f:
            last = list(csv.DictReader(f))[-1]
        weight = 1920 * np.pi * 0.0025**2 * 9.81
        ratio = -float(last["force_grains-plate_y"]) / weight
        print(f"plate force / m g = {ratio:.5f}; overlap {s['contacts']['contact_grains-plate_max_overlap_m']:.2e} m")
        self.assertLess(abs(ratio - 1), 0.01)

    def test_initial_penetration_is_not_pushed_out(self):
        # A grain laid 1 mm (0.4 r) into the plate at t = 0: the penalty spring holds no energy
        # for that overlap, so the grain must not be shot out (LS-DYNA ignores initial
        # penetrations the same way); it stays, at rest, and the energy balance holds.
        out = self.work / "initial"
        s = run_scenario(grain_case(self.work, "initial", end=1e-4, frame=5e-5, y0=0.0015,
                                    vy=0.0, fixed=True), out)
        p, a, _, _ = read_vtu(out / "grains_000002.vtu")
        speed = np.linalg.norm(a["velocity"][0])
        print(f"grain laid 1 mm deep: after 0.1 ms at y = {p[0][1] * 1e3:.4f} mm, |v| = "
              f"{speed:.2e} m/s; energy balance {s['energy']['balance_error']:.1e}")
        self.assertLess(speed, 1e-3)
        self.assertAlmostEqual(p[0][1], 0.0015, delta=1e-7)

    def test_fast_grain_does_not_pass_through(self):
        for v in (100.0, 1000.0):
            out = self.work / f"fast{int(v)}"
            run_scenario(grain_case(self.work, f"fast{int(v)}", end=5e-5, frame=2.5e-5,
                                    y0=0.0026 + v * 1e-6, vy=-v, fixed=True), out)
            p, a, _, _ = read_vtu(out / "grains_000002.vtu")
            print(f"{v:.0f} m/s: grain at y = {p[0][1] * 1e3:.3f} mm, v_y = {a['velocity'][0][1]:.1f} m/s")
            self.assertGreater(p[0][1], 0.0)
            self.assertGreater(a["velocity"][0][1], 0.0)


ERODING = scenario_text(compose_scenario(
    "dem-fem-eroding", 2, 3e-4,
    description="a grain drives through the eroding top rows of a plate",
    output=output(5e-5, history_every=1),
    domain=domain([-0.05, -0.02], [0.05, 0.05], gravity=[0, 0]),
    materials=[STEEL_JC, SAND],
    parts=[part("plate", "fem", "steel", 0.001, box([-0.01, -0.01], [0.01, 0.0]),
                fem={"erosion_plastic_strain": 0.3, **fixed_bottom()}),
           part("grains", "dem", "sand", 0.005, box([-0.02, 0.001], [0.02, 0.04]),
                particles=[particle([0.0, 0.0051], 0.005, [0, -300])])],
    contacts=[contact("grains", "plate", friction=0.4)]))


class DemFemErosion(unittest.TestCase):
    def test_grain_through_eroding_rows_keeps_the_energy_balance(self):
        # A 5 mm grain at 300 m/s into a plate of 1 mm elements sinks several elements deep;
        # the elements under it erode (plastic strain 0.3) while it still presses on them, and
        # the face behind each one appears inside the grain's overlap. That jump of the overlap
        # is not compression the spring was loaded through: it joins the grain's offset
        # (coupling.hpp). Pushed out instead, the spring throws the face nodes off and the
        # balance error is 7.7 (770 %; measured before the offset took such jumps). Bound: 2 %
        # (measured 0.8 %; the same grain at 100 m/s, which erodes nothing: 0.3 %).
        work = scratch("contact_dem_fem_erosion")
        path = work / "eroding.toml"
        path.write_text(ERODING)
        s = run_scenario(path, work / "out")
        plate = next(p for p in s["parts"] if p["name"] == "plate")
        eroded = plate["diagnostics"]["eroded_elements"]
        err = s["energy"]["balance_error"]
        print(f"grain through eroding rows: {eroded} elements eroded, energy balance {err:.2e}")
        self.assertGreaterEqual(eroded, 5)
        self.assertLess(abs(err), 0.02)


SPH_DEM = scenario_text(compose_scenario(
    "sph-dem", 2, 2e-4, description="a gas blob hits a few grains", output=output(5e-5),
    domain=domain([-0.1, -0.1], [0.1, 0.2]),
    materials=[GAS, SAND],
    parts=[part("blob", "sph", "gas", 0.004, box([-0.03, 0.012], [0.03, 0.05]),
                initial={"pressure_pa": 1e5, "velocity_m_s": [0, -100.0]}),
           part("grains", "dem", "sand", 0.006, box([-0.03, -0.01], [0.03, 0.01]))],
    contacts=[contact("blob", "grains")]))


class SphDem(unittest.TestCase):
    def test_blob_on_grains_conserves_momentum(self):
        work = scratch("contact_sph_dem")
        (work / "case.toml").write_text(SPH_DEM)
        out = work / "out"
        s = run_scenario(work / "case.toml", out)
        drift, p0 = momentum_drift(out, (("blob", "mass"), ("grains", "mass")), 5)
        _, a, _, _ = read_vtu(out / "grains_000004.vtu")
        grains = (a["velocity"] * a["mass"][:, None]).sum(axis=0)
        print(f"momentum drift {drift:.1e}; grains took {grains[1]:.3f} of {p0[1]:.3f} kg m/s; "
              f"energy balance {s['energy']['balance_error']:.2e}")
        self.assertLess(grains[1], 0.1 * p0[1])  # the grains were pushed down
        self.assertLess(drift, 1e-10)
        self.assertLess(abs(s["energy"]["balance_error"]), 0.01)


def fem_fem_case(work, tag, dim=2, end=6e-5, frame=1.5e-5, g=0.0, y0=0.0201, vx=2.0, vy=-10.0,
                 fixed=False):
    """A 20 mm steel block with its bottom at y0 moving at (vx, vy) onto a steel base."""
    text = scenario_text(compose_scenario(
        f"fem-fem-{tag}", dim, end, description="a steel block on another",
        output=output(frame, history_every=1),
        domain=domain(vec(dim, -0.05, -0.01, -0.01), vec(dim, 0.05, 0.1, 0.01),
                      gravity=vec(dim, 0, g, 0)),
        materials=[STEEL],
        parts=[part("top", "fem", "steel", 0.005,
                    box(vec(dim, -0.01, y0, -0.01), vec(dim, 0.01, y0 + 0.02, 0.01)),
                    initial={"velocity_m_s": vec(dim, vx, vy, 0)}),
               part("base", "fem", "steel", 0.005,
                    box(vec(dim, -0.02, 0.0, -0.01), vec(dim, 0.02, 0.02, 0.01)),
                    fem=fixed_bottom(fixed))],
        contacts=[contact("top", "base", friction=0.3)]))
    path = work / f"{tag}.toml"
    path.write_text(text)
    return path


class FemFem(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("contact_fem_fem")

    def check_momentum(self, dim):
        out = self.work / f"impact{dim}d"
        s = run_scenario(fem_fem_case(self.work, f"impact{dim}d", dim=dim), out)
        drift, p0 = momentum_drift(out, (("top", "node_mass"), ("base", "node_mass")), 5)
        _, a, _, _ = read_vtu(out / "top_000004.vtu")
        top = (a["velocity"] * a["node_mass"][:, None]).sum(axis=0) / a["node_mass"].sum()
        print(f"{dim}D block on a free block: momentum drift {drift:.1e} of |p0| = "
              f"{np.linalg.norm(p0):.3f} kg m/s; top block's velocity after {top[:2]} m/s; "
              f"energy balance {s['energy']['balance_error']:.2e}; max overlap "
              f"{s['contacts']['contact_top-base_max_overlap_m']:.1e} m")
        self.assertGreater(top[1], 0)  # it bounced
        self.assertLess(top[0], 2.0)   # friction slowed the sliding
        self.assertLess(drift, 1e-10)
        self.assertLess(abs(s["energy"]["balance_error"]), 0.01)

    def test_block_on_free_block_conserves_momentum_2d(self):
        self.check_momentum(2)

    def test_block_on_free_block_conserves_momentum_3d(self):
        self.check_momentum(3)

    def test_block_resting_on_block_carries_its_weight(self):
        out = self.work / "resting"
        s = run_scenario(fem_fem_case(self.work, "resting", end=2e-3, frame=1e-3, g=-9.81,
                                      y0=0.02, vx=0.0, vy=0.0, fixed=True), out)
        with open(out / "history.csv") as f:
            rows = list(csv.DictReader(f))
        t = np.array([float(r["time_s"]) for r in rows])
        fy = np.array([float(r["force_top-base_y"]) for r in rows])
        late = t >= 1e-3
        weight = 7850 * 0.02 * 0.02 * 9.81
        ratio = -fy[late].mean() / weight
        print(f"base force / m g = {ratio:.5f} (mean over 1-2 ms, {late.sum()} rows); range "
              f"{-fy[late].max() / weight:.3f} .. {-fy[late].min() / weight:.3f}; energy "
              f"balance {s['energy']['balance_error']:.1e}")
        self.assertLess(abs(ratio - 1), 0.01)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
