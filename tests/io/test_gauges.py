# ctest-cost: 8
"""[[gauges]] (issue 28): history output at chosen entities, to gauges.csv.

- The values a gauge writes at a frame's step are the ones VTK's reader finds in that frame's
  VTU file at the same entity: FEM nodes and elements (by id and nearest a point), SPH and DEM
  particles followed by their `id` field while others leave the domain (outflow "remove"); a
  particle that has left reads NaN.
- Rows come every output.gauges_every_steps steps, at every frame and at the end; the step and
  time columns are history.csv's at the same steps.
- A run restarted from a mid-run checkpoint writes gauges.csv bit for bit.
- Bad gauges (unknown field, id out of range, an element field without elements; a face with
  an element field, a z face in 2D, a face with ids, a sum of one point) stop `crater check` and
  `crater run` with exit 2 before any work. (The face's resultant is verified in
  tests/verification/fem_support/test_face_resultant.py.)
"""
import csv
import math
import sys
import unittest
from pathlib import Path

import numpy as np

from crater_test import (SOURCE_DIR, assert_restart_identical, crater, read_pvd, read_vtu,
                         read_vtu_cells, scratch)

DATA = Path(SOURCE_DIR) / "tests" / "data"

PLATE_GAUGES = """
[[gauges]]
name = "mid"
part = "plate"
point_m = [0.0, 0.0]
fields = ["velocity", "displacement", "von_mises", "plastic_strain"]

[[gauges]]
name = "ends"
part = "plate"
ids = [0, 7]
element_ids = [3, 40]
fields = ["velocity", "pressure"]
"""

OUTFLOW_GAUGES = """
[[gauges]]
name = "gas"
part = "gas"
ids = [0, 20, 100]
fields = ["velocity", "density"]

[[gauges]]
name = "grains"
part = "cloud"
ids = [1, 30, 95]
fields = ["velocity", "angular_velocity"]
"""


def scene(name, base, gauges, extra=""):
    d = scratch(f"gauges_{name}")
    d.mkdir(parents=True, exist_ok=True)
    (d / "s.toml").write_text((DATA / base).read_text().replace("[output]\n", "[output]\n" + extra)
                              + gauges)
    return d


def read_rows(path):
    with open(path, newline="") as f:
        r = csv.reader(f)
        header = next(r)
        return header, [[float(x) for x in row] for row in r]


class Gauges(unittest.TestCase):
    def check_frames(self, out, header, rows, part, kind, gauges):
        """Every column of `gauges` (on `part`) equals the frame's VTU value at each frame's
        step."""
        frames = read_pvd(out / f"{part}.pvd")
        times = np.array([row[1] for row in rows])
        compared = 0
        for t, name in frames:
            k = int(np.flatnonzero(times == t)[0])  # a row at every frame, at its very time
            points, arrays, _, _ = read_vtu(out / name)
            cells = read_vtu_cells(out / name)
            ids = arrays.get("id")
            for col, value in zip(header[2:], rows[k][2:]):
                gauge, entity, field = col.split(".")
                if gauge not in gauges:
                    continue
                if not entity.startswith(kind[0]) and not (kind[1] and entity.startswith(kind[1])):
                    continue
                comp = None
                if "_" in field and field.rsplit("_", 1)[1] in ("x", "y", "z"):
                    field, c = field.rsplit("_", 1)
                    comp = "xyz".index(c)
                eid = int(entity.lstrip("nodeparticlement"))
                if entity.startswith("element"):
                    v = cells[field][eid]
                elif entity.startswith("particle"):
                    where = np.flatnonzero(ids == eid)
                    if where.size == 0:
                        self.assertTrue(math.isnan(value), f"{col} at t={t}: left, not NaN")
                        compared += 1
                        continue
                    v = arrays[field][where[0]]
                else:
                    v = arrays[field][eid]
                v = float(v if comp is None else v[comp])
                self.assertEqual(value, v, f"{col} at t = {t}")
                compared += 1
        return compared

    def test_fem_nodes_and_elements_equal_the_frames(self):
        d = scene("plate", "fem_plate_2d.toml", PLATE_GAUGES, "gauges_every_steps = 3\n")
        crater("run", d / "s.toml", "--out", d / "out", "--force", "--quiet")
        header, rows = read_rows(d / "out" / "gauges.csv")
        self.assertEqual(header[:3], ["step", "time_s", "mid.node555.velocity_x"])
        self.assertIn("ends.element40.pressure", header)
        n = self.check_frames(d / "out", header, rows, "plate", ("node", "element"),
                              ("mid", "ends"))
        self.assertGreater(n, 100)
        # The cadence: every 3rd step, the frames' steps and the last step; the same steps and
        # times as history.csv's rows there.
        steps = [int(r[0]) for r in rows]
        with open(d / "out" / "history.csv") as f:
            hist = {int(r["step"]): float(r["time_s"]) for r in csv.DictReader(f)}
        self.assertTrue(all(s % 3 == 0 or s in hist for s in steps))
        self.assertTrue(set(range(0, steps[-1] + 1, 3)) <= set(steps))
        for r in rows:
            if int(r[0]) in hist:
                self.assertEqual(r[1], hist[int(r[0])])
        self.assertEqual(len(rows), len(set(steps)))

    def test_particles_followed_by_id_while_others_leave(self):
        d = scene("outflow", "outflow_2d.toml", OUTFLOW_GAUGES)
        crater("run", d / "s.toml", "--out", d / "out", "--force", "--quiet")
        header, rows = read_rows(d / "out" / "gauges.csv")
        n = sum(self.check_frames(d / "out", header, rows, part, ("particle", None), (gauge,))
                for part, gauge in (("gas", "gas"), ("cloud", "grains")))
        self.assertGreater(n, 50)
        # Some gas particles leave (NaN from then on), and do not come back.
        cols = [i for i, c in enumerate(header) if c.startswith("gas.")]
        left = [i for i in cols if math.isnan(rows[-1][i])]
        self.assertTrue(left, "no gauged gas particle left the box: the NaN case is untested")
        for i in left:
            first = next(k for k, r in enumerate(rows) if math.isnan(r[i]))
            self.assertTrue(all(math.isnan(r[i]) for r in rows[first:]))

    def test_restart_rewrites_gauges_bit_for_bit(self):
        d = scene("restart", "outflow_2d.toml", OUTFLOW_GAUGES,
                  "checkpoint_every_steps = 100\ncheckpoint_keep = 50\n")
        crater("run", d / "s.toml", "--out", d / "full", "--force", "--quiet")
        ckpts = sorted((d / "full" / "checkpoints").glob("*.ckpt"))
        self.assertGreaterEqual(len(ckpts), 2)
        assert_restart_identical(d / "s.toml", d / "full", ckpts[0])

    def test_bad_gauges_exit_2(self):
        cases = [
            ('fields = ["vonmises"]', "no output field 'vonmises' in part 'plate'"),
            ('ids = [99999]\nfields = ["velocity"]', "part 'plate' has no node 99999"),
            ('ids = [1]\nfields = ["von_mises"]', "'von_mises' is an element field"),
            # Sums and faces (the resultant on an FEM face).
            ('face = "left"\nfields = ["von_mises"]', "a face selects nodes"),
            ('face = "front"\nfields = ["reaction_force"]', "a face of the z axis"),
            ('face = "left"\nids = [1]\nfields = ["reaction_force"]', "not several"),
            ('point_m = [0.0, 0.0]\nsum = true\nfields = ["reaction_force"]',
             "a sum needs ids, element_ids or face"),
        ]
        for body, expected in cases:
            with self.subTest(body=body):
                gauge = f'\n[[gauges]]\nname = "g"\npart = "plate"\n' + \
                        ('point_m = [0.0, 0.0]\n' if not any(
                            k in body for k in ("ids", "face", "point_m")) else "") + body + "\n"
                d = scene("bad", "fem_plate_2d.toml", gauge)
                for cmd in ("check", "run"):
                    args = [cmd, d / "s.toml"] + (["--out", d / "out", "--force"]
                                                  if cmd == "run" else [])
                    p = crater(*args, check=False)
                    self.assertEqual(p.returncode, 2, p.stderr)
                    self.assertIn(expected, p.stderr)
                self.assertFalse((d / "out" / "summary.json").exists())


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
