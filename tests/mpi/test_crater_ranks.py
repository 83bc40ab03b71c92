# ctest-processors: 2
# ctest-timeout: 300
"""`crater run` on several MPI ranks (issue 29, docs/distributed.md, "crater run on ranks").

The DEM bed of tests/data/dem_ranks_3d.toml (729 spheres bursting into the empty half of a
closed box) is run without a launcher on one thread (the reference), and under
`mpirun -np 1, 2, 3, 4` on one thread and `-np 2` on two threads per rank (4 ranks
oversubscribed on 2 cores). Every run must give the reference's files bit for bit:
- history.csv, byte for byte (energies and work books summed over the ranks);
- summary.json but its "run" block (counts, masses, diagnostics, energies, steps);
- every VTU frame's points and point data, entity by entity (by id: one rank writes in its
  memory order, the root of several ranks in id order), read with VTK's reader;
- the same set of files (the root alone writes), with the PVD collection;
- the same checkpoints (steps 1000 and 1224), byte for byte: the root writes the whole bed in
  the order one rank holds it.
Then the run is resumed from the 2-rank checkpoint of step 1000 on 3 ranks and on 1 (plain):
every file is again the uninterrupted run's.
The same bed settled under gravity first ([parts.packing] settle = true): on 2 ranks the ranks
settle it together (the bed spread as a run's) and rank 0 writes the cache (one file, the plain
run's byte for byte), and the run is the plain run's bit for bit; on 3 ranks the cached packing
is reused, with the same history. A bed carved around a charge and a plate
(tests/data/contacts_ranks_2d.toml) settles on 2 ranks into the cache file of one rank, byte
for byte (the carved regions are fixed bodies of the settling bed).
A bonded block (tests/data/dem_bonded_2d.toml, 800 disks, 1,540 parallel bonds, linear
springs, rolling resistance, rate-dependent friction) thrown onto a walled floor, run to 20 ms
(2,684 steps): 901 bonds break, fragments roll, and grains change ranks (188 arrivals on a new
rank on 2 ranks, 1,176 on 4) with their bonds; bit for bit on 2, 3, 4 ranks and 2 ranks of 2
threads, its 2-rank checkpoint resumed on 3 ranks and on 1.
The same bed between moving walls (the top one coming down at 0.5 m/s, the right one a servo at
20 kPa): history.csv's wall columns and every file bit for bit on 2, 3, 4 ranks and 2 ranks of
2 threads, its 2-rank checkpoint resumed on 3 ranks and on 1.
tests/data/outflow_2d.toml (a gas disk, a cloud of grains and two bonded columns leaving a
small box, domain.outflow = "remove": the gas and the columns leave whole, 76 of the cloud's 96
grains, so the ranks end up holding none of a part's entities, bonded ones included): bit for
bit on 2, 3 and 4 ranks, resumed on 3 and on 1.
`crater check` under the launcher, and an error of rank 0 alone, end every rank with exit code
2 and one message. The progress line on ranks shows the load balance (the part whose heaviest
rank is furthest above the mean, as summary.json's ranks_by_part has it).
Under `make test` only the first case of the file runs on 4 ranks and on 2 ranks of 2
threads, the others on 2 and 3 ranks of one thread (on_ranks.rank_counts); `make test-slow`
runs every case on every count (test_ranks_full_slow.py).
"""
import csv
import json
import re
import shutil
import subprocess
import sys
import unittest

from crater_test import BIN, SOURCE_DIR, scratch
from on_ranks import (MPIRUN, assert_ranks_give, assert_resumes, assert_resumes_elsewhere,
                      assert_same_run, by_id, checkpoints, files, mpirun, plain, rank_counts)

SCENE = SOURCE_DIR / "tests" / "data" / "dem_ranks_3d.toml"
# Checkpoints by step count only (a wall-clock one would come when a run is slow).
CHECKPOINTS = ["--set", "output.checkpoint_every_steps=500", "--set", "output.checkpoint_every_s=0"]
CKPTS = ["step_000000001000.ckpt", "step_000000001224.ckpt"]
# Moving walls: the top one from just above the bed down at 0.5 m/s, the right one a servo at
# 20 kPa (their loads are sums over every rank's grains).
WALLS = ('parts.bed.dem.wall_motion=[{face="top",position_m=0.06,velocity_m_s=-0.5},'
         '{face="right",stress_pa=2.0e4,max_speed_m_s=0.5}]')


@unittest.skipIf(not MPIRUN, "crater was built without MPI (CRATER_MPIRUN unset)")
class CraterRunOnRanks(unittest.TestCase):
    def test_dem_bed_bit_identical_on_1_to_4_ranks(self):
        work = scratch("crater_ranks")
        ref = work / "plain"
        p = subprocess.run([BIN, "run", SCENE, "--out", ref, "--force", "--quiet", "--threads",
                            "1", *CHECKPOINTS], capture_output=True, text=True, timeout=240)
        self.assertEqual(p.returncode, 0, p.stderr)
        frames = [n for n in files(ref) if n.endswith(".vtu")]
        self.assertEqual(len(frames), 5)
        first, _ = by_id(ref / frames[0])
        self.assertEqual(len(first["id"]), 729)
        for np_, threads in ((1, 1), (2, 1), (3, 1), (4, 1), (2, 2)):
            with self.subTest(ranks=np_, threads=threads):
                out = work / f"ranks{np_}_threads{threads}"
                p = mpirun(np_, "run", SCENE, "--out", out, "--force", "--quiet", "--threads",
                           threads, *CHECKPOINTS, threads=threads)
                self.assertEqual(p.returncode, 0, p.stderr)
                assert_same_run(self, ref, out, f"{np_} ranks x {threads} threads", CKPTS)
        # Resumed from the checkpoint of 2 ranks at step 1000, on 3 ranks and on 1.
        for np_ in (3, 1):
            with self.subTest(resumed_on=np_):
                assert_resumes(self, SCENE, work / "ranks2_threads1", CKPTS[0], np_, CHECKPOINTS,
                               f"resumed on {np_}")

    def test_settled_bed_on_ranks(self):
        work = scratch("crater_ranks_settled")
        cache = work / "cache"
        sets = ["--set", "parts.bed.packing.settle=true",
                "--set", f'parts.bed.packing.cache_dir="{cache}"', *CHECKPOINTS]
        ref = work / "plain"
        p = subprocess.run([BIN, "run", SCENE, "--out", ref, "--force", "--quiet", "--threads",
                            "1", *sets], capture_output=True, text=True, timeout=240)
        self.assertEqual(p.returncode, 0, p.stderr)
        (packed,) = list(cache.iterdir())
        settled_alone = packed.read_bytes()
        shutil.rmtree(cache)
        # Settled again on 2 ranks (the cache is empty): spread over both, the same bytes.
        out = work / "ranks2_threads1"
        p = mpirun(2, "run", SCENE, "--out", out, "--force", "--quiet", "--threads", 1, *sets)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual([f.name for f in cache.iterdir()], [packed.name])
        self.assertEqual(packed.read_bytes(), settled_alone)
        assert_same_run(self, ref, out, "settled on 2 ranks", CKPTS)
        # Reused on 3 ranks: the run's history again (summary.json says "reused").
        out = work / "ranks3_reused"
        p = mpirun(3, "run", SCENE, "--out", out, "--force", "--quiet", "--threads", 1, *sets)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual((out / "history.csv").read_bytes(), (ref / "history.csv").read_bytes())
        self.assertEqual([f.name for f in cache.iterdir()], [packed.name])

    def test_carved_bed_settled_on_ranks(self):
        # Settled around the charge and the plate (fixed bodies while it settles), on one rank
        # and on 2: the same cache file, byte for byte; one step of the run after it.
        # Gravity 1,000 times the earth's, and settled when the grains' kinetic energy is below
        # m g r: the column falls in 5 ms (18,400 steps, 1.2 s on one rank; 5 min at 1 g) onto
        # the plate and around the charge.
        work = scratch("crater_ranks_carved")
        scene = SOURCE_DIR / "tests" / "data" / "contacts_ranks_2d.toml"
        packed = {}
        for np_ in (1, 2):
            cache = work / f"cache{np_}"
            sets = ["--set", "parts.soil.packing.settle=true",
                    "--set", f'parts.soil.packing.cache_dir="{cache}"',
                    "--set", "domain.gravity_m_s2=[0.0,-1e4]",
                    "--set", "parts.soil.packing.settle_kinetic_ratio=1.0",
                    "--set", "time.max_steps=1", "--set", "output.vtu=false"]
            out = work / f"ranks{np_}"
            args = ("run", scene, "--out", out, "--force", "--threads", 1, *sets)
            p = mpirun(2, *args) if np_ == 2 else plain(*args)
            self.assertEqual(p.returncode, 0, p.stderr)
            if np_ == 2:  # rank 0's log: the bed settled spread over the ranks
                self.assertIn("settling 550 grains under gravity", p.stdout + p.stderr)
                self.assertIn("spread over 2 ranks", p.stdout + p.stderr)
            (packed[np_],) = list(cache.iterdir())
        self.assertEqual(packed[2].name, packed[1].name)
        self.assertEqual(packed[2].read_bytes(), packed[1].read_bytes())
        self.assertEqual((work / "ranks2" / "history.csv").read_bytes(),
                         (work / "ranks1" / "history.csv").read_bytes())

    def test_bonded_block_on_ranks(self):
        work = scratch("crater_ranks_bonded")
        ref = work / "plain"
        scene = SOURCE_DIR / "tests" / "data" / "dem_bonded_2d.toml"
        opts = ["--set", "scenario.end_time_s=0.02", "--set", "output.interval_s=0.005",
                *checkpoints(1000)]
        p = plain("run", scene, "--out", ref, "--force", "--quiet", "--threads", "1", *opts)
        self.assertEqual(p.returncode, 0, p.stderr)
        diagnostics = json.loads((ref / "summary.json").read_text())["parts"][0]["diagnostics"]
        self.assertGreater(diagnostics["bonds_broken"], 100)  # bonds break during the run
        self.assertLess(diagnostics["bonds_broken"], diagnostics["bonds_initial"])  # and hold

        def moved(out, np_):  # grains changed ranks with their bonds
            figures = json.loads((out / "summary.json").read_text())["run"]["ranks_by_part"]
            self.assertGreater(figures["rock"]["migrations"], 50, figures)

        ckpts = sorted(f.name for f in (ref / "checkpoints").iterdir())
        self.assertEqual(len(ckpts), 3)
        assert_ranks_give(self, ref, scene, opts, rank_counts([(2, 1), (3, 1), (4, 1), (2, 2)]),
                          ckpts, "bonded", moved)
        assert_resumes_elsewhere(self, scene, ref, ckpts[0], opts, "bonded")

    def test_moving_walls_on_ranks(self):
        work = scratch("crater_ranks_walls")
        ref = work / "plain"
        opts = ["--set", WALLS, *CHECKPOINTS]
        p = plain("run", SCENE, "--out", ref, "--force", "--quiet", "--threads", "1", *opts)
        self.assertEqual(p.returncode, 0, p.stderr)
        rows = list(csv.DictReader(open(ref / "history.csv")))
        # the top wall came down into the bursting grains, the servo wall carried them
        self.assertAlmostEqual(float(rows[-1]["bed_wall_top_position_m"]), 0.06 - 0.5 * 0.004,
                               delta=1e-9)
        self.assertGreater(max(float(r["bed_wall_top_force_n"]) for r in rows), 0)
        self.assertGreater(max(float(r["bed_wall_right_force_n"]) for r in rows), 0)
        assert_ranks_give(self, ref, SCENE, opts, rank_counts([(2, 1), (3, 1), (4, 1), (2, 2)]),
                          CKPTS, "moving walls")
        assert_resumes_elsewhere(self, SCENE, ref, CKPTS[0], opts, "moving walls")

    def test_outflow_scene_on_ranks(self):
        work = scratch("crater_ranks_outflow")
        ref = work / "plain"
        scene = SOURCE_DIR / "tests" / "data" / "outflow_2d.toml"
        opts = checkpoints(100)
        p = plain("run", scene, "--out", ref, "--force", "--quiet", "--threads", "1", *opts)
        self.assertEqual(p.returncode, 0, p.stderr)
        parts = json.loads((ref / "summary.json").read_text())["parts"]
        for part in parts:  # every one that left is booked
            first, _ = by_id(ref / f"{part['name']}_000000.vtu")
            self.assertEqual(part["count"] + part["diagnostics"]["left_domain_count"],
                             len(first["id"]), part["name"])
        # the gas and the bonded columns are gone whole: no rank holds any of them
        self.assertEqual([p["count"] for p in parts if p["name"] != "cloud"], [0, 0])
        ckpts = sorted(f.name for f in (ref / "checkpoints").iterdir())
        self.assertGreaterEqual(len(ckpts), 3)
        assert_ranks_give(self, ref, scene, opts, rank_counts([(2, 1), (3, 1), (4, 1)]), ckpts,
                          "outflow")
        assert_resumes_elsewhere(self, scene, ref, ckpts[1], opts, "outflow")

    def test_progress_line_shows_the_load(self):
        # The last progress line names the part whose heaviest rank is furthest above the mean.
        out = scratch("crater_ranks_progress") / "out"
        p = mpirun(2, "run", SCENE, "--out", out, "--force", "--set", "time.max_steps=50")
        self.assertEqual(p.returncode, 0, p.stderr)
        m = re.search(r"2 ranks, load max/mean (\d+\.\d+) \(bed\)", p.stderr)
        self.assertIsNotNone(m, p.stderr)
        self.assertGreaterEqual(float(m.group(1)), 1.0)
        run = json.loads((out / "summary.json").read_text())["run"]
        figures = run["ranks_by_part"]
        self.assertAlmostEqual(figures["bed"]["load_ratio"], float(m.group(1)), delta=0.005)
        # Each rank's loop, stages and time in MPI's calls: rank 0's stages are time_by_part_s's
        # (the gather keeps the ranks' order), and no stage waits longer than it lasts.
        by_rank = run["time_by_rank_s"]
        self.assertEqual(by_rank["loop"][0], run["loop_time_s"])
        self.assertEqual(by_rank["parts"]["bed"][0], run["time_by_part_s"]["parts"]["bed"])
        self.assertEqual(by_rank["contacts"][0], run["time_by_part_s"]["contacts"])
        for q in range(2):
            self.assertGreater(by_rank["mpi"][q], 0)  # every step has its collectives
            self.assertLessEqual(by_rank["mpi"][q], by_rank["loop"][q])
            self.assertLessEqual(by_rank["mpi_by_stage"]["bed"][q], by_rank["parts"]["bed"][q])
            self.assertLessEqual(by_rank["mpi_by_stage"]["bed"][q] +
                                 by_rank["mpi_by_stage"]["contacts"][q], by_rank["mpi"][q])
        self.assertEqual([len(v) for v in by_rank.values() if isinstance(v, list)], [2, 2, 2])
        # One rank has no such block.
        one = scratch("crater_ranks_progress") / "one"
        p = plain("run", SCENE, "--out", one, "--force", "--quiet", "--set", "time.max_steps=5")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertNotIn("time_by_rank_s", json.loads((one / "summary.json").read_text())["run"])

    def test_errors_on_ranks(self):
        work = scratch("crater_ranks_refused")
        # Every model runs on ranks; `crater check` does not.
        p = mpirun(2, "check", SCENE)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("only `crater run` runs on several MPI ranks", p.stderr)
        # An error of rank 0 alone (an --out that holds a run, without --force) ends every
        # rank: the others used to wait for it forever.
        out = work / "holds_a_run"
        p = mpirun(2, "run", SCENE, "--out", out, "--force", "--quiet", "--set",
                   "time.max_steps=10")
        self.assertEqual(p.returncode, 0, p.stderr)
        p = mpirun(2, "run", SCENE, "--out", out, "--quiet", timeout=60)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("pass --force to replace it", p.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
