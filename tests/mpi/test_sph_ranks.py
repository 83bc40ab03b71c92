# ctest-processors: 2
# ctest-timeout: 400
"""The SPH part on several MPI ranks (issue 29, docs/distributed.md, "The SPH part on ranks").

Each scene is run without a launcher on one thread (the reference) and under mpirun on several
ranks (oversubscribed on 2 cores); every run must give the reference's files bit for bit
(history.csv and the PVD collection byte for byte, summary.json but its "run" block, every VTU
frame's points and point data by particle id, read with VTK's reader, and the checkpoints byte
for byte: the root writes the whole part in the order one rank holds it):
- tests/data/sph_ranks_2d.toml, a dam break of 800 particles: no-slip walls of dummy particles
  with the continuity density; then free-slip walls (mirror images) with the summation density;
  then no-slip walls with the summation density, to 0.15 s (the wall particles' densities, which
  the summation reads before they are averaged again, shared at each rebuild by the ranks that
  hold all their fluid neighbours; without the sharing the runs on 2 and 3 ranks part from one
  rank's by 0.09 s);
- tests/data/sph_ranks_3d.toml, a TNT sphere of 912 particles expanding into vacuum at km/s:
  continuity, then summation density;
- `make run`'s demo (scenarios/demo.toml), the 2D TNT charge of 1,264 particles, 97 steps;
- tests/data/sph_outflow_ranks_2d.toml, a gas blob of 208 particles splashing on a steel plate
  (the sph-fem contact) and leaving the domain box (domain.outflow = "remove"): 182 particles
  leave over 3,972 steps, many removals, each a rebuild of the lists on every rank; the
  reference must have removed most of them, and its removal books (left_domain_*) and energy
  balance are compared with the rest.
A 2-rank checkpoint is resumed on 3 ranks and on 1: the uninterrupted run's files again. On 4
ranks the dam break's cuts, by the cost model (domain.balance = "count"), are made again as the
water flows (fields::rebalanced_cuts): every rank keeps a share of the water. The other cases cut
by measured time (the default), which the results must not notice either.
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



# scene, --set options, checkpoint interval [steps], the checkpoints written, rank counts
# (ranks, threads per rank), particles
CASES = {
    # By the cost model (domain.balance = "count"), whose cuts the 4-rank run checks
    # (assert_rebalanced); the other cases cut by measured time, the default.
    "dam_no_slip": (DATA / "sph_ranks_2d.toml", ["--set", 'domain.balance="count"'], 1000,
                    ["step_000000001000.ckpt", "step_000000002000.ckpt",
                     "step_000000002269.ckpt"], [(2, 1), (3, 1), (4, 1), (2, 2)], 800),
    "dam_free_slip_summation": (DATA / "sph_ranks_2d.toml",
                                ["--set", 'parts.fluid.sph.wall_slip="free"', "--set",
                                 'parts.fluid.sph.density="summation"'], 1000,
                                ["step_000000001000.ckpt", "step_000000002000.ckpt",
                                 "step_000000002458.ckpt"], [(2, 1), (3, 1)], 800),
    "dam_no_slip_summation": (DATA / "sph_ranks_2d.toml",
                              ["--set", 'parts.fluid.sph.density="summation"', "--set",
                               "scenario.end_time_s=0.15"], 250, None, [(2, 1), (3, 1)], 800),
    "tnt_continuity": (DATA / "sph_ranks_3d.toml", [], 50,
                       ["step_000000000050.ckpt", "step_000000000086.ckpt"],
                       rank_counts([(2, 1), (3, 1), (4, 1), (2, 2)]), 912),
    "demo": ("demo", [], 50, ["step_000000000050.ckpt", "step_000000000097.ckpt"],
             rank_counts([(2, 1), (3, 1), (4, 1), (2, 2)]), 1264),
    "tnt_summation": (DATA / "sph_ranks_3d.toml", ['--set', 'parts.charge.sph.density="summation"'],
                      40, None, [(2, 1), (3, 1)], 912),
    "outflow_contact": (DATA / "sph_outflow_ranks_2d.toml", [], 1500, None,
                        rank_counts([(2, 1), (3, 1), (4, 1), (2, 2)]), 208),
}


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class SphOnRanks(unittest.TestCase):
    def run_case(self, name, resume=False):
        scene, sets, every, ckpts, ranks, particles = CASES[name]
        work = scratch(f"sph_ranks_{name}")
        ref = work / "plain"
        opts = [*sets, *checkpoints(every)]
        p = plain("run", scene, "--out", ref, "--force", "--quiet", "--threads", "1", *opts)
        self.assertEqual(p.returncode, 0, p.stderr)
        first, _ = by_id(ref / [n for n in files(ref) if n.endswith(".vtu")][0])
        self.assertEqual(len(first["id"]), particles)
        if ckpts is None:  # the steps of this variant: whatever the reference took
            ckpts = sorted(f.name for f in (ref / "checkpoints").iterdir())
        self.assertGreaterEqual(len(ckpts), 2)
        assert_ranks_give(self, ref, scene, opts, ranks, ckpts, name,
                          lambda out, np_: self.assert_rebalanced(out)
                          if name == "dam_no_slip" and np_ == 4 else None)
        if resume:
            assert_resumes_elsewhere(self, scene, ref, ckpts[0], opts, name)
        return ref

    def assert_rebalanced(self, out):
        # The water flows out of the boxes of the cuts made at t = 0 (two of 4 ranks owned none
        # of it by the end before the cuts were made again): the cuts follow it.
        figures = json.loads((out / "summary.json").read_text())["run"]["ranks_by_part"]["fluid"]
        self.assertGreaterEqual(figures["rebalances"], 1)
        self.assertGreaterEqual(figures["owned_min"], 0.6 * figures["owned_max"], figures)

    def test_dam_break_no_slip_walls(self):
        self.run_case("dam_no_slip", resume=True)

    def test_dam_break_free_slip_walls_summation_density(self):
        self.run_case("dam_free_slip_summation")

    def test_dam_break_no_slip_walls_summation_density(self):
        # The wall particles' densities, which the summation reads before they are averaged
        # again, from the ranks that hold all their fluid neighbours (since 2026-12-01).
        self.run_case("dam_no_slip_summation", resume=True)

    def test_tnt_sphere_continuity(self):
        self.run_case("tnt_continuity", resume=True)

    def test_make_run_demo(self):
        self.run_case("demo", resume=True)

    def test_tnt_sphere_summation_density(self):
        self.run_case("tnt_summation", resume=True)

    def test_outflow_beside_a_contact(self):
        ref = self.run_case("outflow_contact", resume=True)
        summary = json.loads((ref / "summary.json").read_text())
        blob = next(p for p in summary["parts"] if p["name"] == "blob")
        self.assertGreater(blob["diagnostics"]["left_domain_count"], 150, blob)
        with open(ref / "history.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        pushed = sum(float(r["force_blob-plate_y"]) != 0 for r in rows)
        self.assertGreater(pushed, len(rows) // 2)  # the contact acts through the removals


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
