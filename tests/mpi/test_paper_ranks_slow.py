# ctest-labels: slow
# ctest-processors: 2
# ctest-timeout: 3600
"""The paper's scenes on several MPI ranks, the slow set (issue 29, docs/distributed.md; the
quick set is test_paper_ranks.py, `make test-slow` runs this one):
- `paper-20cm` at the demo level to 1 ms (3,793 steps; about 1,140 grains and 360 particles
  leave) under `mpirun -np 3` and `-np 4` on one thread and `-np 2` on two threads per rank
  (oversubscribed on 2 cores), and the 2-rank checkpoint of step 2000 resumed on 3 ranks and
  on 1;
- `paper-3d` at the demo level to 1 ms (1,500 steps: a 3D quarter model of 2,183 SPH
  particles, 20,130 spheres and 5,760 Hex8 with its symmetry planes, the three contacts) on
  2, 3 and 4 ranks and 2 ranks of 2 threads, and its 2-rank checkpoint of step 1000 resumed
  on 3 ranks and on 1. Its bed is settled first if the cache does not hold it (about 4 min on
  one thread). By 1 ms its bed has hardly moved (3-43 grains change ranks), so only that some
  cross is asked of it.
Each run must give the plain one-thread run's files bit for bit, as in the quick set.
"""
import sys
import unittest

from crater_test import scratch
from on_ranks import MPIRUN, assert_ranks_give, assert_resumes, checkpoints, plain
from test_paper_ranks import OPTS, assert_spread, run_reference

OPTS_3D = ["--set", "scenario.end_time_s=1.0e-3", *checkpoints(500)]


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class PaperOnRanksSlow(unittest.TestCase):
    def test_paper_20cm_on_3_and_4_ranks_and_threads(self):
        work = scratch("paper_ranks_slow")
        ref, ckpts = run_reference(self, work)
        assert_ranks_give(self, ref, "paper-20cm", OPTS, [(2, 1), (3, 1), (4, 1), (2, 2)], ckpts,
                          "paper-20cm", lambda out, np_: assert_spread(self, out, np_), timeout=900)
        for np_ in (3, 1):
            assert_resumes(self, "paper-20cm", work / "ranks2_threads1", "step_000000002000.ckpt",
                           np_, OPTS, f"paper-20cm: resumed on {np_}", timeout=900)

    def test_paper_3d(self):
        work = scratch("paper_3d_ranks")
        ref = work / "plain"
        p = plain("run", "paper-3d", "--out", ref, "--force", "--quiet", "--threads", "1",
                  *OPTS_3D, timeout=1200)
        self.assertEqual(p.returncode, 0, p.stderr)
        ckpts = sorted(f.name for f in (ref / "checkpoints").iterdir())
        self.assertEqual(len(ckpts), 3)
        assert_ranks_give(self, ref, "paper-3d", OPTS_3D, [(2, 1), (3, 1), (4, 1), (2, 2)], ckpts,
                          "paper-3d", lambda out, np_: assert_spread(self, out, np_, 0),
                          timeout=900)
        for np_ in (3, 1):
            assert_resumes(self, "paper-3d", work / "ranks2_threads1", "step_000000001000.ckpt",
                           np_, OPTS_3D, f"paper-3d: resumed on {np_}", timeout=900)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
