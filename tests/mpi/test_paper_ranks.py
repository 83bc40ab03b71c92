# ctest-processors: 2
# ctest-timeout: 600
# ctest-fixtures: bundled_bed
# ctest-cost: 45
"""The paper's scene on several MPI ranks (issue 29, docs/distributed.md, "Which scenes"):
`paper-20cm` at the demo level to 1 ms, its whole model at once. A TNT charge (SPH) in a
settled sand bed (DEM, absorbing walls at the sides and the bottom), under the steel plate
(FEM, Johnson-Cook with erosion), the three contacts between them; products and grains leave
through the domain's faces and the absorbing walls (about 1,100 grains and 360 particles by
1 ms, removed in batches of 32 steps) and cross the ranks' cuts at up to km/s.

The plain run (one rank, on two threads: the test holds both cores, and one rank gives the same
bits on any thread count, tests/regression/test_thread_determinism.py) is the reference; the
run under `mpirun -np 2` must give its
files bit for bit (history.csv and the PVD collections byte for byte, summary.json but its
"run" block, with the metrics and the outflow ledgers, every VTU frame's points and point data
by id or by node and element, read with VTK's reader, and the checkpoints byte for byte), each
part spread over both ranks. The count of each particle part is kept exactly: those in the
model and those removed make the first frame's count.

3 and 4 ranks, 2 ranks of 2 threads, the resumes of the 2-rank checkpoint on 3 ranks and on 1,
and paper-3d are the slow set (test_paper_ranks_slow.py); a resume from a checkpoint written
in a step that removed grains is in the quick set (test_contacts_ranks.py, grains_leave_2d).
"""
import json
import math
import sys
import unittest

from crater_test import scratch
from on_ranks import MPIRUN, assert_ranks_give, by_id, checkpoints, plain

# The demo level to 1 ms (3,793 steps), a checkpoint every 1,000 steps and at the end.
OPTS = ["--set", "scenario.end_time_s=1.0e-3", *checkpoints(1000)]
PARTS = ("charge", "plate", "soil")


def run_reference(test, work):
    """The plain run into work/plain; its checkpoints' names."""
    ref = work / "plain"
    p = plain("run", "paper-20cm", "--out", ref, "--force", "--quiet", "--threads", "2", *OPTS,
              timeout=540)
    test.assertEqual(p.returncode, 0, p.stderr)
    summary = json.loads((ref / "summary.json").read_text())
    parts = {p["name"]: p for p in summary["parts"]}
    for name in ("charge", "soil"):
        first, _ = by_id(ref / f"{name}_000000.vtu")
        left = parts[name]["diagnostics"]["left_domain_count"]
        test.assertGreater(left, 100, name)  # the outflow is exercised on ranks
        test.assertEqual(parts[name]["count"] + left, len(first["id"]), name)
        # and the mass: in the model plus removed, the first frame's, to rounding
        initial = math.fsum(first["mass"])
        now = parts[name]["mass_kg"] + parts[name]["diagnostics"]["left_domain_mass_kg"]
        test.assertAlmostEqual(now / initial, 1.0, delta=1e-12, msg=name)
    test.assertGreater(parts["plate"]["diagnostics"]["eroded_elements"], 0)
    return ref, sorted(f.name for f in (ref / "checkpoints").iterdir())


def assert_spread(test, out, ranks, crossings=100):
    """Each part is spread over every rank, and more than `crossings` of its products and of its
    grains crossed the cuts (paper-20cm: thousands). The step limits take the views of the
    contact forces at most steps (2,658 of the first 3,000 in paper-20cm on 2 ranks): the
    contacts' views are gathered about once a step, not twice. The soil's view is its contact
    zone's at every gather, and of the zone only the grains that a rank's own search finds
    touching the charge or the plate travel (4.0 % of the bed in paper-20cm on 2 ranks to 1 ms,
    where the zone's cells hold 18.4 %: a share above 10 % is the cells' alone), and the charge's
    whole view is gathered without its masses and ids at most gathers, when no rank's have
    changed (3,857 of 4,217 in paper-20cm on 2 ranks)."""
    summary = json.loads((out / "summary.json").read_text())
    run = summary["run"]
    test.assertEqual(run["ranks"], ranks)
    views = run["contact_views"]
    test.assertGreater(views["reused_for_limits"], 0.5 * summary["steps"], views)
    test.assertLess(views["gathers"], 1.5 * summary["steps"], views)
    test.assertEqual(views["zone_views"], views["gathers"], views)
    test.assertLess(views["zone_share"], 0.1, views)
    test.assertGreater(views["zone_share"], 0, views)
    test.assertGreater(views["static_fields_kept"], 0.8 * views["gathers"], views)
    figures = run["ranks_by_part"]
    for part in PARTS:
        test.assertGreater(figures[part]["owned_min"], 0, part)
    for part in ("charge", "soil"):
        test.assertGreater(figures[part]["migrations"], crossings, (part, figures[part]))


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class PaperOnRanks(unittest.TestCase):
    def test_paper_20cm_on_2_ranks(self):
        work = scratch("paper_ranks")
        ref, ckpts = run_reference(self, work)
        self.assertEqual(len(ckpts), 4)
        assert_ranks_give(self, ref, "paper-20cm", OPTS, [(2, 1)], ckpts, "paper-20cm",
                          lambda out, np_: assert_spread(self, out, np_), timeout=540)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
