"""The 3D probes (issue 26): the ground surface averaged in rings about the crater's axis, the
crater's depth and radius read off it, and the plate's perforated area, against geometry known
exactly.

Rings. A bed of grains of radius R on a simple cubic lattice of pitch 2R (top at z = 0) with a
spherical bowl removed (every grain whose centre lies in the sphere): rim radius A, depth H
(sphere radius RS = (A^2 + H^2) / 2H), depth below z = 0
  drop(rho) = sqrt(RS^2 - rho^2) - (RS - H)   (rho < A; 0 outside).
surface_profile.csv must hold rings of width w = surface_bin_m about the axis, each the mean
over the columns whose centres lie in it; the independent answer is the same mean of the
bowl's exact surface over each column's square (sampled finely here). The probe finds a
column's surface from the solid volume in its cells, within about a grain diameter
(docs/theory.md, "Probes"): the tolerance on every ring's height is 2R. The bowl is there at
t = 0 and nothing moves in the few steps of the run (the lattice touches without overlap), so
the drop is zero. Three runs: a full model with the axis given by the detonation point of an
(unlit) SPH charge, the same with `[probes] axis_m` instead and no charge (the same profile,
bit for bit), and a quarter model (symmetry planes x = 0 and y = 0, the bowl at the corner)
whose axis defaults to that corner: its rings are the full model's.

Crater. A crater that opens during the run (class CraterFromErodedPlug): a square recess
filled by a steel plug that erodes in a few steps; depth and radius against the exact profile.

Perforation. A steel plate (quarter model, symmetry planes x = 0 and y = 0; two hexahedra
through its thickness) whose nodes in two patches start with a large vertical velocity: at the
corner the bottom nodes move down and the top ones up, in a patch further out only the bottom
nodes move down. The elements there stretch and erode by plastic strain; which ones is the
run's (deterministic) business, and the test asks only that the plate ends with columns eroded
through, columns eroded in one layer only, and intact ones. plate_perforated_area_m2 must be
four times (the two symmetry planes) the area that a raster over the final VTU file's reference
(undeformed: points - displacement) element footprints finds covered by no live element: an
independent reading of the same definition, exact here (the footprints are squares of the
raster's pitch x 8). A 2D plate (one symmetry plane, x = 0) does the same with a length x 1 m
(x 2). tests/unit/solver/test_probe_geometry.cpp checks designed patterns against hand
answers."""
# ctest-timeout: 120
import csv
import json
import math
import sys
import unittest

import numpy as np

from crater_test import crater, read_pvd, scratch
from scenario_blocks import (SAND, STEEL_JC, TNT, box, compose_scenario, domain,
                             output, part, particle, write_scenario)

R = 0.01          # grain radius [m]
W = 4 * R         # surface_bin_m: columns and rings of 4R (2 x 2 stacks of grains)
A, H = 0.25, 0.1  # the bowl's rim radius and depth [m]
RS = (A * A + H * H) / (2 * H)
BED = 0.16        # the bed's depth below z = 0 [m]
# The full model's bowl axis: off the domain's centre (0.4, 0.4), and off the columns' centres
# and corners (a column whose centre lies exactly on a ring's edge falls on either side of it
# by round-off).
AXIS = (0.39, 0.43)
END_S = 1e-5      # a few DEM steps


def bowl_drop(rho):
    """The bowl's exact depth below z = 0 at distance rho from its axis."""
    rho = np.asarray(rho, dtype=float)
    return np.where(rho < A, np.sqrt(np.maximum(RS * RS - rho * rho, 0)) - (RS - H), 0.0)


def bed_grains(lo_xy, hi_xy, axis):
    """The lattice bed over [lo_xy, hi_xy] minus the bowl about `axis`."""
    xs = np.arange(lo_xy[0] + R, hi_xy[0], 2 * R)
    ys = np.arange(lo_xy[1] + R, hi_xy[1], 2 * R)
    zs = np.arange(-BED + R, 0.0, 2 * R)
    centre = np.array([axis[0], axis[1], RS - H])
    out = []
    for x in xs:
        for y in ys:
            for z in zs:
                if np.linalg.norm(np.array([x, y, z]) - centre) >= RS:
                    out.append(particle([float(x), float(y), float(z)], R))
    return out


def bowl_scenario(name, lo_xy, hi_xy, axis, *, charge=False, axis_m=None, symmetry=None):
    soil = part("soil", "dem", "sand", 2 * R, box([lo_xy[0], lo_xy[1], -BED], [hi_xy[0], hi_xy[1], 0.0]),
                dem={"radius_min_m": R, "radius_max_m": R},
                particles=bed_grains(lo_xy, hi_xy, axis))
    parts = [soil]
    if charge:
        # Unlit during the run (it lights at 1 s): only its detonation point matters.
        c = [axis[0], axis[1], 0.08]
        parts.append(part("charge", "sph", "tnt", 0.01,
                          box([c[0] - 0.02, c[1] - 0.02, 0.06], [c[0] + 0.02, c[1] + 0.02, 0.1]),
                          detonation=[{"point_m": c, "time_s": 1.0}]))
    d = domain([lo_xy[0], lo_xy[1], -BED], [hi_xy[0], hi_xy[1], 0.12], [0.0, 0.0, -9.81])
    if symmetry:
        d["symmetry_planes"] = symmetry
    probes = {"soil": "soil", "surface_bin_m": W, "axis_m": axis_m}
    return compose_scenario(name, 3, END_S, domain=d, output=output(END_S),
                            materials=[SAND, TNT] if charge else [SAND], parts=parts,
                            probes=probes)


def expected_rings(lo_xy, hi_xy, axis):
    """(r, drop) per ring: the mean over the ring's columns of the bowl's depth averaged over
    each column's square (20 x 20 samples), as the probe defines the profile."""
    nx = round((hi_xy[0] - lo_xy[0]) / W)
    ny = round((hi_xy[1] - lo_xy[1]) / W)
    s = (np.arange(20) + 0.5) / 20 * W
    rings = {}
    for i in range(nx):
        for j in range(ny):
            x0, y0 = lo_xy[0] + i * W, lo_xy[1] + j * W
            cx, cy = x0 + W / 2 - axis[0], y0 + W / 2 - axis[1]
            r = math.hypot(cx, cy)
            gx, gy = np.meshgrid(x0 + s - axis[0], y0 + s - axis[1])
            drop = float(bowl_drop(np.hypot(gx, gy)).mean())
            rings.setdefault(int(r // W), []).append((r, drop))
    return [(np.mean([a for a, _ in v]), np.mean([b for _, b in v]))
            for _, v in sorted(rings.items())]


def read_profile(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows, {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


class CraterProfile3D(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        work = scratch("probes_3d_crater")
        cls.runs = {}
        cases = {
            "detonation": ((0.0, 0.0), (0.8, 0.8), AXIS, dict(charge=True)),
            "axis_m": ((0.0, 0.0), (0.8, 0.8), AXIS, dict(axis_m=list(AXIS))),
            "quarter": ((0.0, 0.0), (0.4, 0.4), (0.0, 0.0), dict(symmetry=["left", "bottom"])),
        }
        for name, (lo, hi, axis, kw) in cases.items():
            path = write_scenario(work / f"{name}.toml", bowl_scenario(name, lo, hi, axis, **kw))
            out = work / name
            crater("run", path, "--out", out, "--force", "--quiet", "--threads", 1)
            with open(out / "summary.json") as f:
                m = json.load(f)["metrics"]
            cls.runs[name] = (out, m, expected_rings(lo, hi, axis))

    def test_profile_columns_and_axis(self):
        for name, (out, m, _) in self.runs.items():
            with self.subTest(run=name):
                rows, _ = read_profile(out / "surface_profile.csv")
                self.assertEqual(list(rows[0].keys()),
                                 ["r_m", "surface_initial_m", "surface_m", "dz_m"])
                axis = (0.0, 0.0) if name == "quarter" else AXIS
                self.assertEqual((m["crater_axis_x_m"], m["crater_axis_y_m"]), axis)

    def test_axis_from_detonation_point_and_from_axis_m_agree(self):
        a = (self.runs["detonation"][0] / "surface_profile.csv").read_text()
        b = (self.runs["axis_m"][0] / "surface_profile.csv").read_text()
        self.assertEqual(a, b)

    def test_rings_follow_the_bowl(self):
        for name, (out, m, expected) in self.runs.items():
            with self.subTest(run=name):
                _, p = read_profile(out / "surface_profile.csv")
                r_exp = np.array([r for r, _ in expected])
                z_exp = -np.array([d for _, d in expected])
                self.assertEqual(len(p["r_m"]), len(r_exp))
                np.testing.assert_allclose(p["r_m"], r_exp, atol=1e-9)
                for key in ("surface_initial_m", "surface_m"):
                    err = np.abs(p[key] - z_exp)
                    print(f"\n{name}: {key} error max {err.max() * 1e3:.2f} mm (tolerance "
                          f"{2e3 * R:.0f} mm) over {len(err)} rings", file=sys.stderr)
                    self.assertLess(err.max(), 2 * R)
                # The bowl was there at t = 0 and nothing moved: no drop, no crater.
                self.assertLess(np.abs(p["dz_m"]).max(), 1e-9)
                self.assertEqual(m["crater_depth_m"], 0.0)
                self.assertEqual(m["crater_radius_m"], 0.0)
                self.assertLess(abs(m["surface_settlement_max_m"]), 1e-9)
                self.assertNotIn("surface_settlement_max_x_m", m)


# --- a crater that opens during the run -------------------------------------------------------

PA, PH = 0.12, 0.08  # the plug's half-width and depth [m]: 3 x 2 columns' worth
PLUG_H = 0.04        # its elements' size


class CraterFromErodedPlug(unittest.TestCase):
    """The ground at t = 0 counts the plate's live elements where the soil was carved around
    it; a quarter model (symmetry planes x = 0 and y = 0) of the lattice bed has a square
    recess, half-width PA and depth PH, at the corner, filled by a steel plug (the probes'
    plate). Its nodes start with vertical velocities -V, 0, +V by layer (a uniform stretch),
    so that every element erodes by plastic strain within a few steps: the recess is a crater
    that opens during the run. Each column's drop is then PH inside the square and 0 outside
    (the square's edges are columns' edges), each ring's the fraction of its columns inside x
    PH. The axis defaults to the corner (the symmetry planes'). Tolerances: a ring's drop
    within 2R (the surface's accuracy), so the depth too; the radius (where the drop falls
    below R, between rings) within 2R over the slope of the exact profile between the two
    rings that bracket the crossing."""

    @classmethod
    def setUpClass(cls):
        work = scratch("probes_3d_plug")
        lo, hi = (0.0, 0.0), (0.4, 0.4)
        xs = np.arange(R, hi[0], 2 * R)
        zs = np.arange(-BED + R, 0.0, 2 * R)
        grains = [particle([float(x), float(y), float(z)], R)
                  for x in xs for y in xs for z in zs
                  if not (x < PA and y < PA and z > -PH)]
        e = 1e-3
        zones = [{"region": box([0, 0, z - e], [PA, PA, z + e]), "velocity_m_s": [0, 0, v]}
                 for z, v in [(-PH, -1000.0), (-PH / 2, 0.0), (0.0, 1000.0)]]
        d = domain([lo[0], lo[1], -BED], [hi[0], hi[1], 0.12], [0.0, 0.0, -9.81])
        d["symmetry_planes"] = ["left", "bottom"]
        scenario = compose_scenario(
            "plug", 3, 5e-5, domain=d, output=output(5e-5), materials=[SAND, STEEL_JC],
            parts=[part("soil", "dem", "sand", 2 * R, box([0, 0, -BED], [hi[0], hi[1], 0.0]),
                        dem={"radius_min_m": R, "radius_max_m": R}, particles=grains,
                        carve=["plug"]),
                   # A micrometre inside the recess: a grain touching the plug would be carved
                   # (or not) by the round-off of its lattice position.
                   part("plug", "fem", "steel", PLUG_H,
                        box([0, 0, -PH + 1e-6], [PA - 1e-6, PA - 1e-6, 0.0]),
                        zones=zones, fem={"erosion_plastic_strain": 0.3,
                                          "erode_inverted": True})],
            probes={"soil": "soil", "plate": "plug", "surface_bin_m": W})
        path = write_scenario(work / "plug.toml", scenario)
        cls.out = work / "out"
        crater("run", path, "--out", cls.out, "--force", "--quiet", "--threads", 1)
        with open(cls.out / "summary.json") as f:
            cls.m = json.load(f)["metrics"]
        # The exact profile: columns of side W over the quarter, drop PH inside the square.
        n = round(hi[0] / W)
        rings = {}
        for i in range(n):
            for j in range(n):
                cx, cy = (i + 0.5) * W, (j + 0.5) * W
                r = math.hypot(cx, cy)
                rings.setdefault(int(r // W), []).append((r, PH if cx < PA and cy < PA else 0.0))
        cls.expected = [(np.mean([a for a, _ in v]), np.mean([b for _, b in v]))
                        for _, v in sorted(rings.items())]

    def test_the_plug_is_gone(self):
        n = round(PA / PLUG_H) ** 2 * round(PH / PLUG_H)
        self.assertEqual(self.m["plate_eroded_elements"], n)
        self.assertEqual((self.m["crater_axis_x_m"], self.m["crater_axis_y_m"]), (0.0, 0.0))

    def test_ring_drops(self):
        _, p = read_profile(self.out / "surface_profile.csv")
        r_exp = np.array([r for r, _ in self.expected])
        d_exp = np.array([d for _, d in self.expected])
        np.testing.assert_allclose(p["r_m"], r_exp, atol=1e-9)
        # Flat at t = 0: the plug fills the recess.
        self.assertLess(np.abs(p["surface_initial_m"]).max(), 2 * R)
        err = np.abs(-p["dz_m"] - d_exp)
        print(f"\nplug: initial surface within {np.abs(p['surface_initial_m']).max() * 1e3:.3f} "
              f"mm of z = 0; ring drop error max {err.max() * 1e3:.2f} mm (tolerance "
              f"{2e3 * R:.0f} mm) over {len(err)} rings", file=sys.stderr)
        self.assertLess(err.max(), 2 * R)

    def test_depth_and_radius(self):
        r = np.array([a for a, _ in self.expected])
        d = np.array([b for _, b in self.expected])
        k = int(np.argmax(d <= R))  # the first ring outward whose exact drop is below R
        f = (d[k - 1] - R) / (d[k - 1] - d[k])
        radius = r[k - 1] + f * (r[k] - r[k - 1])
        tol = 2 * R / ((d[k - 1] - d[k]) / (r[k] - r[k - 1]))
        print(f"\nplug: depth {self.m['crater_depth_m']:.4f} m (exact {PH}); radius "
              f"{self.m['crater_radius_m']:.4f} m (exact profile's {radius:.4f}, tolerance "
              f"{tol:.4f}; the square's equal-area radius {2 * PA / math.sqrt(math.pi):.4f})",
              file=sys.stderr)
        self.assertLess(abs(self.m["crater_depth_m"] - PH), 2 * R)
        self.assertLess(abs(self.m["crater_radius_m"] - radius), tol)
        self.assertEqual(self.m["crater_radius_lower_bound"], 0.0)  # it ends inside the domain
        # Outside the crater and the ring next to it nothing moved.
        self.assertLess(abs(self.m["surface_settlement_max_m"]), 2 * R)
        self.assertGreater(self.m["surface_settlement_max_r_m"], self.m["crater_radius_m"] + W)


class AxisKey(unittest.TestCase):
    """probes.axis_m: [x, y], in 3D only; a wrong length, type or dimension exits 2 naming it."""

    def check(self, name, scenario):
        path = write_scenario(scratch("probes_3d_axis") / f"{name}.toml", scenario)
        return crater("check", path, check=False)

    def test_bad_axis_exits_2(self):
        tiny = [particle([0.01, 0.01, -0.01], R)]
        for name, value, needle in [("long", [0.1, 0.2, 0.3], "expected [x, y]"),
                                    ("short", [0.1], "got 1 entries"),
                                    ("text", "centre", "expected an array of numbers")]:
            with self.subTest(case=name):
                s = compose_scenario(
                    name, 3, END_S, domain=domain([0, 0, -0.1], [0.2, 0.2, 0.1]),
                    materials=[SAND],
                    parts=[part("soil", "dem", "sand", 2 * R, box([0, 0, -0.1], [0.2, 0.2, 0]),
                                dem={"radius_min_m": R, "radius_max_m": R}, particles=tiny)],
                    probes={"soil": "soil", "axis_m": value})
                p = self.check(name, s)
                self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
                self.assertIn("probes.axis_m", p.stderr)
                self.assertIn(needle, p.stderr)

    def test_axis_in_2d_exits_2(self):
        s = compose_scenario(
            "flat", 2, END_S, domain=domain([0, -0.1], [0.2, 0.1]), materials=[SAND],
            parts=[part("soil", "dem", "sand", 2 * R, box([0, -0.1], [0.2, 0]),
                        dem={"radius_min_m": R, "radius_max_m": R},
                        particles=[particle([0.01, -0.01], R)])],
            probes={"soil": "soil", "axis_m": [0.1, 0.0]})
        p = self.check("two_d", s)
        self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
        self.assertIn("probes.axis_m", p.stderr)
        self.assertIn("3D", p.stderr)


# --- perforation ------------------------------------------------------------------------------

HE = 0.02     # element size [m]
SIDE = 0.2    # the quarter plate's side (3D), the half plate's length (2D: x 2) [m]
THICK = 0.04  # two elements through the thickness
V = 1000.0    # the patches' initial vertical velocity [m/s]


def zone(lo, hi, v):
    return {"region": box(lo, hi), "velocity_m_s": v}


def plate_scenario(dim):
    """A quarter (3D) or half (2D) plate with the two patches of the module's docstring."""
    z0, z1 = -THICK / 2, THICK / 2
    e = 1e-3  # zone boxes reach 1 mm past the node planes they hold
    if dim == 3:
        hole = 0.06 - HE / 2  # nodes x, y in {0, 0.02, 0.04}: columns 0-2 stretched
        zones = [zone([0, 0, z0 - e], [hole, hole, z0 + e], [0, 0, -V]),
                 zone([0, 0, z1 - e], [hole, hole, z1 + e], [0, 0, V]),
                 # nodes x, y in {0.12, 0.14, 0.16}, bottom only: columns 5-8, bottom layer
                 zone([0.11, 0.11, z0 - e], [0.17, 0.17, z0 + e], [0, 0, -V])]
        region = box([0, 0, z0], [SIDE, SIDE, z1])
        d = domain([0, 0, -0.1], [SIDE, SIDE, 0.1])
        d["symmetry_planes"] = ["left", "bottom"]
    else:
        hole = 0.06 - HE / 2
        zones = [zone([0, z0 - e], [hole, z0 + e], [0, -V]),
                 zone([0, z1 - e], [hole, z1 + e], [0, V]),
                 zone([0.11, z0 - e], [0.17, z0 + e], [0, -V])]
        region = box([0, z0], [2 * SIDE, z1])
        d = domain([0, -0.1], [2 * SIDE, 0.1])
        d["symmetry_planes"] = ["left"]
    steel = part("plate", "fem", "steel", HE, region, zones=zones,
                 fem={"erosion_plastic_strain": 0.3, "erode_inverted": True})
    return compose_scenario(f"perforation-{dim}d", dim, 5e-5, domain=d, output=output(5e-5),
                            materials=[STEEL_JC], parts=[steel], probes={"plate": "plate"})


def read_cells(path):
    """Reference node positions (points - displacement), each cell's point ids, eroded flags."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    pts = vtk_to_numpy(grid.GetPoints().GetData())
    ref = pts - vtk_to_numpy(grid.GetPointData().GetArray("displacement"))
    eroded = vtk_to_numpy(grid.GetCellData().GetArray("eroded"))
    cells = []
    for c in range(grid.GetNumberOfCells()):
        ids = grid.GetCell(c).GetPointIds()
        cells.append([ids.GetId(k) for k in range(ids.GetNumberOfIds())])
    return ref, np.array(cells), eroded


def open_footprint(path, dim, step):
    """The reference footprint area (2D: length) covered by no live element, by a raster of
    pitch `step` over the plate: a sample is open when it lies in some element's footprint
    (bounding box of its reference nodes' horizontal coordinates: the elements are boxes)
    and in no live one's."""
    ref, cells, eroded = read_cells(path)
    h = dim - 1  # horizontal axes: x (2D), x and y (3D)
    lo = ref[cells].min(axis=1)[:, :h]
    hi = ref[cells].max(axis=1)[:, :h]
    axes = [np.arange(ref[:, a].min() + step / 2, ref[:, a].max(), step) for a in range(h)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, h)
    inside = lambda sel: np.any(np.all((grid[:, None, :] > lo[sel][None]) &
                                       (grid[:, None, :] < hi[sel][None]), axis=2), axis=1)
    any_cell = inside(np.ones(len(cells), bool))
    live = inside(eroded == 0)
    return float(np.count_nonzero(any_cell & ~live)) * step ** h, ref, cells, eroded


class PerforatedArea(unittest.TestCase):
    def run_plate(self, dim):
        work = scratch(f"probes_perforation_{dim}d")
        path = write_scenario(work / "plate.toml", plate_scenario(dim))
        out = work / "out"
        crater("run", path, "--out", out, "--force", "--quiet", "--threads", 1)
        with open(out / "summary.json") as f:
            m = json.load(f)["metrics"]
        _, last = read_pvd(out / "plate.pvd")[-1]
        return m, out / last

    def check_plate(self, dim, mirrors):
        m, last = self.run_plate(dim)
        raster, ref, cells, eroded = open_footprint(last, dim, HE / 8)
        # Columns: elements with the same reference footprint (x, y of the centroid).
        key = np.round(ref[cells].mean(axis=1)[:, :dim - 1] / HE, 3)
        _, column = np.unique(key, axis=0, return_inverse=True)
        per_column = np.bincount(column.ravel(), weights=eroded)
        kinds = {int(k) for k in per_column}
        self.assertEqual(kinds, {0, 1, 2}, "want intact, half and fully eroded columns")
        expected = mirrors * raster
        print(f"\n{dim}D: {np.count_nonzero(per_column == 2)} columns eroded through, "
              f"{np.count_nonzero(per_column == 1)} in one layer; plate_perforated_area_m2 "
              f"{m['plate_perforated_area_m2']:.6g}, raster x {mirrors} {expected:.6g}",
              file=sys.stderr)
        self.assertGreater(expected, 0)
        self.assertAlmostEqual(m["plate_perforated_area_m2"], expected, delta=1e-9)
        # A column eroded through joins the bottom face to the top one: perforated.
        self.assertEqual(m["plate_perforated"], 1)

    def test_quarter_plate_3d(self):
        self.check_plate(3, 4)

    def test_half_plate_2d(self):
        self.check_plate(2, 2)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
