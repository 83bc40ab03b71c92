# ctest-timeout: 600
"""Checkpoints and restart (issue 7): a run killed half-way and resumed, or stopped by SIGINT
and resumed, gives outputs bit-identical to an uninterrupted run; a damaged or mismatched
checkpoint is refused before anything runs.

Scenario: the bundled demo (2D SPH TNT charge, 97 steps) with a checkpoint every 20 steps.
"Bit-identical": every VTU, the PVD and history.csv byte for byte; summary.json equal except
its "run" block (wall time, threads) and, for the resumed runs, nothing else.
"""
import os
import shutil
import signal
import subprocess
import sys
import time
import unittest
from pathlib import Path

from crater_test import BIN, assert_restart_identical, crater, scratch, summary_without_run_block

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DEMO = SOURCE / "scenarios" / "demo.toml"
EVERY = ["--set", "output.checkpoint_every_steps=20"]


def start(out):
    return subprocess.Popen([BIN, "run", DEMO, "--out", out, "--force", "--quiet", *EVERY],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_for(path, proc, timeout=300):
    t0 = time.time()
    while not path.exists():
        if proc.poll() is not None:
            raise AssertionError(f"the run ended before {path} appeared")
        if time.time() - t0 > timeout:
            raise AssertionError(f"{path} did not appear")
        time.sleep(0.02)


class Checkpoints(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = scratch("checkpoint")
        cls.full = cls.dir / "full"
        crater("run", DEMO, "--out", cls.full, "--force", "--quiet", *EVERY)

    def assert_same_run(self, other):
        names = sorted(p.name for p in self.full.iterdir() if p.is_file())
        self.assertTrue(any(n.endswith(".vtu") for n in names))
        for n in names:
            a, b = self.full / n, other / n
            self.assertTrue(b.exists(), f"{n} missing in {other}")
            if n == "crater-command.toml":
                continue  # the command line: --out differs
            if n == "summary.json":
                self.assertEqual(summary_without_run_block(a), summary_without_run_block(b))
            else:
                self.assertEqual(a.read_bytes(), b.read_bytes(), f"{n} differs")

    def test_sigkill_then_resume_is_bit_identical(self):
        out = self.dir / "killed"
        proc = start(out)
        wait_for(out / "checkpoints" / "step_000000000040.ckpt", proc)
        proc.kill()
        proc.wait()
        import json
        status = json.loads((out / "summary.json").read_text())["status"]
        self.assertEqual(status, "running", "the killed run finished anyway")
        crater("run", DEMO, "--resume", out, "--quiet", *EVERY)
        self.assert_same_run(out)

    def test_sigint_writes_checkpoint_exits_130_and_resumes(self):
        out = self.dir / "interrupted"
        proc = start(out)
        wait_for(out / "checkpoints" / "step_000000000020.ckpt", proc)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=300)
        self.assertEqual(proc.returncode, 130, err)
        import json
        s = json.loads((out / "summary.json").read_text())
        self.assertEqual(s["status"], "interrupted")
        newest = sorted((out / "checkpoints").glob("*.ckpt"))[-1]
        step = int(newest.stem.split("_")[1])
        self.assertEqual(step, s["steps"], "the checkpoint is not of the step the run stopped at")
        crater("run", DEMO, "--resume", out, "--quiet", *EVERY)
        self.assert_same_run(out)

    def copy_with_checkpoint(self, name):
        out = self.dir / name
        if out.exists():
            shutil.rmtree(out)
        shutil.copytree(self.full, out)
        ck = sorted((out / "checkpoints").glob("*.ckpt"))[-1]
        return out, ck

    def test_flipped_byte_is_refused(self):
        out, ck = self.copy_with_checkpoint("flipped")
        data = bytearray(ck.read_bytes())
        data[len(data) // 2] ^= 0x10
        ck.write_bytes(bytes(data))
        before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
        proc = crater("run", DEMO, "--restart", ck, "--quiet", *EVERY, check=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("checksum", proc.stderr)
        self.assertIn(ck.name, proc.stderr)
        after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
        self.assertEqual(before, after, "a refused checkpoint changed the run directory")

    def test_truncated_checkpoint_is_refused(self):
        out, ck = self.copy_with_checkpoint("truncated")
        ck.write_bytes(ck.read_bytes()[:-100])
        proc = crater("run", DEMO, "--restart", ck, "--quiet", *EVERY, check=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("truncated", proc.stderr)

    def test_other_scenario_is_refused(self):
        out, ck = self.copy_with_checkpoint("other")
        proc = crater("run", DEMO, "--restart", ck, "--quiet", *EVERY,
                      "--set", "time.safety_factor=0.5", check=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("another scenario", proc.stderr)

    def test_restart_from_mid_run_checkpoints(self):
        # Every part type, restarted from checkpoints the uninterrupted run wrote (kept): DEM
        # with contact histories (a settling bed) and with bonds breaking, SPH in 3D, FEM with
        # plasticity, damage and erosion, and Holmquist-Johnson-Cook concrete (its compaction
        # state per element).
        # SPH also with the summation density (h solved at each force stage from the saved h),
        # in 3D and beside no-slip walls (the dam break: the wall particles' densities, which
        # the summation reads before they are averaged again, are in the checkpoint since
        # 2026-12-01; before, a restart started them from rho0 and went its own way).
        cases = [("dem_bed_2d.toml", 5000, []), ("dem_bonded_2d.toml", 100, []),
                 ("sph3d_small.toml", 5, []),
                 ("sph3d_small.toml", 5, ["--set", "parts.charge.sph.density=\"summation\"",
                                          "--set", "scenario.end_time_s=2e-5"]),
                 ("sph_ranks_2d.toml", 100, ["--set", "parts.fluid.sph.density=\"summation\"",
                                            "--set", "scenario.end_time_s=0.1"]),
                 ("fem_plate_2d.toml", 150, []), ("fem_concrete_2d.toml", 100, [])]
        for k, (name, every, extra) in enumerate(cases):
            with self.subTest(scenario=name, extra=extra):
                scen = SOURCE / "tests" / "data" / name
                sets = ["--set", f"output.checkpoint_every_steps={every}",
                        "--set", "output.checkpoint_keep=1000", *extra]
                full = self.dir / f"full_{k}_{name}"
                crater("run", scen, "--out", full, "--force", "--quiet", *sets)
                cks = sorted((full / "checkpoints").glob("*.ckpt"))
                self.assertGreaterEqual(len(cks), 2)
                for ck in (cks[0], cks[len(cks) // 2]):
                    assert_restart_identical(scen, full, ck, sets[1::2])

    def test_restart_across_outflow_removals(self):
        # domain.outflow = "remove": SPH particles and DEM grains (with contact and bond
        # histories) leave between the checkpoint and the end, and before it; the restarted run
        # removes the same particles at the same steps. Checkpoints before any removal, while
        # the gas leaves, and while the grains leave.
        scen = SOURCE / "tests" / "data" / "outflow_2d.toml"
        sets = ["--set", "output.checkpoint_every_steps=10", "--set", "output.checkpoint_keep=1000"]
        full = self.dir / "full_outflow"
        crater("run", scen, "--out", full, "--force", "--quiet", *sets)
        import json
        summary = json.loads((full / "summary.json").read_text())
        left = {p["name"]: p["diagnostics"]["left_domain_count"] for p in summary["parts"]}
        self.assertTrue(all(n > 0 for n in left.values()), left)
        history = (full / "history.csv").read_text().splitlines()
        column = history[0].split(",").index("eroded_j")
        eroded = {int(r.split(",")[0]): float(r.split(",")[column]) for r in history[1:]}
        final = eroded[max(eroded)]
        cks = sorted((full / "checkpoints").glob("*.ckpt"))
        steps = {ck: int(ck.stem.split("_")[1]) for ck in cks}
        before = [ck for ck in cks if eroded[steps[ck]] == 0]
        during = [ck for ck in cks if 0 < eroded[steps[ck]] < final]
        self.assertTrue(before, "no checkpoint before the first removal")
        self.assertGreaterEqual(len(during), 3, "too few checkpoints between removals")
        for ck in (before[-1], during[0], during[len(during) // 2], during[-1]):
            with self.subTest(checkpoint=ck.name):
                assert_restart_identical(scen, full, ck, sets[1::2])

    def test_resume_without_checkpoint_is_refused(self):
        out = self.dir / "empty"
        out.mkdir(exist_ok=True)
        proc = crater("run", DEMO, "--resume", out, "--quiet", check=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("checkpoint", proc.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
