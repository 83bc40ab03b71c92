"""Helpers for crater's Python tests (run by Debian's /usr/bin/python3).

VTK comes from `vtkmodules` (not `import vtk`, which loads every VTK module): Debian's
python3-vtk9 and ParaView's python3-paraview both provide it (tools/setup-deps.sh).

The environment (set by CTest, see tests/CMakeLists.txt):
  CRATER_BIN         path of the crater binary
  CRATER_SOURCE_DIR  repository root
  CRATER_TEST_TMP    scratch directory for run outputs
"""
import filecmp
import json
import os
import subprocess
import tempfile
from pathlib import Path

BIN = os.environ.get("CRATER_BIN", "build/release/bin/crater")
SOURCE_DIR = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
TMP = Path(os.environ.get("CRATER_TEST_TMP", tempfile.gettempdir()))


COMMAND_FILE = "crater-command.toml"  # a run's command line, recorded in its directory


def scratch(name):
    """A fresh, empty scratch directory for one test."""
    d = TMP / name
    if d.exists():
        for p in sorted(d.rglob("*"), reverse=True):
            p.unlink() if p.is_file() else p.rmdir()
    d.mkdir(parents=True, exist_ok=True)
    return d


def crater(*args, timeout=900, check=True):
    """Runs crater; returns the CompletedProcess. With check, a non-zero exit fails loudly."""
    proc = subprocess.run([BIN, *map(str, args)], capture_output=True, text=True, timeout=timeout)
    if check and proc.returncode != 0:
        raise AssertionError(
            f"crater {' '.join(map(str, args))} exited {proc.returncode}\n"
            f"stdout:\n{proc.stdout}\nstderr:\n{proc.stderr}")
    return proc


def run_scenario(scenario, out_dir, threads=None, sets=(), extra=(), timeout=900):
    """Runs a scenario quietly into out_dir (overwriting); returns the parsed summary.json.
    timeout [s] bounds the run (crater())."""
    args = ["run", scenario, "--out", out_dir, "--force", "--quiet"]
    if threads is not None:
        args += ["--threads", threads]
    for s in sets:
        args += ["--set", s]
    crater(*args, *extra, timeout=timeout)
    with open(Path(out_dir) / "summary.json") as f:
        return json.load(f)


def summary_without_run_block(path):
    """summary.json minus its "run" block (wall time, threads), which legitimately differs."""
    with open(path) as f:
        s = json.load(f)
    s.pop("run", None)
    return s


def assert_bit_identical_runs(scenario, work_dir, sets=(), threads=(1, 2)):
    """Runs `scenario` once per thread count and asserts every output file is bit-identical
    (summary.json: everything but its "run" block). Returns the list of compared files."""
    dirs = []
    # crater runs loops shorter than 2048 entities on one thread (src/parallel/parallel.hpp);
    # 0 makes every loop of these small cases parallel, which is what is being tested.
    old = os.environ.get("CRATER_PARALLEL_MIN")
    os.environ["CRATER_PARALLEL_MIN"] = "0"
    try:
        for n in threads:
            d = Path(work_dir) / f"threads{n}"
            # Checkpoints by wall-clock time (output.checkpoint_every_s) come when a run is
            # slow, e.g. beside other tests: off, so that both runs write the same files.
            run_scenario(scenario, d, threads=n, sets=["output.checkpoint_every_s=0", *sets])
            dirs.append(d)
    finally:
        if old is None:
            del os.environ["CRATER_PARALLEL_MIN"]
        else:
            os.environ["CRATER_PARALLEL_MIN"] = old
    ref = dirs[0]
    names = sorted(p.name for p in ref.iterdir() if p.is_file())
    if not any(n.endswith(".vtu") for n in names):
        raise AssertionError(f"{scenario}: no VTU output to compare in {ref}")
    for other in dirs[1:]:
        other_names = sorted(p.name for p in other.iterdir() if p.is_file())
        if names != other_names:
            raise AssertionError(f"different file sets: {names} vs {other_names}")
        for n in names:
            a, b = ref / n, other / n
            if n == COMMAND_FILE:
                continue  # how each run was started (--threads, --out): differs by design
            if n == "summary.json":
                if summary_without_run_block(a) != summary_without_run_block(b):
                    raise AssertionError(f"{n} differs between {ref.name} and {other.name}")
            elif not filecmp.cmp(a, b, shallow=False):
                raise AssertionError(f"{n} differs between {ref.name} and {other.name}")
    return names


def assert_restart_identical(scenario, full, checkpoint, sets=()):
    """Restarts `scenario` from `checkpoint` (a file in full/checkpoints) in a copy of the run
    directory `full`, with the --set overrides `sets` of the run that wrote it, and asserts
    that every file it writes is bit-identical to full's (summary.json: all but its "run"
    block)."""
    import shutil
    full = Path(full)
    again = full.parent / (full.name + "_again")
    if again.exists():
        shutil.rmtree(again)
    shutil.copytree(full, again)
    (again / "summary.json").unlink()
    crater("run", scenario, "--restart", again / "checkpoints" / Path(checkpoint).name, "--quiet",
           *[a for x in sets for a in ("--set", x)])
    for f in sorted(full.iterdir()):
        # The command file records the restart's own command line (a later --resume takes it).
        if f.is_file() and f.name not in ("summary.json", COMMAND_FILE):
            if f.read_bytes() != (again / f.name).read_bytes():
                raise AssertionError(f"from {Path(checkpoint).name}: {f.name} differs")
    if summary_without_run_block(full / "summary.json") != \
            summary_without_run_block(again / "summary.json"):
        raise AssertionError(f"from {Path(checkpoint).name}: summary.json differs")


def read_grid(path):
    """A .vtu, or a .pvtu with its pieces merged (output.pieces = "ranks"), read with VTK's own
    XML reader: the vtkUnstructuredGrid."""
    from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader

    parallel = str(path).endswith(".pvtu")
    reader = vtkXMLPUnstructuredGridReader() if parallel else vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    if reader.GetErrorCode() != 0:
        raise AssertionError(f"VTK could not read {path}")
    return reader.GetOutput()


def grid_arrays(data):
    """A vtkPointData or vtkCellData as {name: numpy array}."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i))
            for i in range(data.GetNumberOfArrays())}


def grid_cells(grid):
    """Each cell's point indices, a list per cell."""
    cells = []
    for c in range(grid.GetNumberOfCells()):
        ids = grid.GetCell(c).GetPointIds()
        cells.append([ids.GetId(k) for k in range(ids.GetNumberOfIds())])
    return cells


def read_vtu(path):
    """Reads a .vtu with VTK's own XML reader; returns (points Nx3, {name: array}, n_cells)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    grid = read_grid(path)
    pts = vtk_to_numpy(grid.GetPoints().GetData()) if grid.GetPoints() else None
    arrays = grid_arrays(grid.GetPointData())
    fd = grid.GetFieldData()
    time = None
    if fd.GetArray("TimeValue") is not None:
        time = float(fd.GetArray("TimeValue").GetValue(0))
    return pts, arrays, grid.GetNumberOfCells(), time


def read_vtu_cells(path):
    """Cell data of a .vtu read with VTK's own XML reader: {name: array}."""
    return grid_arrays(read_grid(path).GetCellData())


def read_pvtu(path):
    """A .pvtu (one piece per MPI rank, output.pieces = "ranks") read with VTK's own parallel XML
    reader, its pieces merged: (points Nx3, {name: point array}, {name: cell array}, cells),
    cells a list of each cell's point indices."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy

    grid = read_grid(path)
    pts = vtk_to_numpy(grid.GetPoints().GetData()) if grid.GetPoints() else np.zeros((0, 3))
    return (pts, grid_arrays(grid.GetPointData()), grid_arrays(grid.GetCellData()),
            grid_cells(grid))


def read_pvd(path):
    """Reads a .pvd (ParaView collection) with VTK's own XML parser; returns [(time, file)].
    VTK 9.1 has no PVD reader class (it is ParaView's); vtkXMLUtilities parses VTK XML files."""
    from vtkmodules.vtkIOXMLParser import vtkXMLUtilities

    root = vtkXMLUtilities.ReadElementFromFile(str(path))
    if root is None or root.GetName() != "VTKFile" or root.GetAttribute("type") != "Collection":
        raise AssertionError(f"{path} is not a VTK Collection file")
    coll = root.FindNestedElementWithName("Collection")
    if coll is None:
        raise AssertionError(f"{path} has no <Collection>")
    out = []
    for i in range(coll.GetNumberOfNestedElements()):
        e = coll.GetNestedElement(i)
        if e.GetName() == "DataSet":
            out.append((float(e.GetAttribute("timestep")), e.GetAttribute("file")))
    return out
