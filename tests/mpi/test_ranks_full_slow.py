# ctest-labels: slow
# ctest-processors: 2
# ctest-timeout: 3600
"""Every tests/mpi case on every rank and thread count it lists (issue 29; the slow set of
`make test-slow`). Under `make test` most cases run on 2 and 3 ranks of one thread only, and one
case of each kind per file on all its counts (on_ranks.rank_counts): this runs each of those
files again with CRATER_RANKS_FULL=1, so that 4 ranks and 2 ranks of 2 threads are tested for
every case.
"""
import os
import subprocess
import sys
import unittest
from pathlib import Path

from on_ranks import MPIRUN

HERE = Path(__file__).resolve().parent
FILES = ["test_sph_ranks.py", "test_fem_ranks.py", "test_contacts_ranks.py",
         "test_crater_ranks.py", "test_tunnel_ranks.py", "test_multi_rate_ranks.py",
         "test_pieces_ranks.py"]


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class EveryRankCount(unittest.TestCase):
    def test_every_case_on_every_count(self):
        env = dict(os.environ, CRATER_RANKS_FULL="1")
        for name in FILES:
            with self.subTest(file=name):
                p = subprocess.run([sys.executable, str(HERE / name)], env=env,
                                   capture_output=True, text=True, timeout=3000)
                self.assertEqual(p.returncode, 0, p.stderr[-4000:])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
