# ctest-processors: 2
# ctest-timeout: 400
"""The FEM part on several MPI ranks (issue 29, docs/distributed.md, "The FEM part on ranks").

Each scene is run without a launcher on one thread (the reference) and under mpirun on several
ranks (oversubscribed on 2 cores); every run must give the reference's files bit for bit
(history.csv and the PVD collection byte for byte, summary.json but its "run" block, every VTU
frame's points, point data and cell data in node and element order, read with VTK's reader, and
the checkpoints byte for byte: the root writes the whole mesh as one rank does):
- tests/data/fem_plate_2d.toml: the paper's Johnson-Cook plate struck in its middle, with
  damage and erosion (20 elements erode, their nodes on the cuts too);
- tests/data/fem_ranks_2d.toml: the plate under a pressure pulse, with gravity, dashpot ends,
  a velocity boundary, a rigid wall with friction and selective mass scaling;
- tests/data/fem_concrete_2d.toml: Holmquist-Johnson-Cook concrete (compaction state);
- the 3D Taylor bar of tests/verification/fem_taylor as that test runs it (a Gmsh mesh file of
  1,920 Hex8, symmetry planes, Johnson-Cook with heating, 3,713 steps to 80 us).
- tests/data/fem_erosion_ranks_2d.toml: a rod striking a rigid wall end-on, eroding at the wall
  (302 of its 1,000 elements), cut by its live elements' count (domain.balance = "count"): the
  cuts are made again as the elements erode (FemPart::rebalance), and the entities move to
  their new ranks with everything they hold; the first cut alone would leave the rank at the
  wall well below the others.
A 2-rank checkpoint is resumed on 3 ranks and on 1: the uninterrupted run's files again.
Under `make test` only the first case of the file runs on 4 ranks and on 2 ranks of 2
threads, the others on 2 and 3 ranks of one thread (on_ranks.rank_counts); `make test-slow`
runs every case on every count (test_ranks_full_slow.py).
"""
import json
import sys
import unittest

import numpy as np

from crater_test import SOURCE_DIR, read_grid, read_vtu_cells, scratch
from on_ranks import (MPIRUN, assert_ranks_give, assert_resumes_elsewhere, by_id, checkpoints,
                      files, plain, rank_counts)

DATA = SOURCE_DIR / "tests" / "data"
sys.path.insert(0, str(SOURCE_DIR / "tests" / "verification" / "fem_taylor"))
from test_taylor_bar import write_case  # noqa: E402  (the verification case's mesh and scene)



# scene (or a function of the work directory that writes it), --set options, checkpoint
# interval [steps], rank counts (ranks, threads per rank), elements, resumed
CASES = {
    "plate_erosion": (DATA / "fem_plate_2d.toml", [], 200, [(2, 1), (3, 1), (4, 1), (2, 2)],
                      1000, True),
    "loads_walls_mass_scaling": (DATA / "fem_ranks_2d.toml", [], 100,
                                 rank_counts([(2, 1), (3, 1), (4, 1), (2, 2)]), 1000, True),
    "concrete_hjc": (DATA / "fem_concrete_2d.toml", [], 200, [(2, 1), (3, 1)], None, False),
    # 442 steps; on 2 ranks the cuts are first made again at step 200, before that step's
    # checkpoint, which the resumes start from.
    "erosion_recut": (DATA / "fem_erosion_ranks_2d.toml", ["--set", 'domain.balance="count"'],
                      200, rank_counts([(2, 1), (3, 1), (4, 1), (2, 2)]), 1000, True),
    "taylor_3d": (write_case, [], 1000, rank_counts([(2, 1), (3, 1), (4, 1), (2, 2)]), 1920,
                  True),
}


def rest_centres_y(frame):
    """The height of each element's centre in a frame (element order), read with VTK."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    grid = read_grid(frame)
    pts = vtk_to_numpy(grid.GetPoints().GetData())
    return np.array([pts[[grid.GetCell(c).GetPointId(k) for k in range(4)], 1].mean()
                     for c in range(grid.GetNumberOfCells())])


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class FemOnRanks(unittest.TestCase):
    def run_case(self, name):
        scene, sets, every, ranks, elements, resume = CASES[name]
        work = scratch(f"fem_ranks_{name}")
        if callable(scene):
            scene = scene(work)
        ref = work / "plain"
        opts = [*sets, *checkpoints(every)]
        p = plain("run", scene, "--out", ref, "--force", "--quiet", "--threads", "1", *opts)
        self.assertEqual(p.returncode, 0, p.stderr)
        first, _ = by_id(ref / [n for n in files(ref) if n.endswith(".vtu")][0])
        if elements is not None:
            self.assertEqual(len(first["cell:eroded"]), elements)
        ckpts = sorted(f.name for f in (ref / "checkpoints").iterdir())
        self.assertGreaterEqual(len(ckpts), 2)
        assert_ranks_give(self, ref, scene, opts, ranks, ckpts, name, self.assert_spread)
        if resume:
            assert_resumes_elsewhere(self, scene, ref, ckpts[0], opts, name)
        return ref

    def assert_spread(self, out, ranks):
        # Every rank owns a share of the elements (a bisection of their centres), and holds
        # ghost nodes where its share meets the others'. Cuts made again (the elements' erosion
        # or the measured time) leave shares of other sizes.
        figures = json.loads((out / "summary.json").read_text())["run"]["ranks_by_part"]
        part = next(iter(figures.values()))
        self.assertGreater(part["owned_min"], 0, figures)
        if part["rebalances"] == 0:
            self.assertLessEqual(part["owned_max"] - part["owned_min"], 1, figures)
        self.assertGreater(part["ghost_nodes_max"], 0, figures)

    def diagnostics(self, ref):
        return json.loads((ref / "summary.json").read_text())["parts"][0]["diagnostics"]

    def test_plate_with_erosion(self):
        d = self.diagnostics(self.run_case("plate_erosion"))
        self.assertGreater(d["eroded_elements"], 0)

    def test_loads_walls_dashpots_mass_scaling(self):
        d = self.diagnostics(self.run_case("loads_walls_mass_scaling"))
        self.assertGreater(d["mass_scaled_elements"], 0)
        self.assertGreater(d["eroded_elements"], 0)

    def test_concrete_compaction(self):
        self.run_case("concrete_hjc")

    def test_cuts_made_again_as_elements_erode(self):
        """The busiest rank's live elements stay within 15 % above the ranks' mean at the end
        (the cuts are looked at every 100 steps, made again beyond 10 %, and the rod erodes on
        in between), where the first cut alone would leave the busiest more than 30 % above:
        the eroded elements' centres at rest, from the reference run's frames."""
        ref = self.run_case("erosion_recut")
        d = self.diagnostics(ref)
        frames = sorted(n for n in files(ref) if n.endswith(".vtu"))
        y = rest_centres_y(ref / frames[0])
        eroded = read_vtu_cells(ref / frames[-1])["eroded"] > 0
        self.assertEqual(int(eroded.sum()), d["eroded_elements"])
        self.assertGreater(d["eroded_elements"], 200)
        live = d["elements"] - d["eroded_elements"]
        for ranks in (2, 3, 4):
            # The first cut: a bisection of the centres along the rod (equal counts).
            order = np.argsort(y, kind="stable")
            shares = np.array_split(order, ranks)
            first = max(int((~eroded[s]).sum()) for s in shares) * ranks / live
            self.assertGreater(first, 1.3, f"{ranks} ranks: the scene no longer parts the ranks")
            out = ref.parent / f"ranks{ranks}_threads1"
            if not (out / "summary.json").exists():
                continue
            part = json.loads((out / "summary.json").read_text())["run"]["ranks_by_part"]["rod"]
            self.assertGreaterEqual(part["rebalances"], 1, part)
            # The cuts are made again when the busiest rank is 10 % above the mean (nothing
            # bounds the least busy one: on 4 ranks it ends at 0.85 of the mean, the others
            # within 10 % above).
            self.assertLessEqual(part["live_max"] * ranks / live, 1.15, part)
            self.assertGreater(part["live_min"], 0, part)

    def test_taylor_bar_3d(self):
        self.run_case("taylor_3d")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
