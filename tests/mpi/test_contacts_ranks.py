# ctest-processors: 2
# ctest-timeout: 300
"""Contacts between parts on several MPI ranks (issue 29, docs/distributed.md): the three
pairings of paper-20cm, charge-plate (sph-fem), soil-plate (dem-fem, with friction) and
charge-soil (sph-dem), give one rank's results bit for bit, whichever ranks hold the particles,
grains, nodes and faces of a pair.

Each scene is run without a launcher on one thread (the reference) and under mpirun on 2, 3
and 4 ranks of one thread and on 2 ranks of 2 threads (oversubscribed on 2 cores); every run
must give the reference's files bit for bit (history.csv with the contacts' force columns and
the PVD collections byte for byte, summary.json but its "run" block, with the contacts'
pairs, overlaps and forces, every VTU frame's points, point data and cell data by id or in
node and element order, read with VTK's reader, and the checkpoints byte for byte, which hold
the contacts' state), and each part must be spread over every rank:
- tests/data/contacts_ranks_2d.toml: a TNT disk (316 particles) in a lattice bed of 550
  grains under a clamped Johnson-Cook plate of 480 quads; the products reach the plate through
  the grains, erode some 25 elements (the contact surfaces change) and push through;
- the same with paper-20cm's boundaries for the grains: absorbing (viscous, transmitting) walls
  at the sides and the bottom (the top a rigid wall) and domain.outflow = "remove", so that
  90 grains leave through the absorbing faces during the run (removed in the steps they cross, their ghosts with
  them on the ranks that hold them); the checkpoint it resumes from (step 500) is written in a
  step that removed a grain, before the lists are built again (2, 3 and 4 ranks of one
  thread: the blasts cover 2 ranks of 2 threads);
- tests/data/contacts_ranks_3d.toml: the same in 3D, a TNT sphere (280 particles) off the
  box's axis in a bed of 294 spheres under a clamped plate of 288 Hex8.
The reference must have every contact active (some nonzero force in its history.csv columns),
so that the comparison cannot pass on a scene where the contacts do nothing. A 2-rank
checkpoint is resumed on 3 ranks and on 1: the uninterrupted run's files again.
Under `make test` only the first case of the file runs on 4 ranks and on 2 ranks of 2
threads, the others on 2 and 3 ranks of one thread (on_ranks.rank_counts); `make test-slow`
runs every case on every count (test_ranks_full_slow.py).
"""
import csv
import json
import sys
import unittest

from crater_test import SOURCE_DIR, scratch
from on_ranks import (MPIRUN, assert_ranks_give, assert_resumes_elsewhere, by_id, checkpoints,
                      files, plain, rank_counts)

DATA = SOURCE_DIR / "tests" / "data"
PARTS = ("charge", "plate", "soil")
CONTACTS = ("charge-plate", "soil-plate", "charge-soil")



# scene, --set options, checkpoint interval [steps], rank counts (ranks, threads per rank),
# entities of each part in the first frame (particles, grains; the plate's elements), whether
# the plate erodes
CASES = {
    "blast_2d": (DATA / "contacts_ranks_2d.toml", [], 500, [(2, 1), (3, 1), (4, 1), (2, 2)],
                 {"charge": 316, "plate": 480, "soil": 550}, True),
    "blast_3d": (DATA / "contacts_ranks_3d.toml", [], 400,
                 rank_counts([(2, 1), (3, 1), (4, 1), (2, 2)]),
                 {"charge": 280, "plate": 288, "soil": 294}, False),
    "grains_leave_2d": (DATA / "contacts_ranks_2d.toml",
                        ["--set", 'parts.soil.dem.walls=["top"]', "--set",
                         'parts.soil.dem.absorbing_walls=["left","right","bottom"]', "--set",
                         "parts.soil.dem.absorbing_wall_p_wave_speed_m_s=450.0", "--set",
                         'domain.outflow="remove"'],
                        500, rank_counts([(2, 1), (3, 1), (4, 1)]),
                        {"charge": 316, "plate": 480, "soil": 550}, True),
}


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class ContactsOnRanks(unittest.TestCase):
    def run_case(self, name):
        scene, sets, every, ranks, counts, erodes = CASES[name]
        work = scratch(f"contacts_ranks_{name}")
        ref = work / "plain"
        opts = [*sets, *checkpoints(every)]
        p = plain("run", scene, "--out", ref, "--force", "--quiet", "--threads", "1", *opts)
        self.assertEqual(p.returncode, 0, p.stderr)
        for part, n in counts.items():
            first, _ = by_id(ref / f"{part}_000000.vtu")
            self.assertEqual(len(first["cell:eroded"] if part == "plate" else first["id"]), n,
                             part)
        self.assertGreaterEqual(len([n for n in files(ref) if n.endswith(".vtu")]), 3 * 4)
        self.assert_contacts_active(ref)
        if erodes:  # erosion changes the plate's surface under the contacts
            self.assertGreater(self.diagnostics(ref, "plate")["eroded_elements"], 0)
        self.assert_counts_kept(ref, counts)
        ckpts = sorted(f.name for f in (ref / "checkpoints").iterdir())
        self.assertGreaterEqual(len(ckpts), 2)
        assert_ranks_give(self, ref, scene, opts, ranks, ckpts, name, self.assert_spread)
        assert_resumes_elsewhere(self, scene, ref, ckpts[0], opts, name)
        return ref

    def assert_contacts_active(self, ref):
        # Each contact pushed at some history row: a nonzero component of its total force.
        with open(ref / "history.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        self.assertGreater(len(rows), 10)
        for c in CONTACTS:
            columns = [k for k in rows[0] if k.startswith(f"force_{c}_")]
            self.assertTrue(columns, f"history.csv has no force_{c}_* column")
            self.assertTrue(all(k[-2:] in ("_x", "_y", "_z") for k in columns), columns)
            active = sum(any(float(r[k]) != 0.0 for k in columns) for r in rows)
            # in most rows, not in a stray one: the contact works through the run
            self.assertGreater(active, len(rows) // 2, f"contact {c}: {active} rows of "
                               f"{len(rows)} with a force")
        contacts = json.loads((ref / "summary.json").read_text())["contacts"]
        for c in CONTACTS:
            self.assertIn(f"contact_{c}_pairs", contacts)

    def assert_spread(self, out, ranks):
        # Every rank owns a share of each part: the pairs of every contact come from
        # entities on several ranks.
        run = json.loads((out / "summary.json").read_text())["run"]
        self.assertEqual(run["ranks"], ranks)
        figures = run["ranks_by_part"]
        self.assertEqual(sorted(figures), sorted(PARTS), figures)
        for part in PARTS:
            self.assertGreater(figures[part]["owned_min"], 0, (part, figures))

    def assert_counts_kept(self, ref, counts):
        # Particles and grains that leave are counted: those left and those gone make the
        # first frame's count exactly (the ranks' runs give these files bit for bit).
        parts = json.loads((ref / "summary.json").read_text())["parts"]
        for p in parts:
            if "left_domain_count" in p["diagnostics"]:
                self.assertEqual(p["count"] + p["diagnostics"]["left_domain_count"],
                                 counts[p["name"]], p["name"])

    def diagnostics(self, ref, part):
        parts = json.loads((ref / "summary.json").read_text())["parts"]
        return next(p for p in parts if p["name"] == part)["diagnostics"]

    def test_blast_2d(self):
        self.run_case("blast_2d")

    def test_blast_3d(self):
        self.run_case("blast_3d")

    def test_grains_leave_2d(self):
        ref = self.run_case("grains_leave_2d")
        self.assertGreater(self.diagnostics(ref, "soil")["left_domain_count"], 50)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
