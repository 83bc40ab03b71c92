# ctest-timeout: 300
"""Planes of symmetry ([domain] symmetry_planes): half a symmetric problem against the whole.

The reference for SPH and FEM is the same problem modelled whole, by the same code but without
any symmetry condition (an independent computation: no mirror images, no constrained nodes):
  - SPH: a square of ideal gas (gamma 1.4, rho 1 kg/m^3, 1e5 Pa) with a core at 1e7 Pa expands
    into vacuum, 2D, 40 x 40 particles on x in [-0.2, 0.2] against 20 x 40 on [0, 0.2] with
    the left face a plane of symmetry, to 1e-4 s (the blast front crosses the plane's
    neighbourhood: every particle near x = 0 meets the mirror images). The
    half model's particles are paired with the whole one's by their position at t = 0.
  - FEM: a steel plate (elastic, 0.4 x 0.04 m, 40 x 4 quadrilaterals) clamped at both ends
    under a pressure of 50 MPa on the middle half of its top face, against the right half
    (clamped at its right end, the left face the plane) to 1e-4 s (the wave crosses the plate
    a few times). Nodes paired by reference position.
  - 3D, quarter models (planes on the left, x = 0, and back, z = 0): the gas (20^3 particles
    against 10 x 20 x 10, core at 1e7 Pa, to 5e-5 s) and a plate 0.4 x 0.04 x 0.4 m
    (20 x 2 x 20 hexahedra against 10 x 2 x 10) clamped on its four sides under 50 MPa on
    the middle quarter of its top face.
  The half model sees the same mass and forces per node or particle as the whole (a node on
  the plane has half the whole's mass and half its force), so the two agree to round-off,
  which grows over the steps of the run: tolerance 1e-9 of the field's scale (position:
  of the part's size; velocity, pressure, density: of their largest value in the whole
  model). Measured: SPH 4e-11 (velocity), 1e-12 (position, density, pressure); FEM 7e-16
  (velocity), 7e-17 (position); 3D quarters: SPH 6e-15, FEM 5e-16. Without the plane the half model fails at once: the SPH gas
  leaves through the open face (exit 3 at 4 us), the FEM plate's velocities differ by 0.39 of
  their scale.

DEM has no exact symmetry (a grain straddling the plane in the whole model has no place in
the half), so the plane is a frictionless rigid wall without rolling resistance (the issue's
definition): a sphere (3D, r = 5 cm, sand) thrown at it obliquely, (-1, 0.5, 0.3) m/s, must
leave with its tangential velocity unchanged and no spin, to round-off (no tangential force,
no torque: 1e-12), and with the normal velocity reversed by the grain-wall restitution 0.5
(Hertz-Mindlin with the part's restitution damping: within 2 %). Measured: tangential
(0.5, 0.3) m/s and spin 0 exactly, normal 0.4956 m/s (0.9 %). The same throw at an ordinary
wall (friction 0.5) leaves at (0.378, 0.227) m/s tangential with 7.1 rad/s of spin, which shows
the checks can fail.

Input errors of the key are in tests/scenarios/bad/symmetry_plane_*.toml.
"""
import sys
import unittest

import numpy as np

from crater_test import read_vtu, run_scenario, scratch
from scenario_blocks import (AIR, SAND, STEEL, boundary, box, compose_scenario, domain, output,
                             part, particle, scenario_text)

TOL = 1e-9


def sph_gas(half, symmetric=True):
    dom = domain([0.0 if half else -0.6, -0.6], [0.6, 0.6])
    if half and symmetric:
        dom["symmetry_planes"] = ["left"]
    return compose_scenario(
        "sym-sph", 2, 1e-4, output=output(1e-4), domain=dom,
        materials=[AIR],
        parts=[part("gas", "sph", "air", 0.01, box([0.0 if half else -0.2, -0.2], [0.2, 0.2]),
                    initial={"pressure_pa": 1e5},
                    zones=[{"region": box([-0.05, -0.05], [0.05, 0.05]),
                            "pressure_pa": 1e7}])])


def sph_gas_3d(quarter, symmetric=True):
    """The 3D case as a quarter: planes of symmetry on the left (x = 0) and back (z = 0)."""
    lo = 0.0 if quarter else -0.6
    dom = domain([lo, -0.6, lo], [0.6, 0.6, 0.6])
    if quarter and symmetric:
        dom["symmetry_planes"] = ["left", "back"]
    g = 0.0 if quarter else -0.2
    return compose_scenario(
        "sym-sph-3d", 3, 5e-5, output=output(5e-5), domain=dom,
        materials=[AIR],
        parts=[part("gas", "sph", "air", 0.02, box([g, -0.2, g], [0.2, 0.2, 0.2]),
                    initial={"pressure_pa": 1e5},
                    zones=[{"region": box([-0.06, -0.06, -0.06], [0.06, 0.06, 0.06]),
                            "pressure_pa": 1e7}])])


def fem_plate(half, symmetric=True):
    x0 = 0.0 if half else -0.2
    dom = domain([x0, -0.1], [0.2, 0.1])
    if half and symmetric:
        dom["symmetry_planes"] = ["left"]
    ends = [boundary("fixed", "right")] + ([] if half else [boundary("fixed", "left")])
    load = {"type": "pressure", "face": "top", "region": box([-0.1, -1.0], [0.1, 1.0]),
            "time_s": [0.0, 1e-4], "pressure_pa": [50e6, 50e6]}
    return compose_scenario(
        "sym-fem", 2, 1e-4, output=output(1e-4), domain=dom,
        materials=[STEEL],
        parts=[part("plate", "fem", "steel", 0.01, box([x0, 0.0], [0.2, 0.04]),
                    fem={"boundary": ends, "loads": [load]})])


def fem_plate_3d(quarter, symmetric=True):
    """The 3D plate as a quarter (planes on the left and back): 0.4 x 0.04 x 0.4 m clamped on
    its four sides, the pressure on the middle quarter of its top face."""
    lo = 0.0 if quarter else -0.2
    dom = domain([lo, -0.1, lo], [0.2, 0.1, 0.2])
    if quarter and symmetric:
        dom["symmetry_planes"] = ["left", "back"]
    sides = ["right", "front"] + ([] if quarter else ["left", "back"])
    load = {"type": "pressure", "face": "top", "region": box([-0.1, -1.0, -0.1], [0.1, 1.0, 0.1]),
            "time_s": [0.0, 1e-4], "pressure_pa": [50e6, 50e6]}
    return compose_scenario(
        "sym-fem-3d", 3, 5e-5, output=output(5e-5), domain=dom,
        materials=[STEEL],
        parts=[part("plate", "fem", "steel", 0.02, box([lo, 0.0, lo], [0.2, 0.04, 0.2]),
                    fem={"boundary": [boundary("fixed", f) for f in sides], "loads": [load]})])


def dem_throw(symmetric):
    dom = domain([0.0, 0.0, 0.0], [1.0, 1.0, 1.0])
    dem = {"radius_min_m": 0.05, "radius_max_m": 0.05, "wall_restitution": 0.5}
    if symmetric:
        dom["symmetry_planes"] = ["left"]
    else:
        dem.update(walls=["left"], wall_friction=0.5)
    return compose_scenario(
        "sym-dem", 3, 0.03, output=output(0.03), domain=dom,
        materials=[SAND],
        parts=[part("grain", "dem", "sand", 0.1, box([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), dem=dem,
                    particles=[particle([0.06, 0.5, 0.5], 0.05, [-1.0, 0.5, 0.3])])])


def run(work, name, scenario):
    path = work / f"{name}.toml"
    path.write_text(scenario_text(scenario))
    run_scenario(path, work / name, threads=1)
    return work / name


def frames(out, part_name):
    """The first and last frames of a part, the last in the first's order (by id: SPH
    particles are renumbered as they move)."""
    files = sorted(out.glob(f"{part_name}_*.vtu"))
    first, last = read_vtu(files[0]), read_vtu(files[-1])
    if "id" not in first[1]:
        return first, last
    row = {int(k): n for n, k in enumerate(last[1]["id"])}
    order = np.array([row[int(k)] for k in first[1]["id"]])
    return first, (last[0][order], {k: v[order] for k, v in last[1].items()}, last[2], last[3])


def pair_by_start(half_first, whole_first):
    """For each entity of the half model, the index of the whole model's entity that started
    at the same place."""
    key = lambda p: tuple(round(c / 1e-6) for c in p)  # noqa: E731
    where = {key(p): i for i, p in enumerate(whole_first[0])}
    return np.array([where[key(p)] for p in half_first[0]])


def worst(half_last, whole_last, match, fields):
    """The largest difference of each field (and the positions) over the paired entities,
    relative to the field's largest value in the whole model."""
    out = {"position": np.abs(half_last[0] - whole_last[0][match]).max() / 0.4}
    for f in fields:
        a, b = half_last[1][f], whole_last[1][f][match]
        out[f] = np.abs(a - b).max() / np.abs(whole_last[1][f]).max()
    return out


class SymmetryPlanes(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("symmetry_planes")

    def compare(self, make, part_name, fields, symmetric=True):
        name = part_name.removesuffix("3d")
        whole = frames(run(self.work, f"{part_name}_whole", make(False)), name)
        half = frames(run(self.work, f"{part_name}_half{int(symmetric)}",
                          make(True, symmetric)), name)
        match = pair_by_start(half[0], whole[0])
        return worst(half[1], whole[1], match, fields)

    def test_sph_half_equals_whole(self):
        err = self.compare(sph_gas, "gas", ["velocity", "density", "pressure"])
        print(f"SPH half vs whole, relative: {err}", file=sys.stderr)
        for f, e in err.items():
            self.assertLess(e, TOL, f)

    def test_sph_quarter_equals_whole_3d(self):
        err = self.compare(sph_gas_3d, "gas3d", ["velocity", "density", "pressure"])
        print(f"SPH 3D quarter vs whole, relative: {err}", file=sys.stderr)
        for f, e in err.items():
            self.assertLess(e, TOL, f)

    def test_fem_half_equals_whole(self):
        err = self.compare(fem_plate, "plate", ["velocity"])
        print(f"FEM half vs whole, relative: {err}", file=sys.stderr)
        for f, e in err.items():
            self.assertLess(e, TOL, f)

    def test_fem_quarter_equals_whole_3d(self):
        err = self.compare(fem_plate_3d, "plate3d", ["velocity"])
        print(f"FEM 3D quarter vs whole, relative: {err}", file=sys.stderr)
        for f, e in err.items():
            self.assertLess(e, TOL, f)

    def test_dem_grain_slides_without_spin(self):
        out = run(self.work, "grain_symmetry", dem_throw(True))
        _, (x, a, _, t) = frames(out, "grain")
        v, w = a["velocity"][0], a["angular_velocity"][0]
        print(f"DEM off the symmetry plane: v = {v}, omega = {w}", file=sys.stderr)
        self.assertGreater(x[0][0], 0.051, "the grain did not come back from the plane")
        self.assertLess(abs(v[1] - 0.5), 1e-12)
        self.assertLess(abs(v[2] - 0.3), 1e-12)
        self.assertLess(np.abs(w).max(), 1e-12)
        self.assertLess(abs(v[0] / 1.0 - 0.5), 0.02 * 0.5)  # restitution 0.5, normal 1 m/s

        # The same throw at a wall with friction: the checks above would fail.
        out = run(self.work, "grain_wall", dem_throw(False))
        _, (_, a, _, _) = frames(out, "grain")
        print(f"DEM off a friction wall: v = {a['velocity'][0]}, "
              f"omega = {a['angular_velocity'][0]}", file=sys.stderr)
        self.assertGreater(abs(a["velocity"][0][1] - 0.5), 1e-3)
        self.assertGreater(np.abs(a["angular_velocity"][0]).max(), 1e-3)


if __name__ == "__main__":
    unittest.main()
