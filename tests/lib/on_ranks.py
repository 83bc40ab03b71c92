"""Helpers for the tests that run crater on several MPI ranks (tests/mpi/*.py): the launcher,
and the comparison of a run on ranks with the plain run of one rank, bit for bit.

CRATER_MPIRUN (set by CMake in a build with MPI; empty otherwise, and the tests are skipped)
names the launcher.
"""
import os
import shutil
import subprocess

import numpy as np

from crater_test import BIN, read_vtu, read_vtu_cells, summary_without_run_block

MPIRUN = os.environ.get("CRATER_MPIRUN", "")
# The slow set (tests/mpi/test_ranks_full_slow.py, label slow) runs every case on every rank and
# thread count it lists; `make test` runs most of them on 2 and 3 ranks of one thread.
FULL = os.environ.get("CRATER_RANKS_FULL") == "1"
QUICK = [(2, 1), (3, 1)]


def rank_counts(counts):
    """The (ranks, threads per rank) of `counts` a case runs on: those in QUICK under `make
    test`, all of them in the slow set. Each test file keeps one case of each kind on all its
    counts in `make test` (4 ranks, 2 ranks of 2 threads) by listing them without this."""
    return list(counts) if FULL else [c for c in counts if c in QUICK]


def checkpoints(every):
    """--set options for a checkpoint every `every` steps (by step count only: a wall-clock one
    would come when a run is slow), all of them kept."""
    return ["--set", f"output.checkpoint_every_steps={every}", "--set",
            "output.checkpoint_every_s=0", "--set", "output.checkpoint_keep=20"]


def mpirun(np_, *args, threads=1, timeout=240):
    """crater under the launcher on np_ ranks of `threads` threads (oversubscribed as needed)."""
    env = dict(os.environ)
    env.update({"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
                "OMPI_MCA_btl_vader_single_copy_mechanism": "none",
                "OMPI_MCA_rmaps_base_oversubscribe": "1", "OMP_NUM_THREADS": str(threads),
                # every loop parallel, even over these few entities (src/parallel/parallel.hpp)
                "CRATER_PARALLEL_MIN": "0"})
    return subprocess.run([MPIRUN, "-np", str(np_), BIN, *map(str, args)], env=env,
                          capture_output=True, text=True, timeout=timeout)


def plain(*args, timeout=240):
    """crater without a launcher (one rank)."""
    return subprocess.run([BIN, *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def by_id(path):
    """A VTU frame's points and point arrays ordered by the entities' ids, and its time. A mesh
    part's nodes have no id: their file order is their numbering; its cell arrays come too, in
    the file's (element) order, named "cell:<name>"."""
    pts, arrays, _, time = read_vtu(path)
    order = (np.argsort(arrays["id"], kind="stable") if "id" in arrays
             else np.arange(len(pts)))
    out = {name: a[order] for name, a in arrays.items()}
    out["points"] = pts[order]
    if "id" not in arrays:
        out.update({f"cell:{name}": a for name, a in read_vtu_cells(path).items()})
    return out, time


def files(run):
    return sorted(f.name for f in run.iterdir() if f.is_file())


def assert_same_checkpoints(test, a, b, expected):
    names = sorted(f.name for f in (a / "checkpoints").iterdir())
    test.assertEqual(names, expected)
    test.assertEqual(sorted(f.name for f in (b / "checkpoints").iterdir()), names)
    for n in names:
        test.assertEqual((a / "checkpoints" / n).read_bytes(),
                         (b / "checkpoints" / n).read_bytes(), n)


def assert_same_frames(test, ref, out, what):
    """Every VTU frame of `ref` in `out` with the same bits, entity by entity (by id)."""
    for f in [n for n in files(ref) if n.endswith(".vtu")]:
        a, ta = by_id(ref / f)
        b, tb = by_id(out / f)
        test.assertEqual(ta, tb, f)
        test.assertEqual(sorted(a), sorted(b), f)
        for name in a:
            # bit for bit: the bytes of the arrays, not their values
            test.assertTrue(np.array_equal(a[name].view(np.uint8), b[name].view(np.uint8)),
                            f"{f}: {name} differs ({what})")


def assert_same_run(test, ref, out, what, checkpoints):
    """`out` holds the files of `ref`: every CSV file (history, gauges, surface profile), PVD
    collections and checkpoints byte for byte, the summary but its "run" block, every frame's
    points and point data by id."""
    names = files(ref)
    test.assertEqual(files(out), names, what)
    for n in names:
        if n.endswith(".csv") or n.endswith(".pvd"):
            test.assertEqual((out / n).read_bytes(), (ref / n).read_bytes(), f"{n} ({what})")
    test.assertEqual(summary_without_run_block(out / "summary.json"),
                     summary_without_run_block(ref / "summary.json"), what)
    assert_same_checkpoints(test, ref, out, checkpoints)
    assert_same_frames(test, ref, out, what)


def assert_ranks_give(test, ref, scene, opts, ranks, checkpoints, what, check=None, timeout=240):
    """`scene` run with `opts` on each (ranks, threads) of `ranks`, into the sibling
    ranks<N>_threads<T> of the plain run `ref`, writes the files of `ref` (assert_same_run);
    check(out, ranks), if given, looks at each run further. `timeout`: per run [s]."""
    for np_, threads in ranks:
        with test.subTest(case=what, ranks=np_, threads=threads):
            out = ref.parent / f"ranks{np_}_threads{threads}"
            p = mpirun(np_, "run", scene, "--out", out, "--force", "--quiet", "--threads",
                       threads, *opts, threads=threads, timeout=timeout)
            test.assertEqual(p.returncode, 0, p.stderr)
            assert_same_run(test, ref, out, f"{what}: {np_} ranks x {threads} threads",
                            checkpoints)
            if check:
                check(out, np_)


def assert_resumes_elsewhere(test, scene, ref, checkpoint, sets, what):
    """The 2-rank run beside the plain run `ref` (ranks2_threads1), resumed from `checkpoint`
    on 3 ranks and on 1, writes its files again (the tests/mpi cases' restart check)."""
    for np_ in (3, 1):
        with test.subTest(case=what, resumed_on=np_):
            assert_resumes(test, scene, ref.parent / "ranks2_threads1", checkpoint, np_, sets,
                           f"{what}: resumed on {np_}")


def assert_resumes(test, scene, run, checkpoint, ranks, sets, what, timeout=240):
    """The run in `run` resumed from its checkpoint `checkpoint` on `ranks` ranks (1: plain)
    writes the files of the uninterrupted run again (a frame's VTU by its data, a PVTU of frames
    in pieces not at all: it names the pieces of the ranks that wrote it). `timeout`: of the
    resumed run [s]."""
    again = run.parent / f"{run.name}_resumed_on_{ranks}"
    if again.exists():
        shutil.rmtree(again)
    shutil.copytree(run, again)
    (again / "summary.json").unlink()
    args = ["run", scene, "--restart", again / "checkpoints" / checkpoint, "--quiet",
            "--threads", "1", *sets]
    p = mpirun(ranks, *args, timeout=timeout) if ranks > 1 else plain(*args, timeout=timeout)
    test.assertEqual(p.returncode, 0, p.stderr)
    for n in files(run):
        if n.endswith((".vtu", ".pvtu")) or n in ("summary.json", "crater-command.toml"):
            continue
        test.assertEqual((again / n).read_bytes(), (run / n).read_bytes(), f"{n} ({what})")
    test.assertEqual(summary_without_run_block(again / "summary.json"),
                     summary_without_run_block(run / "summary.json"), what)
    ckpts = sorted(f.name for f in (run / "checkpoints").iterdir())
    assert_same_checkpoints(test, run, again, ckpts)
    assert_same_frames(test, run, again, what)
