# ctest-timeout: 600
"""The run directory keeps a user's data and a run's ability to continue (issue 22, items 1, 2,
6, 7 and 9). Each case failed on the code before the fix:

1. `--force` removed every *.csv and *.json of --out, the user's own too, and a first run into
   a non-empty directory was not questioned; an old report/ survived.
2. The old run's checkpoints survived --force, so the new run's were pruned as soon as written
   and --resume refused.
6. `--restart FILE --out NEWDIR` failed (and its error named --resume).
7. A full disk left no summary.json; --resume after freeing space must continue from the newest
   complete checkpoint, bit-identical to an uninterrupted run.
9. The run directory did not record --set/--level/--threads: `crater run --resume DIR` now
   needs nothing retyped; SIGINT says how to resume.

Scenario: the bundled demo (2D SPH charge, 97 steps, 9 frames).
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import unittest
from pathlib import Path

from crater_test import BIN, crater, scratch, summary_without_run_block

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DEMO = SOURCE / "scenarios" / "demo.toml"
EVERY = ["--set", "output.checkpoint_every_steps=20"]


def outputs(d):
    """The files whose bytes a continued run must reproduce (VTU, PVD, history)."""
    return {p.name: p.read_bytes() for p in sorted(Path(d).iterdir())
            if p.suffix in (".vtu", ".pvd") or p.name == "history.csv"}


class RunDirectory(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = scratch("run_directory")
        cls.full = cls.dir / "full"
        crater("run", DEMO, "--out", cls.full, "--quiet", *EVERY)

    def fresh(self, name):
        d = self.dir / name
        if d.exists():
            shutil.rmtree(d)
        return d

    def test_summary_splits_the_loop_time_by_part(self):
        # run.time_by_part_s: every part of the scenario by name, the contacts, probes, output
        # and the rest; none negative, and together they are the loop's wall time.
        s = json.loads((self.full / "summary.json").read_text())
        tp = s["run"]["time_by_part_s"]
        self.assertEqual(list(tp["parts"]), [p["name"] for p in s["parts"]])
        spent = list(tp["parts"].values()) + [tp[k] for k in ("contacts", "probes", "output",
                                                             "other")]
        self.assertTrue(all(x >= 0 for x in spent), tp)
        self.assertGreater(sum(tp["parts"].values()), 0)
        loop = s["run"]["loop_time_s"]
        self.assertLessEqual(sum(spent) - tp["other"], loop * (1 + 1e-9))
        if tp["other"] > 0:
            self.assertAlmostEqual(sum(spent), loop, delta=1e-9 * loop)

    # --- 1 ---------------------------------------------------------------------------------
    def test_force_keeps_the_users_files_and_clears_the_old_run(self):
        out = self.fresh("force")
        crater("run", DEMO, "--out", out, "--quiet", *EVERY, "--set", "output.interval_s=4e-6")
        (out / "my_notes.csv").write_text("mine\n")
        (out / "my_settings.json").write_text("{}\n")
        (out / "report").mkdir()
        (out / "report" / "report.md").write_text("the previous run's report\n")
        old_frames = sorted(p.name for p in out.glob("*.vtu"))
        self.assertIn("charge_000010.vtu", old_frames)
        proc = crater("run", DEMO, "--out", out, "--quiet", *EVERY, check=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("--force", proc.stderr)
        crater("run", DEMO, "--out", out, "--quiet", "--force", *EVERY)
        self.assertEqual((out / "my_notes.csv").read_text(), "mine\n")
        self.assertEqual((out / "my_settings.json").read_text(), "{}\n")
        self.assertFalse((out / "report").exists(), "the old run's report/ survived --force")
        self.assertFalse((out / "charge_000010.vtu").exists(), "an old frame survived --force")
        self.assertEqual(outputs(out), outputs(self.full))

    def test_non_empty_directory_without_manifest_is_refused(self):
        out = self.fresh("foreign")
        out.mkdir()
        (out / "data.csv").write_text("precious\n")
        for extra in ([], ["--force"]):
            proc = crater("run", DEMO, "--out", out, "--quiet", *extra, check=False)
            self.assertEqual(proc.returncode, 2, proc.stderr)
            self.assertIn("--out", proc.stderr)
            self.assertIn("did not write", proc.stderr)
        self.assertEqual([p.name for p in out.iterdir()], ["data.csv"])

    def test_hostile_manifest_cannot_delete_outside(self):
        out = self.fresh("hostile_manifest")
        crater("run", DEMO, "--out", out, "--quiet")
        victim = self.dir / "victim.txt"
        victim.write_text("outside\n")
        with open(out / "crater-manifest.txt", "a") as f:
            f.write("../victim.txt\n" + str(victim) + "\n")
        crater("run", DEMO, "--out", out, "--quiet", "--force")
        self.assertTrue(victim.exists(), "--force followed a manifest line out of the directory")

    # --- 2 ---------------------------------------------------------------------------------
    def test_force_clears_old_checkpoints_so_the_new_run_resumes(self):
        out = self.fresh("force_checkpoints")
        # The old run: checkpoints up to step 80. The new one: another scenario (a shorter end
        # time), stopped at step 30 with a checkpoint at 20 (and none at its end, so that the
        # resume below starts from 20).
        crater("run", DEMO, "--out", out, "--quiet", *EVERY)
        self.assertTrue((out / "checkpoints" / "step_000000000080.ckpt").exists())
        new = [*EVERY, "--set", "scenario.end_time_s=3e-5", "--set", "time.max_steps=30",
               "--set", "output.checkpoint_at_end=false"]
        crater("run", DEMO, "--out", out, "--quiet", "--force", *new)
        cks = sorted(p.name for p in (out / "checkpoints").glob("*.ckpt"))
        self.assertEqual(cks, ["step_000000000020.ckpt"])
        proc = crater("run", DEMO, "--resume", out, "--quiet", *new, check=False)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        summary = json.loads((out / "summary.json").read_text())
        self.assertEqual((summary["status"], summary["steps"]), ("completed", 30))

    # --- 6 ---------------------------------------------------------------------------------
    def test_restart_into_a_new_directory(self):
        src = self.fresh("restart_src")
        shutil.copytree(self.full, src)
        ck = sorted((src / "checkpoints").glob("*.ckpt"))[0]
        new = self.fresh("restart_new")
        crater("run", DEMO, "--restart", ck, "--out", new, "--quiet", *EVERY)
        self.assertEqual(outputs(new), outputs(self.full))
        self.assertEqual(summary_without_run_block(new / "summary.json"),
                         summary_without_run_block(self.full / "summary.json"))
        self.assertEqual(outputs(src), outputs(self.full), "the source run was changed")

    def test_restart_error_names_restart(self):
        src = self.fresh("restart_short_history")
        shutil.copytree(self.full, src)
        (src / "history.csv").write_text("step\n")
        ck = sorted((src / "checkpoints").glob("*.ckpt"))[0]
        proc = crater("run", DEMO, "--restart", ck, "--out", self.fresh("restart_bad"), "--quiet",
                      *EVERY, check=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("--restart", proc.stderr)
        self.assertNotIn("--resume'", proc.stderr)

    # --- 7 ---------------------------------------------------------------------------------
    def test_full_disk_leaves_a_summary_and_resumes(self):
        if shutil.which("unshare") is None:
            self.skipTest("unshare (util-linux) is missing")
        mnt = self.fresh("disk_mnt")
        mnt.mkdir()
        kept = self.fresh("disk_result")
        # A 1 MB file system fills after a few frames and checkpoints; then it grows, and the
        # run continues with --resume alone.
        script = f"""
set -u
mount -t tmpfs -o size=1200k none '{mnt}' || exit 90
'{BIN}' run '{DEMO}' --out '{mnt}/run' --quiet {' '.join(EVERY)} 2> '{mnt}/../disk_err.txt'
echo $? > '{mnt}/../disk_rc.txt'
cp -r '{mnt}/run' '{kept}.failed'
mount -o remount,size=20m '{mnt}' || exit 91
'{BIN}' run --resume '{mnt}/run' --quiet || exit 92
cp -r '{mnt}/run' '{kept}'
"""
        proc = subprocess.run(["unshare", "--user", "--map-root-user", "--mount", "sh", "-c",
                               script], capture_output=True, text=True, timeout=300)
        if proc.returncode == 90:
            self.skipTest("cannot mount a tmpfs in a user namespace here: " + proc.stderr)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        rc = int((self.dir / "disk_rc.txt").read_text())
        err = (self.dir / "disk_err.txt").read_text()
        self.assertEqual(rc, 1, err)
        self.assertIn("No space left", err)
        failed = Path(f"{kept}.failed")
        summary = json.loads((failed / "summary.json").read_text())
        self.assertIn(summary["status"], ("failed", "running"))
        self.assertTrue(list((failed / "checkpoints").glob("*.ckpt")))
        self.assertEqual(outputs(kept), outputs(self.full))
        self.assertEqual(json.loads((kept / "summary.json").read_text())["status"], "completed")
        shutil.rmtree(failed)

    # --- 9 ---------------------------------------------------------------------------------
    def test_resume_reuses_the_recorded_command(self):
        out = self.fresh("recorded")
        sets = ["--set", "output.checkpoint_every_steps=20", "--set", "time.safety_factor=0.8"]
        proc = subprocess.Popen([BIN, "run", DEMO, "--out", out, "--quiet", "--threads", "1",
                                 *sets], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        t0 = time.time()
        while not (out / "checkpoints" / "step_000000000040.ckpt").exists():
            self.assertIsNone(proc.poll(), "the run ended before its checkpoint at step 40")
            self.assertLess(time.time() - t0, 300)
            time.sleep(0.01)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=300)
        self.assertEqual(proc.returncode, 130, err)
        self.assertIn(f"crater run --resume {out}", err)
        summary = json.loads((out / "summary.json").read_text())
        self.assertEqual(summary["run"]["command"]["set"],
                         ["output.checkpoint_every_steps=20", "time.safety_factor=0.8"])
        self.assertEqual(summary["run"]["command"]["threads"], 1)
        # No scenario, no --set: the recorded ones (another safety factor would be refused).
        crater("run", "--resume", out, "--quiet")
        reference = self.fresh("recorded_reference")
        crater("run", DEMO, "--out", reference, "--quiet", *sets)
        self.assertEqual(outputs(out), outputs(reference))

    def test_report_shows_the_command(self):
        out = self.fresh("reported")
        crater("run", DEMO, "--out", out, "--quiet", "--set", "time.safety_factor=0.8")
        proc = crater("report", out, check=False, timeout=300)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        text = (out / "report" / "report.md").read_text()
        self.assertIn("| command | `", text)
        self.assertIn("--set time.safety_factor=0.8", text)

    def test_killed_run_leaves_a_summary(self):
        out = self.fresh("killed")
        proc = subprocess.Popen([BIN, "run", DEMO, "--out", out, "--quiet", *EVERY],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        t0 = time.time()
        while not (out / "checkpoints" / "step_000000000020.ckpt").exists():
            self.assertIsNone(proc.poll(), "the run ended before its first checkpoint")
            self.assertLess(time.time() - t0, 300)
            time.sleep(0.01)
        proc.kill()
        proc.wait()
        summary = json.loads((out / "summary.json").read_text())
        self.assertIn(summary["status"], ("running", "completed"))
        self.assertEqual(summary["scenario"]["name"], "demo")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
