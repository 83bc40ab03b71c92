# ctest-processors: 2
# ctest-timeout: 300
"""`crater run --ranks N` (issue 29, docs/distributed.md "Running on several ranks"): started
without a launcher, crater starts itself under the MPI launcher its build found (or
$CRATER_MPIEXEC) on N ranks of this machine, each taking the machine's cores / N threads unless
--threads says otherwise; under a launcher, --ranks must match its rank count.

- tests/data/dem_ranks_3d.toml (a 3D bed of 729 grains, 1,224 steps) with --ranks 2 and with
  --ranks 3 (more ranks than this machine's 2 cores: crater lets Open MPI oversubscribe, the
  environment not saying so) gives the plain run's history.csv byte for byte and its
  summary.json but the "run" block, which says the rank count and the threads a rank took;
- `crater report` of the 2-rank run says the ranks and tabulates each rank's stages and each
  part's share among them;
- --ranks 1 runs without a launcher;
- a scenario with errors: exit 2 through the launcher, each error said once;
- --ranks 3 under a launcher of 2 ranks, --ranks 0, and a launcher that is not there: exit 2,
  saying what was expected.
"""
import json
import os
import subprocess
import sys
import unittest

from crater_test import BIN, SOURCE_DIR, scratch, summary_without_run_block
from on_ranks import MPIRUN, mpirun, plain

SCENE = SOURCE_DIR / "tests" / "data" / "dem_ranks_3d.toml"


def with_ranks(*args, extra_env=None):
    """crater started alone with `args` (--ranks among them), as a user would: the launcher's
    root permission (containers, CI) in the environment, nothing about oversubscription."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("OMPI_MCA_rmaps")}
    env.update({"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
                "OMPI_MCA_btl_vader_single_copy_mechanism": "none"})
    env.pop("OMP_NUM_THREADS", None)
    env.update(extra_env or {})
    return subprocess.run([BIN, *map(str, args)], env=env, capture_output=True, text=True,
                          timeout=240)


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class RanksOption(unittest.TestCase):
    def test_ranks_start_the_launcher(self):
        work = scratch("ranks_option")
        ref = work / "plain"
        p = plain("run", SCENE, "--out", ref, "--force", "--quiet", "--threads", "1")
        self.assertEqual(p.returncode, 0, p.stderr)
        cores = os.cpu_count() or 1
        for n in (2, 3):
            with self.subTest(ranks=n):
                out = work / f"ranks{n}"
                p = with_ranks("run", SCENE, "--out", out, "--force", "--quiet", "--ranks", n)
                self.assertEqual(p.returncode, 0, p.stderr)
                self.assertEqual((out / "history.csv").read_bytes(),
                                 (ref / "history.csv").read_bytes())
                self.assertEqual(summary_without_run_block(out / "summary.json"),
                                 summary_without_run_block(ref / "summary.json"))
                run = json.loads((out / "summary.json").read_text())["run"]
                self.assertEqual(run["ranks"], n)
                self.assertEqual(run["threads"], max(1, cores // n))
                if n == 2:
                    self.assert_report_on_ranks(out, run)
        out = work / "ranks1"
        p = with_ranks("run", SCENE, "--out", out, "--force", "--quiet", "--ranks", 1)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertNotIn("ranks", json.loads((out / "summary.json").read_text())["run"])
        self.assertEqual((out / "history.csv").read_bytes(), (ref / "history.csv").read_bytes())

    def assert_report_on_ranks(self, out, run):
        """`crater report` of a run on ranks says so, and tabulates each rank's loop time and
        each part's share among the ranks as summary.json has them."""
        p = subprocess.run([BIN, "report", out], capture_output=True, text=True, timeout=300)
        self.assertEqual(p.returncode, 0, p.stderr)
        text = (out / "report" / "report.md").read_text()
        self.assertIn(f"s on {run['ranks']} MPI ranks of {run['threads']} thread(s)", text)
        for r, t in enumerate(run["time_by_rank_s"]["loop"]):
            self.assertRegex(text, rf"\| {r} \| {t:.4g} \|")
        for name, f in run["ranks_by_part"].items():
            self.assertIn(f"| `{name}` | {f['owned_min']} – {f['owned_max']} |", text)

    def test_errors_exit_2(self):
        work = scratch("ranks_option_errors")
        bad = work / "bad.toml"
        bad.write_text('[scenario]\nname = "x"\n')
        p = with_ranks("run", bad, "--out", work / "bad", "--force", "--ranks", 2)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertEqual(p.stderr.count("missing required key (an array of tables"), 2,
                         p.stderr)  # materials and parts, once each: rank 0 says them
        p = mpirun(2, "run", SCENE, "--out", work / "mismatch", "--force", "--ranks", 3)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("--ranks 3 was given under a launcher that started 2", p.stderr)
        p = with_ranks("run", SCENE, "--out", work / "zero", "--force", "--ranks", 0)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("--ranks", p.stderr)
        p = with_ranks("run", SCENE, "--out", work / "nolauncher", "--force", "--ranks", 2,
                       extra_env={"CRATER_MPIEXEC": str(work / "no-such-mpiexec")})
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("no-such-mpiexec cannot be run", p.stderr)
        self.assertFalse((work / "nolauncher" / "summary.json").exists())


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
