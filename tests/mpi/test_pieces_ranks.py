# ctest-processors: 2
# ctest-timeout: 400
# ctest-cost: 25
"""Frames written in pieces on several MPI ranks (issue 29, output.pieces = "ranks",
docs/distributed.md "What is written"): each rank writes its own entities of every part as a
piece (pieces/<part>_<frame>_<rank>.vtu) and rank 0 a PVTU over them (<part>_<frame>.pvtu,
listed in the PVD), so that no rank holds a whole part.

tests/data/contacts_ranks_2d.toml (an SPH charge in a DEM bed under an eroding FEM plate, the
three contacts; 1,516 steps) and its 3D counterpart are run without a launcher on one thread
(the reference, one VTU per part and frame), then on 2 ranks with pieces (and the 2D scene on 3
in the slow set, test_ranks_full_slow.py). Read with VTK's parallel reader (vtkXMLPUnstructuredGridReader), every frame is the
reference's frame bit for bit:
- a particle part's pieces hold every grain or particle exactly once, with its point data;
- a mesh part's pieces hold every element exactly once (by `element_id`), with its cell data and
  its nodes (by `node_id`: a node shared by two ranks' elements is in both pieces, with its
  owner's values in each);
history.csv is the reference's byte for byte, the PVD the reference's with .pvtu for .vtu, and
every PVTU names one piece per rank. The 2-rank run resumed on 3 ranks writes its files again
(checkpoints byte for byte), and restarted into another directory it takes the earlier frames
with their pieces. A run that stops (exit 3) writes its failure frame in pieces too. `crater
report` reads the frames of a run in pieces. On one rank the key
changes nothing.
"""
import sys
import unittest

import numpy as np

from crater_test import (SOURCE_DIR, grid_cells, read_grid, read_pvd, read_pvtu, read_vtu,
                         read_vtu_cells, scratch)
from on_ranks import FULL, MPIRUN, assert_resumes, checkpoints, files, mpirun, plain

PIECES = ["--set", 'output.pieces="ranks"']
OPTS = checkpoints(500)


def bits_equal(a, b):
    return a.shape == b.shape and np.array_equal(a.view(np.uint8), b.view(np.uint8))


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class PiecesOnRanks(unittest.TestCase):
    def check_frame(self, ref_vtu, pvtu, ranks):
        pts, arrays, _, _ = read_vtu(ref_vtu)
        got_pts, got, got_cells, cells = read_pvtu(pvtu)
        sources = [e for e in pvtu.read_text().split('"') if e.startswith("pieces/")]
        if ranks:
            self.assertEqual(len(sources), ranks, pvtu.name)
        for s in sources:
            self.assertTrue((pvtu.parent / s).is_file(), s)
        if "id" in arrays:  # particles: each exactly once
            self.assertEqual(sorted(got["id"]), sorted(arrays["id"]), pvtu.name)
            a, b = np.argsort(arrays["id"]), np.argsort(got["id"])
            self.assertTrue(bits_equal(pts[a], got_pts[b]), pvtu.name)
            self.assertEqual(sorted(got), sorted(arrays), pvtu.name)
            for name in arrays:
                self.assertTrue(bits_equal(arrays[name][a], got[name][b]), f"{pvtu.name} {name}")
            return
        # a mesh: nodes by number (a shared node in several pieces), elements once each
        node = got["node_id"]
        self.assertEqual(set(node), set(range(len(pts))), pvtu.name)
        self.assertTrue(bits_equal(pts[node], got_pts), pvtu.name)
        for name in arrays:
            self.assertTrue(bits_equal(arrays[name][node], got[name]), f"{pvtu.name} {name}")
        ref_cells = read_vtu_cells(ref_vtu)
        element = got_cells["element_id"]
        self.assertEqual(sorted(element), list(range(len(element))), pvtu.name)
        for name in ref_cells:
            self.assertTrue(bits_equal(ref_cells[name][element], got_cells[name]),
                            f"{pvtu.name} cell {name}")
        ref_conn = grid_cells(read_grid(ref_vtu))
        for c, e in enumerate(element):
            self.assertEqual([node[p] for p in cells[c]], ref_conn[e], f"{pvtu.name} {e}")

    def check(self, tag, scene, ranks):
        work = scratch(f"pieces_ranks_{tag}")
        ref = work / "plain"
        p = plain("run", scene, "--out", ref, "--force", "--quiet", "--threads", "1", *OPTS)
        self.assertEqual(p.returncode, 0, p.stderr)
        ckpts = sorted(f.name for f in (ref / "checkpoints").iterdir())
        # One rank: the key changes nothing.
        one = work / "one_rank"
        p = plain("run", scene, "--out", one, "--force", "--quiet", "--threads", "1", *OPTS,
                  *PIECES)
        self.assertEqual(p.returncode, 0, p.stderr)
        for n in files(ref):
            if n not in ("summary.json", "crater-command.toml"):
                self.assertEqual((one / n).read_bytes(), (ref / n).read_bytes(), n)
        for np_ in ranks:
            with self.subTest(case=tag, ranks=np_):
                out = work / f"ranks{np_}"
                p = mpirun(np_, "run", scene, "--out", out, "--force", "--quiet", "--threads", 1,
                           *OPTS, *PIECES)
                self.assertEqual(p.returncode, 0, p.stderr)
                vtus = [n for n in files(ref) if n.endswith(".vtu")]
                self.assertGreaterEqual(len(vtus), 6)
                self.assertEqual(files(out), sorted(
                    [n for n in files(ref) if not n.endswith(".vtu")] +
                    [n[:-4] + ".pvtu" for n in vtus]))
                self.check_run(ref, out, np_)
        # `crater report` reads the frames through their PVTU (the last one: 3 s, not 8).
        p = plain("report", work / "ranks2", "--out", work / "report", "--times", "1.2e-4",
                  timeout=300)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertNotIn("could not read", p.stderr)
        self.assertTrue((work / "report" / "snapshots_parts.png").is_file())
        # Resumed from the 2-rank checkpoint on 3 ranks, in its directory: the uninterrupted
        # run's files (checkpoints byte for byte); and on 2 into another directory, which
        # takes the earlier frames with their pieces.
        run2 = work / "ranks2"
        assert_resumes(self, scene, run2, ckpts[0], 3, [*OPTS, *PIECES], f"{tag}: resumed on 3")
        self.check_run(ref, work / "ranks2_resumed_on_3", 3, since=ckpts[0])
        moved = work / "restarted_elsewhere"
        p = mpirun(2, "run", scene, "--restart", run2 / "checkpoints" / ckpts[0], "--out", moved,
                   "--force", "--quiet", "--threads", 1, *OPTS, *PIECES)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.check_run(ref, moved, 2)

    def check_run(self, ref, out, ranks, since=None):
        """`out`, run on `ranks` ranks with pieces, holds the frames, PVD and history of the
        plain run `ref` (frames from before the checkpoint `since` were written on 2 ranks)."""
        self.assertEqual((out / "history.csv").read_bytes(), (ref / "history.csv").read_bytes())
        for pvd in [n for n in files(ref) if n.endswith(".pvd")]:
            entries = read_pvd(out / pvd)
            self.assertEqual(entries, [(t, f[:-4] + ".pvtu") for t, f in read_pvd(ref / pvd)])
            for _, f in entries:
                self.check_frame(ref / (f[:-5] + ".vtu"), out / f, None if since else ranks)

    def test_2d_scene(self):
        self.check("2d", SOURCE_DIR / "tests" / "data" / "contacts_ranks_2d.toml",
                   (2, 3) if FULL else (2,))

    def test_3d_scene(self):
        self.check("3d", SOURCE_DIR / "tests" / "data" / "contacts_ranks_3d.toml", (2,))

    def test_failure_frame_in_pieces(self):
        # A run that stops (exit 3: the demo's first step is below time.min_dt_s) writes its
        # last state as <part>_failure.pvtu over every rank's piece.
        out = scratch("pieces_ranks_failure") / "ranks2"
        p = mpirun(2, "run", "demo", "--out", out, "--force", "--quiet", "--set",
                   "time.min_dt_s=1", *PIECES)
        self.assertEqual(p.returncode, 3, p.stderr)
        first, _, _, _ = read_pvtu(out / "charge_000000.pvtu")
        pts, arrays, _, _ = read_pvtu(out / "charge_failure.pvtu")
        self.assertEqual(sorted(arrays["id"]), list(range(len(first))))
        self.assertEqual(sorted(f.name for f in (out / "pieces").glob("charge_failure_*.vtu")),
                         ["charge_failure_0000.vtu", "charge_failure_0001.vtu"])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
