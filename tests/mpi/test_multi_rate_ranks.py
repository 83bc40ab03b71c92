# ctest-processors: 2
# ctest-timeout: 600
# ctest-fixtures: bundled_bed
# ctest-cost: 40
"""Multi-rate stepping (time.multi_rate) on several MPI ranks (issue 29, docs/distributed.md,
"Which scenes"): each part at its own step, the coarser parts' contact sums over their steps
kept over the whole part in one rank's order (every rank the same numbers), and each rank's part
taking those of its own entities.

- The two cases of tests/verification/multi_rate: five grains onto a free plate (the grains
  8 plate steps at a time) and an SPH gas blob onto a free plate (2 at a time; in the slow set
  only);
- paper-20cm at the demo level to 0.3 ms: the charge at up to 8 plate steps while its products
  and the grains leave through the faces (the sums follow the particles through removals and
  re-sorts by id).
Each is run without a launcher on one thread (the reference), then on 2 ranks (3, 4 and 2 ranks
of 2 threads in the slow set: test_ranks_full_slow.py); every run gives the reference's files
bit for bit (history.csv, the PVD, summary.json but its "run" block, every frame, every
checkpoint), and the 2-rank checkpoint resumed on 3 ranks and on 1 gives the uninterrupted
run's files.
"""
import json
import sys
import unittest

from crater_test import SOURCE_DIR, scratch
from on_ranks import FULL, MPIRUN, assert_ranks_give, assert_resumes_elsewhere, checkpoints, plain

sys.path.insert(0, str(SOURCE_DIR / "tests" / "verification" / "multi_rate"))
from test_multi_rate import blob_on_plate, grains_on_plate  # noqa: E402  (the scenes alone)

MULTI = ["--set", "time.multi_rate=true"]
RANKS = [(2, 1), *([(3, 1), (4, 1), (2, 2)] if FULL else [])]


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class MultiRateOnRanks(unittest.TestCase):
    def reference(self, tag, scene, opts, coarse):
        """The plain run of `scene` into <tag>/plain; its checkpoints. `coarse` stepped slower
        than the plate."""
        ref = scratch(f"multi_rate_ranks_{tag}") / "plain"
        p = plain("run", scene, "--out", ref, "--force", "--quiet", "--threads", "1", *opts,
                  timeout=400)
        self.assertEqual(p.returncode, 0, p.stderr)
        summary = json.loads((ref / "summary.json").read_text())
        steps = summary["time_step"]["steps_by_part"]
        self.assertLess(steps[coarse], steps["plate"], steps)
        ckpts = sorted(f.name for f in (ref / "checkpoints").iterdir())
        self.assertGreaterEqual(len(ckpts), 2)
        return ref, ckpts, summary

    def check(self, tag, scene, opts, coarse):
        ref, ckpts, summary = self.reference(tag, scene, opts, coarse)
        assert_ranks_give(self, ref, scene, opts, RANKS, ckpts, tag, timeout=400)
        assert_resumes_elsewhere(self, scene, ref, ckpts[0], opts, tag)
        return summary

    def scene(self, tag, text):
        path = scratch(f"multi_rate_ranks_{tag}_scene") / f"{tag}.toml"
        path.write_text(text)
        return path

    def test_grains_on_a_plate(self):
        self.check("grains", self.scene("grains", grains_on_plate()), [*MULTI, *checkpoints(300)],
                   "grains")

    @unittest.skipUnless(FULL, "the slow set (test_ranks_full_slow.py)")
    def test_gas_blob_on_a_plate(self):
        opts = [*MULTI, "--set", "time.multi_rate_max_ratio=2", *checkpoints(600)]
        self.check("blob", self.scene("blob", blob_on_plate()), opts, "blob")

    def test_paper_scene_with_removals(self):
        opts = [*MULTI, "--set", "scenario.end_time_s=3e-4", "--set", "output.interval_s=1.5e-4",
                *checkpoints(250)]
        summary = self.check("paper", "paper-20cm", opts, "charge")
        left = {p["name"]: p["diagnostics"].get("left_domain_count", 0) for p in summary["parts"]}
        self.assertGreater(left["charge"], 0, left)  # removals in the coarse part's steps


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
