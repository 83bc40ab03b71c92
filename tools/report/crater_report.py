#!/usr/bin/env python3
"""crater report: figures and a one-page report.md for a run directory of `crater run`.

  crater report DIR [--out OUT] [--times T1,T2,...]
  /usr/bin/python3 tools/report/crater_report.py DIR [...]      (the same, from the source tree)

`crater report` carries this script inside the binary (CMake embeds it at build time) and runs
it with Debian's /usr/bin/python3, the interpreter python3-vtk9, python3-numpy and
python3-matplotlib load in.

DIR is a finished, failed or interrupted run directory: summary.json, <part>.pvd with its
<part>_NNNNNN.vtu frames (.pvtu over pieces/ when written in pieces on MPI ranks), history.csv,
and when the run wrote them <part>_failure.vtu and
surface_profile.csv. Written into OUT (default DIR/report/):
  snapshots_parts.png       all parts at the chosen output times, a colour per part;
  snapshots_velocity.png    ... coloured by speed;
  snapshots_pressure.png    ... by pressure (SPH and FEM; grains grey);
  snapshots_von_mises.png   ... by von Mises stress (FEM; the other parts grey);
  snapshots_damage.png      ... by damage (FEM parts with a damage model; the others grey);
  energy.png                the energy balance of history.csv (and the kinetic + internal
                            energy each part holds);
  von_mises_history.png     the <part>_max_von_mises_pa columns of history.csv, if any;
  surface_profile.png       the ground surface of surface_profile.csv, if present;
  lining.png                a tunnel lining's gauges (probes.lining) from history.csv, and the
                            soil along the crown line of crown_line.csv, if present;
  plate_from_below.png      3D: the FEM plate's underside over x-y by von Mises stress, eroded
                            elements hatched, at the last frame (and the one nearest
                            probes.stress_time_s), mirrored through the symmetry planes;
  crater_map.png            3D: the ground's height change dz over x-y, last frame vs t = 0,
                            from the grains, mirrored likewise;
  report.md                 the summary as tables (the parts with what left the domain and
                            what eroded; flags such as a crater at the bottom of the box),
                            linking the figures.
Snapshots show up to four output times spread evenly from the first to the last (the state at
failure of a failed run counts as the last), or the frames nearest to --times (seconds).
Particles are drawn as discs of their own size (DEM: the grain radius; SPH: the disc whose area
is mass/density), FEM elements as filled polygons; eroded elements are hidden. 3D runs show a
vertical section through the charge (the vertical axis: along gravity in the scenario file, else
z, as crater's probes take it): the FEM mesh cut by the plane, the particles within about a
particle layer of it. The 3D maps re-read the scenario file (crater-command.toml names it; its
--level and --set applied) for the symmetry planes, the domain and the probes; without it they
are not mirrored.

Exit codes: 0 done; 2 bad input (no run directory, no summary.json, no .pvd, bad --times);
1 missing Python modules or another error; 130 interrupted.
"""
import argparse
import csv
import json
import math
import os
import sys
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

EXIT_OK, EXIT_OTHER, EXIT_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130
DEBIAN_PACKAGES = "python3-vtk9 python3-numpy python3-matplotlib"

# The files this script writes; older copies of them in OUT are removed first, nothing else.
SNAPSHOT_FILES = {
    "parts": "snapshots_parts.png",
    "velocity": "snapshots_velocity.png",
    "pressure": "snapshots_pressure.png",
    "von_mises": "snapshots_von_mises.png",
    "damage": "snapshots_damage.png",
}
ENERGY_FILE = "energy.png"
VON_MISES_HISTORY_FILE = "von_mises_history.png"
SURFACE_FILE = "surface_profile.png"
LINING_FILE = "lining.png"
PLATE_FILE = "plate_from_below.png"
CRATER_MAP_FILE = "crater_map.png"
REPORT_FILE = "report.md"
OUR_FILES = [*SNAPSHOT_FILES.values(), ENERGY_FILE, VON_MISES_HISTORY_FILE, SURFACE_FILE,
             LINING_FILE, PLATE_FILE, CRATER_MAP_FILE, REPORT_FILE]

DEFAULT_SNAPSHOTS = 4
PLATE_CAPTION = (
    "Each element's bottom face projected on the horizontal plane, the lowest drawn over the "
    "others (what is seen from below; axes as in a plan view), by von Mises stress; eroded "
    "elements hatched, grey where no live element is left above them (a hole through the "
    "plate); mirrored through the scenario's symmetry planes.")
CRATER_CAPTION = (
    "The change of the ground's top since t = 0 per column (probes.surface_bin_m, else 8 x the "
    "largest grain radius): the top of the grains standing on the bed's bottom, up to the first "
    "gap of more than three grain diameters (the charge's and the plate's room at t = 0 make no "
    "gap), grains in flight left out (the probe's rules); a column emptied to the bottom is a "
    "hole. Read off the grains, not the probe's solid-volume surface: loosened ground shows as "
    "a rise. Mirrored through the scenario's symmetry planes.")
DPI = 100
# Parts without the plotted quantity are grey, a shade per method (products, grains, steel).
GREY = {"sph": "#dedee6", "dem": "#a6a6a6", "fem": "#707070"}
# The colours of the parts in snapshots_parts.png, by method, then in the parts' order.
PART_COLOURS = {"sph": ["#e0402a", "#f39c12", "#e377c2"], "dem": ["#c8a165", "#8c564b", "#bcbd22"],
                "fem": ["#2f5f9e", "#17becf", "#9467bd"]}


class InputError(Exception):
    """Bad input (exit 2): the message is one line naming the file or option."""


def warn(msg):
    print(f"crater report: warning: {msg}", file=sys.stderr)


# ---------------------------------------------------------------------------------------------
# The run directory (standard library only: bad input is reported before the heavy imports)
# ---------------------------------------------------------------------------------------------

class Part:
    """One part of the run: its name, method (sph, dem, fem) and frames [(time, Path)]."""

    def __init__(self, name, method, frames, failure):
        self.name, self.method, self.frames, self.failure = name, method, frames, failure


class Frame:
    """One snapshot time: {part name: .vtu path}; label is "" or "failure"."""

    def __init__(self, time, files, label=""):
        self.time, self.files, self.label = time, files, label


def load_summary(run_dir):
    path = run_dir / "summary.json"
    if not path.is_file():
        raise InputError(f"{run_dir}: no summary.json; not a run directory of `crater run`")
    try:
        summary = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise InputError(f"{path}: not readable as JSON ({e})") from None
    if not isinstance(summary, dict):
        raise InputError(f"{path}: not a JSON object")
    return summary


def read_pvd(path):
    """[(time, Path)] of a ParaView collection, sorted by time; [] if it cannot be read."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        warn(f"{path}: skipped, not a readable .pvd ({e})")
        return []
    frames = []
    for ds in root.iter("DataSet"):
        try:
            t = float(ds.get("timestep", "nan"))
        except ValueError:
            continue
        f = ds.get("file")
        if f and math.isfinite(t) and (path.parent / f).is_file():
            frames.append((t, path.parent / f))
    return sorted(frames, key=lambda x: x[0])


def find_parts(run_dir, summary):
    """The parts with a .pvd, in the summary's order (then any other .pvd of DIR)."""
    methods = {}
    for p in summary.get("parts") or []:
        if isinstance(p, dict) and isinstance(p.get("name"), str):
            methods[p["name"]] = str(p.get("method", ""))
    names = [n for n in methods if (run_dir / f"{n}.pvd").is_file()]
    names += sorted(p.stem for p in run_dir.glob("*.pvd") if p.stem not in methods)
    if not names:
        raise InputError(f"{run_dir}: no <part>.pvd output; the run wrote no frames")
    parts = []
    for n in names:
        frames = read_pvd(run_dir / f"{n}.pvd")
        failure = run_dir / f"{n}_failure.vtu"
        if not failure.is_file() and (run_dir / f"{n}_failure.pvtu").is_file():
            failure = run_dir / f"{n}_failure.pvtu"  # written in pieces on ranks
        if frames or failure.is_file():
            parts.append(Part(n, methods.get(n, ""), frames, failure if failure.is_file() else None))
    if not parts:
        raise InputError(f"{run_dir}: no .pvd lists an existing .vtu frame")
    return parts


def collect_frames(parts, summary):
    """Every output time of any part, each with the nearest frame of every part; the state at
    failure (<part>_failure.vtu, at summary.json's time_s) last."""
    times = sorted({t for p in parts for t, _ in p.frames})
    merged = []
    for t in times:  # parts share output times; merge those equal to rounding
        if merged and abs(t - merged[-1]) <= 1e-9 * max(abs(t), 1e-300):
            continue
        merged.append(t)
    frames = []
    for t in merged:
        files = {}
        for p in parts:
            if p.frames:
                tp, f = min(p.frames, key=lambda x: abs(x[0] - t))
                if abs(tp - t) <= 1e-9 * max(abs(t), 1e-300):
                    files[p.name] = f
        frames.append(Frame(t, files))
    if any(p.failure for p in parts):
        t_fail = as_float(summary.get("time_s"))
        if t_fail is None:
            t_fail = merged[-1] if merged else 0.0
        files = {p.name: p.failure for p in parts if p.failure}
        frames.append(Frame(t_fail, files, "failure"))
    return frames


def select_frames(frames, times_option):
    if times_option is None:
        n = len(frames)
        if n <= DEFAULT_SNAPSHOTS:
            return list(frames)
        picks = sorted({round(i * (n - 1) / (DEFAULT_SNAPSHOTS - 1))
                        for i in range(DEFAULT_SNAPSHOTS)})
        return [frames[i] for i in picks]
    wanted = []
    for item in times_option.split(","):
        try:
            t = float(item)
        except ValueError:
            raise InputError(f"--times: '{item}' is not a time in seconds "
                             "(give e.g. --times 0.0006,0.002)") from None
        if not math.isfinite(t):
            raise InputError(f"--times: '{item}' is not a finite time in seconds")
        wanted.append(t)
    picks = sorted({min(range(len(frames)), key=lambda i: abs(frames[i].time - t))
                    for t in wanted})
    return [frames[i] for i in picks]


def read_csv_columns(path):
    """{column: [float]} of a CSV file with a header row (non-numbers read as nan); None if the
    file is absent, {} if it cannot be read."""
    if not path.is_file():
        return None
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        warn(f"{path}: skipped ({e})")
        return {}
    if len(rows) < 2:
        return {}
    header = [h.strip() for h in rows[0]]
    cols = {h: [] for h in header}
    for row in rows[1:]:
        if len(row) != len(header):
            continue  # a row cut short by an interrupted run
        for h, v in zip(header, row):
            try:
                cols[h].append(float(v))
            except ValueError:
                cols[h].append(float("nan"))
    return cols


def as_float(v):
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None
    return float(v)


# ---------------------------------------------------------------------------------------------
# Frames read with VTK
# ---------------------------------------------------------------------------------------------

class PartState:
    """One part at one frame, reduced to what is drawn in the plotted plane.

    particles: xy (N x 2) and diameter (N) of discs; or polygons: list of (K x 2) vertex
    arrays. values: {quantity: array per disc or polygon, in plot units}.
    """

    def __init__(self, name, method):
        self.name, self.method = name, method
        self.xy = None
        self.diameter = None
        self.polygons = None
        self.values = {}


def vtk_arrays(data):
    return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i))
            for i in range(data.GetNumberOfArrays()) if data.GetArray(i) is not None}


def read_grid(path):
    # A frame written in pieces on MPI ranks (output.pieces = "ranks") is a .pvtu over them.
    reader = (vtkXMLPUnstructuredGridReader() if str(path).endswith(".pvtu")
              else vtkXMLUnstructuredGridReader())
    reader.SetFileName(str(path))
    reader.Update()
    if reader.GetErrorCode() != 0:
        return None
    grid = reader.GetOutput()
    if grid is None or grid.GetPoints() is None:
        return None
    return grid


AXES = "xyz"


class Plane:
    """What the snapshots show: the plane of a horizontal axis h and the vertical axis v; in 3D
    the section at c0 along the third axis n."""

    def __init__(self, vertical=1, normal=None, c0=0.0):
        self.v, self.n, self.c0 = vertical, normal, c0
        self.h = next(a for a in range(3) if a not in (vertical, normal))

    def cols(self):
        return [self.h, self.v]

    def label(self):
        return "" if self.n is None else f"section {AXES[self.n]} = {self.c0:.3g} m"


def load_scenario(summary, run_dir):
    """The run's scenario as a dict, with its --level and --set applied (the file named by
    DIR/crater-command.toml, else by summary.json); None, with a warning, when it cannot be
    read (a bundled scenario, a file moved or edited since: the figures that need it do
    without). Only what the figures read is trusted: gravity, the domain, its symmetry planes,
    probes, detonation points."""
    cmd = {}
    try:
        import tomllib
    except ImportError:
        return None
    try:
        with open(run_dir / "crater-command.toml", "rb") as f:
            cmd = tomllib.load(f)
    except (OSError, ValueError):
        run = summary.get("run") if isinstance(summary.get("run"), dict) else {}
        c = run.get("command") if isinstance(run.get("command"), dict) else {}
        cmd = {"level": c.get("level", ""), "set": c.get("set", [])}
    sc = summary.get("scenario") if isinstance(summary.get("scenario"), dict) else {}
    names = [cmd.get("scenario_file"), sc.get("file")]
    paths = [Path(n) for n in names if isinstance(n, str) and n]
    paths += [run_dir.parent / n for n in names if isinstance(n, str) and n]
    path = next((q for q in paths if q.is_file()), None)
    if path is None:
        return None
    try:
        with open(path, "rb") as f:
            table = tomllib.load(f)
        sets = []
        level = cmd.get("level") if isinstance(cmd.get("level"), str) else ""
        for name in filter(None, level.split(",")):
            sets += table.get("levels", {}).get(name.strip(), {}).get("set", [])
        sets += cmd.get("set") if isinstance(cmd.get("set"), list) else []
        for item in sets:
            apply_set(table, str(item))
    except (OSError, ValueError, TypeError, KeyError, AttributeError) as e:
        warn(f"{path}: not read as the run's scenario ({e}); 3D maps not mirrored")
        return None
    return table


def apply_set(table, item):
    """One `--set dotted.key=VALUE` on the scenario dict (an array of tables is indexed by its
    entries' names, as crater does: parts.plate.spacing_m)."""
    import tomllib
    key, value = item.split("=", 1)
    value = tomllib.loads(f"v = {value.strip()}")["v"]
    keys = [k.strip() for k in key.split(".")]
    node = table
    for i, k in enumerate(keys):
        if isinstance(node, list):
            j = next((n for n, x in enumerate(node)
                      if isinstance(x, dict) and x.get("name") == k), None)
            if j is None and k.isdigit() and int(k) < len(node):
                j = int(k)
            if j is None:
                return
            k = j
        elif not isinstance(node, dict):
            return
        if i == len(keys) - 1:
            node[k] = value
        else:
            node = node.setdefault(k, {}) if isinstance(node, dict) else node[k]


def vertical_axis_3d(scenario):
    """The vertical axis of a 3D run: the one gravity points along in the scenario file (when it
    can still be read), else z, as crater's probes take it (surface_profile.csv: x_m, y_m)."""
    g = (scenario or {}).get("domain", {}).get("gravity_m_s2")
    try:
        if isinstance(g, list) and len(g) == 3 and any(g):
            return max(range(3), key=lambda a: abs(float(g[a])))
    except (TypeError, ValueError):
        pass
    return 2


def cell_polygons(points, cells, cols):
    """Vertex arrays (in the plotted axes cols) of a vtkCellArray's cells."""
    conn = vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64)
    offs = vtk_to_numpy(cells.GetOffsetsArray()).astype(np.int64)
    sizes = np.diff(offs)
    if len(sizes) and np.all(sizes == sizes[0]):
        return list(points[conn.reshape(-1, sizes[0])][:, :, cols])
    return [points[conn[a:b]][:, cols] for a, b in zip(offs[:-1], offs[1:])]


def speed(v):
    v = np.asarray(v, dtype=float)
    return np.linalg.norm(v, axis=1) if v.ndim == 2 else np.abs(v)


def particle_state(grid, name, method, plane):
    st = PartState(name, method)
    pts = vtk_to_numpy(grid.GetPoints().GetData()).astype(float)
    arr = vtk_arrays(grid.GetPointData())
    n = len(pts)
    dimension = 2 if plane.n is None else 3
    if method == "dem" and "radius" in arr:
        d = 2.0 * np.asarray(arr["radius"], dtype=float)
    elif "mass" in arr and "density" in arr:
        with np.errstate(divide="ignore", invalid="ignore"):
            vol = np.asarray(arr["mass"], float) / np.asarray(arr["density"], float)
        # the disc of the particle's area (2D), the sphere of its volume (3D)
        d = (np.sqrt(4.0 * vol / math.pi) if dimension == 2
             else np.cbrt(6.0 * vol / math.pi))
        d = np.where(np.isfinite(d) & (d > 0), d, np.nan)
        if np.any(np.isfinite(d)):
            # expanded gas would cover everything: at most 2.5x the dense particles' size
            cap = 2.5 * np.nanpercentile(d, 20)
            d = np.where(np.isfinite(d), np.minimum(d, cap), cap)
        else:
            d = None
    else:
        d = None
    if d is None:  # no size in the file: the spacing of n particles over their bounding box
        ext = np.ptp(pts[:, :dimension], axis=0) if n else np.ones(dimension)
        ext = np.where(ext > 0, ext, ext.max() if ext.max() > 0 else 1.0)
        d = np.full(n, float(np.prod(ext) / max(n, 1)) ** (1.0 / dimension))
    keep = np.ones(n, dtype=bool)
    if plane.n is not None and n:
        # the section: a slab about one particle layer thick (the particles' size, or the
        # part's mean spacing where that is larger, as in a loose lattice of grains; 1.2 of
        # it, lest a lattice put its layers just outside)
        ext = np.maximum(np.ptp(pts, axis=0), 1e-12)
        spacing = float(np.prod(ext) / n) ** (1.0 / 3.0)
        keep = np.abs(pts[:, plane.n] - plane.c0) <= 0.6 * np.maximum(d, spacing)
    keep &= np.all(np.isfinite(pts), axis=1)  # a failed run's last state may hold inf or nan
    st.xy = pts[keep][:, plane.cols()]
    st.diameter = d[keep]
    if "velocity" in arr:
        st.values["velocity"] = speed(arr["velocity"])[keep]
    if method != "dem" and "pressure" in arr:
        st.values["pressure"] = np.asarray(arr["pressure"], float)[keep] / 1e6
    return st


def fem_state(grid, name, plane):
    st = PartState(name, "fem")
    if plane.n is not None:
        # the section: the mesh cut by the plane (cell data pass through)
        normal = [0.0, 0.0, 0.0]
        normal[plane.n] = 1.0
        cut_plane = vtkPlane()
        cut_plane.SetOrigin(*[plane.c0 * c for c in normal])
        cut_plane.SetNormal(*normal)
        cutter = vtkCutter()
        cutter.SetCutFunction(cut_plane)
        cutter.SetInputData(grid)
        cutter.Update()
        cut = cutter.GetOutput()
        if cut.GetNumberOfPoints() == 0:
            st.polygons = []
            return st
        pts = vtk_to_numpy(cut.GetPoints().GetData()).astype(float)
        cells = cut.GetPolys()
        point_arrays, cell_arrays = vtk_arrays(cut.GetPointData()), vtk_arrays(cut.GetCellData())
    else:
        pts = vtk_to_numpy(grid.GetPoints().GetData()).astype(float)
        cells = grid.GetCells()
        point_arrays, cell_arrays = vtk_arrays(grid.GetPointData()), vtk_arrays(grid.GetCellData())
    conn = vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64)
    offs = vtk_to_numpy(cells.GetOffsetsArray()).astype(np.int64)
    polygons = cell_polygons(pts, cells, plane.cols())
    keep = np.array([np.all(np.isfinite(p)) for p in polygons], dtype=bool)
    if "eroded" in cell_arrays and len(cell_arrays["eroded"]) == len(polygons):
        keep &= np.asarray(cell_arrays["eroded"], float) < 0.5
    st.polygons = [p for p, k in zip(polygons, keep) if k]
    if "velocity" in point_arrays:
        # an element's speed: the mean of its nodes'
        node_speed = speed(point_arrays["velocity"])
        sums = np.add.reduceat(node_speed[conn], offs[:-1]) if len(conn) else np.zeros(0)
        st.values["velocity"] = (sums / np.diff(offs))[keep]
    for key in ("pressure", "von_mises"):
        if key in cell_arrays and len(cell_arrays[key]) == len(polygons):
            st.values[key] = np.asarray(cell_arrays[key], float)[keep] / 1e6
    if "damage" in cell_arrays and len(cell_arrays["damage"]) == len(polygons):
        st.values["damage"] = np.asarray(cell_arrays["damage"], float)[keep]
    return st


def section_plane(parts, frame, vertical):
    """The vertical section of a 3D run: through the charge's centre (the first SPH part's mean),
    else through the middle of all points, normal to the horizontal axis other than x."""
    normal = 1 if vertical != 1 else 2
    cs = []
    for p in parts:
        f = frame.files.get(p.name)
        grid = read_grid(f) if f else None
        if grid is None:
            continue
        c = vtk_to_numpy(grid.GetPoints().GetData())[:, normal]
        if len(c) and p.method == "sph":
            return Plane(vertical, normal, float(np.mean(c)))
        if len(c):
            cs += [float(c.min()), float(c.max())]
    return Plane(vertical, normal, 0.5 * (min(cs) + max(cs)) if cs else 0.0)


def load_states(parts, frame, plane):
    states = []
    for p in parts:
        f = frame.files.get(p.name)
        if f is None:
            continue
        grid = read_grid(f)
        if grid is None:
            warn(f"{f}: skipped, VTK could not read it")
            continue
        method = p.method or guess_method(grid)
        if method == "fem":
            states.append(fem_state(grid, p.name, plane))
        else:
            states.append(particle_state(grid, p.name, method, plane))
    return states


def guess_method(grid):
    """The method of a part summary.json does not name, from what its file holds."""
    if grid.GetCellData().GetArray("von_mises") is not None:
        return "fem"
    return "dem" if grid.GetPointData().GetArray("radius") is not None else "sph"


# ---------------------------------------------------------------------------------------------
# Figures
# ---------------------------------------------------------------------------------------------

QUANTITIES = {
    # key: (title, colour bar label, colour map); "parts": a colour per part, no colour bar
    "parts": ("parts", None, None),
    "velocity": ("speed", "speed [m/s]", "viridis"),
    "pressure": ("pressure", "pressure [MPa]", "inferno"),
    "von_mises": ("von Mises stress", "von Mises stress [MPa]", "plasma"),
    "damage": ("damage", "damage D (1: failed)", "YlOrRd"),
}
# The tunnel lining's gauges (probes.lining) in history.csv, and the soil's on the crown line.
LINING_GAUGES = [("lining_crown_radial_m", "crown", "tab:red"),
                 ("lining_springline_radial_m", "springline", "tab:blue"),
                 ("lining_invert_radial_m", "invert", "tab:green")]
CROWN_LINE_GAUGES = [("soil_crown_line_interface_up_m", "soil above the crown: at the lining"),
                     ("soil_crown_line_surface_up_m", "soil above the crown: at the ground")]
LINING_CAPTION = (
    "Left: the radial displacement of the lining's inner wall at the gauges of probes.lining "
    "(outward positive), and the upward displacement of the soil on the crown line at the "
    "lining and at the ground (probes.lining_soil). Right, with probes.lining_soil: the soil's "
    "upward displacement along the crown line, its largest over the run and at the end "
    "(crown_line.csv).")


def state_extent(st):
    """(xmin, xmax, ymin, ymax) of a part's drawing; a few stray SPH particles (0.1 % on each
    side) left out."""
    if st.polygons:
        allv = np.concatenate(st.polygons)
        return allv[:, 0].min(), allv[:, 0].max(), allv[:, 1].min(), allv[:, 1].max()
    if st.xy is not None and len(st.xy):
        xy, r = st.xy, 0.5 * np.nanmax(st.diameter)
        if st.method == "sph" and len(xy) > 1000:
            lo, hi = np.percentile(xy, [0.1, 99.9], axis=0)
        else:
            lo, hi = xy.min(axis=0), xy.max(axis=0)
        return lo[0] - r, hi[0] + r, lo[1] - r, hi[1] + r
    return None


def domain_box(scenario, plane):
    """The scenario's [domain] box in the drawing's axes, or None (unknown or unbounded)."""
    dom = (scenario or {}).get("domain") if isinstance(scenario, dict) else None
    if not isinstance(dom, dict):
        return None
    lo, hi = dom.get("min_m"), dom.get("max_m")
    if not (isinstance(lo, list) and isinstance(hi, list)):
        return None
    h, v = plane.cols()
    try:
        return float(lo[h]), float(hi[h]), float(lo[v]), float(hi[v])
    except (IndexError, TypeError, ValueError):
        return None


def outside_view(states, view):
    """How many particles (by centre) and elements (by centroid) of these states lie outside
    the view."""
    x0, x1, y0, y1 = view
    n = 0
    for st in states:
        pts = []
        if st.polygons:
            pts = [poly.mean(axis=0) for poly in st.polygons]
        elif st.xy is not None and len(st.xy):
            pts = st.xy
        for x, y in pts:
            n += not (x0 <= x <= x1 and y0 <= y <= y1)
    return n


def view_note(all_states, frames, view, dom):
    """The caption that says what the view leaves out, if anything."""
    counts = [(f, outside_view(states, view)) for f, states in zip(frames, all_states)]
    cut = [(f, n) for f, n in counts if n]
    if not cut:
        return ""
    x0, x1, y0, y1 = view
    where = ", ".join(f"{n} at {fmt_ms(f.time)}" for f, n in cut)
    return (f"The view is x from {x0:.3g} to {x1:.3g} m and y from {y0:.3g} to {y1:.3g} m"
            + (" (the domain, cut at about the first panel's size beyond the parts)" if dom else "")
            + f"; particles and elements outside it are not drawn: {where}.")


def view_box(all_states, dom=None):
    """One view for every panel: what the parts cover at the chosen times, inside the domain
    (dom, when known: fragments of an FEM part, which the domain does not hold, do not stretch
    it), at most the first panel's size beyond it on each side."""
    def union(states):
        boxes = [b for b in (state_extent(s) for s in states) if b is not None]
        if not boxes:
            return None
        b = np.array(boxes, dtype=float)
        return b[:, 0].min(), b[:, 1].max(), b[:, 2].min(), b[:, 3].max()

    first = union(all_states[0]) if all_states else None
    total = union([s for states in all_states for s in states])
    if total is None:
        return (-1.0, 1.0, -1.0, 1.0)
    if dom is not None and all(math.isfinite(v) for v in dom):
        total = (max(total[0], dom[0]), min(total[1], dom[1]),
                 max(total[2], dom[2]), min(total[3], dom[3]))
        if total[0] >= total[1] or total[2] >= total[3]:
            total = dom
    if first is not None:
        w, h = first[1] - first[0], first[3] - first[2]
        total = (max(total[0], first[0] - w), min(total[1], first[1] + w),
                 max(total[2], first[2] - h), min(total[3], first[3] + h))
    x0, x1, y0, y1 = total
    size = max(x1 - x0, y1 - y0, 1e-12)
    w, h = max(x1 - x0, 0.05 * size), max(y1 - y0, 0.05 * size)
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    return (cx - 0.53 * w, cx + 0.53 * w, cy - 0.53 * h, cy + 0.53 * h)


def colour_range(states, key):
    vals = [s.values[key] for s in states if key in s.values and len(s.values[key])]
    if not vals:
        return None
    v = np.concatenate(vals)
    v = v[np.isfinite(v)]
    if not len(v):
        return None
    if key == "damage":
        return 0.0, 1.0
    # the extremes of a few elements or particles would wash out everything else
    lo, hi = np.percentile(v, [0.5, 99.5])
    if key != "pressure":
        lo = 0.0
    elif lo > 0:
        lo = 0.0
    if hi <= lo:
        hi = lo + max(abs(lo), 1.0) * 1e-3
    return lo, hi


def part_colours(parts):
    """{part name: colour} for snapshots_parts.png."""
    used = {}
    colours = {}
    for p in parts:
        palette = PART_COLOURS.get(p.method, PART_COLOURS["dem"])
        i = used.get(p.method, 0)
        used[p.method] = i + 1
        colours[p.name] = palette[i % len(palette)]
    return colours


def draw_states(ax, states, key, cmap, norm, colours):
    # gas at the bottom, grains above it, the plate on top
    order = {"sph": 0, "dem": 1, "fem": 2}
    for st in sorted(states, key=lambda s: order.get(s.method, 1)):
        vals = st.values.get(key)
        flat = colours.get(st.name, "k") if key == "parts" else GREY.get(st.method, GREY["dem"])
        if st.polygons is not None:
            if not st.polygons:
                continue
            coll = PolyCollection(st.polygons, linewidths=0.3)
        else:
            if not len(st.xy):
                continue
            coll = EllipseCollection(st.diameter, st.diameter, np.zeros(len(st.xy)), units="xy",
                                     offsets=st.xy, offset_transform=ax.transData,
                                     linewidths=0)
        if vals is not None:
            coll.set_array(vals)
            coll.set_cmap(cmap)
            coll.set_norm(norm)
            coll.set_edgecolor("face")
        else:
            coll.set_facecolor(flat)
            coll.set_edgecolor(flat)
        ax.add_collection(coll)


def snapshot_figure(path, key, frames, all_states, view, colours, title, plane):
    label, bar_label, cmap_name = QUANTITIES[key]
    n = len(frames)
    ncols = 1 if n == 1 else 2
    nrows = (n + ncols - 1) // ncols
    x0, x1, y0, y1 = view
    panel_w = 5.6 if ncols == 2 else 7.0
    panel_h = min(max(panel_w * (y1 - y0) / (x1 - x0), 2.2), 7.5)
    fig, axes = plt.subplots(nrows, ncols, figsize=(ncols * (panel_w + 1.2), nrows * panel_h + 0.6),
                             squeeze=False, constrained_layout=True)
    cmap = plt.get_cmap(cmap_name) if cmap_name else None
    for i, ax in enumerate(axes.flat):
        if i >= n:
            ax.set_visible(False)
            continue
        frame, states = frames[i], all_states[i]
        rng = colour_range(states, key) if cmap else None
        norm = Normalize(*(rng or (0.0, 1.0)))
        draw_states(ax, states, key, cmap, norm, colours)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal")
        ax.set_xlabel(f"{AXES[plane.h]} [m]")
        ax.set_ylabel(f"{AXES[plane.v]} [m]")
        when = f"t = {frame.time * 1e3:.4g} ms"
        ax.set_title(when + (" (state at failure)" if frame.label == "failure" else ""))
        if cmap:
            bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.9)
            bar.set_label(bar_label)
        elif i == 0:
            shown = [s for s in states]
            handles = [Patch(color=colours.get(s.name, "k"), label=f"{s.name} ({s.method})")
                       for s in shown]
            ax.legend(handles=handles, fontsize=8, loc="upper right", framealpha=0.9)
    fig.suptitle(f"{title}: {label}" + (f" ({plane.label()})" if plane.n is not None else ""))
    save_png(fig, path)


def save_png(fig, path):
    """Writes the figure as a palette PNG (256 colours: a third of the size of full colour)."""
    fig.set_dpi(DPI)
    fig.canvas.draw()
    rgba = np.asarray(fig.canvas.buffer_rgba())
    plt.close(fig)
    try:
        from PIL import Image
    except ImportError:  # python3-pil comes with python3-matplotlib; without it, full colour
        plt.imsave(path, rgba)
        return
    image = Image.fromarray(rgba[:, :, :3])
    image.quantize(256, method=Image.Quantize.FASTOCTREE).save(path, compress_level=9)


def energy_unit(values):
    m = max((abs(v) for v in values if math.isfinite(v)), default=0.0)
    for scale, unit in ((1e12, "TJ"), (1e9, "GJ"), (1e6, "MJ"), (1e3, "kJ")):
        if m >= scale:
            return scale, unit
    return 1.0, "J"


# history.csv's energy terms: (column, label, colour, line width, style)
ENERGY_TERMS = [("kinetic_j", "kinetic", "tab:blue", 1.6, "-"),
                ("internal_j", "internal", "tab:orange", 1.6, "-"),
                ("total_j", "total", "black", 2.2, "-"),
                ("external_work_j", "external work", "tab:green", 1.0, "--"),
                ("damping_j", "damping", "tab:purple", 1.0, "--"),
                ("hourglass_j", "hourglass", "tab:gray", 1.0, "--"),
                ("contact_j", "contact", "tab:brown", 1.0, "--"),
                ("eroded_j", "eroded", "tab:pink", 1.0, "--")]


def energy_figure(path, hist, title):
    """The energy balance (its terms, and the error on a second axis) and, for runs of several
    parts, how much each part's own total energy changed since the start."""
    t = np.array(hist["time_s"]) * 1e3
    per_part = [c for c in hist if c.startswith("energy_") and c.endswith("_j")]
    fig, axes = plt.subplots(1, 2 if per_part else 1, figsize=(12 if per_part else 7.5, 4.5),
                             squeeze=False, constrained_layout=True)
    ax = axes[0][0]
    # the three main terms always, the others when they are not zero throughout
    terms = [e for e in ENERGY_TERMS if e[0] in hist and (
        e[0] in ("kinetic_j", "internal_j", "total_j") or np.nanmax(np.abs(hist[e[0]])) > 0)]
    scale, unit = energy_unit([v for e in terms for v in hist[e[0]]])
    for col, label, colour, lw, ls in terms:
        ax.plot(t, np.array(hist[col]) / scale, color=colour, lw=lw, ls=ls, label=label)
    ax.set_xlabel("time [ms]")
    ax.set_ylabel(f"energy [{unit}]")
    ax.grid(alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if "energy_error" in hist:
        ax2 = ax.twinx()
        ax2.plot(t, np.array(hist["energy_error"]) * 100.0, color="tab:red", lw=1.2, ls=":",
                 label="energy error")
        ax2.set_ylabel("energy error [%]", color="tab:red")
        ax2.tick_params(axis="y", colors="tab:red")
        h2, l2 = ax2.get_legend_handles_labels()
        handles, labels = handles + h2, labels + l2
    ax.legend(handles, labels, fontsize=8, loc="best")
    ax.set_title("energy balance")
    if per_part:
        ax = axes[0][1]
        names = [c[len("energy_"):-2] for c in per_part]
        held = all(f"kinetic_{n}_j" in hist and f"internal_{n}_j" in hist for n in names)
        if held:
            # What each part holds, kinetic + internal: the charge's energy leaving it. (Each
            # part's total also books its contact work, so the charge's stays near its start.)
            series = {n: np.array(hist[f"kinetic_{n}_j"]) + np.array(hist[f"internal_{n}_j"])
                      for n in names}
        else:  # a run of an older crater: the totals, said to be such
            series = {n: np.array(hist[f"energy_{n}_j"]) for n in names}
        scale, unit = energy_unit([v for d in series.values() for v in d])
        for n in names:
            ax.plot(t, series[n] / scale, lw=1.6, label=n)
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.set_xlabel("time [ms]")
        ax.set_ylabel(f"energy [{unit}]")
        ax.grid(alpha=0.3)
        ax.legend(title="part", fontsize=8)
        ax.set_title("kinetic + internal energy each part holds" if held else
                     "each part's total energy, its contact work included (energy_<part>_j)")
    fig.suptitle(title)
    save_png(fig, path)


def von_mises_history_figure(path, hist, columns, title):
    t = np.array(hist["time_s"]) * 1e3
    fig, ax = plt.subplots(figsize=(7.5, 4.5), constrained_layout=True)
    for c in columns:
        ax.plot(t, np.array(hist[c]) / 1e6, lw=1.6, label=c[:-len("_max_von_mises_pa")])
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("peak von Mises stress [MPa]")
    ax.grid(alpha=0.3)
    ax.legend(title="part", fontsize=8)
    ax.set_title(f"{title}: peak von Mises stress over the plate")
    save_png(fig, path)


def lining_figure(path, hist, line, title):
    """The lining's gauges over time (and the soil's on the crown line); with crown_line.csv,
    the soil's displacement along the crown line."""
    t = np.array(hist["time_s"]) * 1e3
    profile = line is not None and {"above_crown_m", "up_displacement_max_m",
                                     "up_displacement_m"} <= line.keys() and line["above_crown_m"]
    fig, axes = plt.subplots(1, 2 if profile else 1, figsize=(12 if profile else 7.5, 4.5),
                             squeeze=False, constrained_layout=True)
    ax = axes[0][0]
    for col, label, colour in LINING_GAUGES:
        if col in hist:
            ax.plot(t, np.array(hist[col]) * 100, color=colour, lw=1.6, label=label)
    for (col, label), ls in zip(CROWN_LINE_GAUGES, ("--", ":")):
        if col in hist:
            ax.plot(t, np.array(hist[col]) * 100, color="0.35", lw=1.3, ls=ls, label=label)
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("displacement [cm]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("lining: radial displacement of the inner wall")
    if profile:
        ax = axes[0][1]
        h = np.array(line["above_crown_m"])
        ax.plot(np.array(line["up_displacement_max_m"]) * 100, h, "o-", color="tab:red", lw=1.4,
                ms=3, label="largest over the run")
        ax.plot(np.array(line["up_displacement_m"]) * 100, h, "s--", color="0.35", lw=1.2, ms=3,
                label="at the end")
        ax.axvline(0.0, color="0.6", lw=0.8)
        ax.set_xlabel("upward displacement [cm]")
        ax.set_ylabel("height above the crown [m]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title("soil on the crown line (crown_line.csv)")
    fig.suptitle(title)
    save_png(fig, path)


def surface_figure(path, prof, title, end_time_s):
    """surface_profile.csv: the ground's vertical displacement at the end, with the surface
    heights at t = 0 and at the end when the file has them: per column along x (2D), or per
    ring against the distance r from the crater's axis (3D: r_m, dz_m); a file of an earlier
    3D run (a row per column, x_m and y_m) as a map over x and y."""
    radial = "r_m" in prof
    x = np.array(prof["r_m" if radial else "x_m"])
    d = np.array(prof["dz_m" if radial else "vertical_displacement_m"])
    finite = np.isfinite(d)
    big = bool(np.any(finite)) and np.nanmax(np.abs(d)) >= 0.1
    scale, unit = (1.0, "m") if big else (1e3, "mm")
    when = f" at t = {end_time_s * 1e3:.4g} ms" if end_time_s is not None else ""
    if "y_m" in prof:  # 3D: one row per column of an x-y grid
        y = np.array(prof["y_m"])
        fig, ax = plt.subplots(figsize=(7.5, 6.0), constrained_layout=True)
        lim = float(np.nanmax(np.abs(d[finite]))) * scale if np.any(finite) else 0.0
        lim = lim if lim > 0 else 1.0  # a flat ground: +-1 mm

        def pitch(c):
            u = np.unique(c)
            return float(np.diff(u).min()) if len(u) > 1 else 1.0

        wx, wy = pitch(x), pitch(y)
        boxes = [np.array([[xi - wx / 2, yi - wy / 2], [xi + wx / 2, yi - wy / 2],
                           [xi + wx / 2, yi + wy / 2], [xi - wx / 2, yi + wy / 2]])
                 for xi, yi in zip(x[finite], y[finite])]
        coll = PolyCollection(boxes, array=d[finite] * scale, cmap="coolwarm_r",
                              norm=Normalize(-lim, lim), edgecolors="face")
        ax.add_collection(coll)
        ax.set_xlim(x.min() - wx, x.max() + wx)
        ax.set_ylim(y.min() - wy, y.max() + wy)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        fig.colorbar(coll, ax=ax, shrink=0.85).set_label(f"vertical displacement [{unit}]")
        ax.set_title(f"{title}: ground surface{when}")
        save_png(fig, path)
        return
    heights = "surface_initial_m" in prof and "surface_m" in prof
    fig, axes = plt.subplots(2 if heights else 1, 1, figsize=(7.5, 6.5 if heights else 4.0),
                             sharex=True, squeeze=False, constrained_layout=True)
    marker = "." if len(x) < 60 else None
    ax = axes[-1][0]
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.plot(x, d * scale, lw=1.8, marker=marker)
    ax.set_xlabel("distance from the crater's axis r [m]" if radial else "x [m]")
    ax.set_ylabel(f"vertical displacement [{unit}]")
    ax.grid(alpha=0.3)
    if heights:
        top = axes[0][0]
        top.plot(x, np.array(prof["surface_initial_m"]), color="0.5", lw=1.4, ls="--",
                 marker=marker, label="t = 0")
        top.plot(x, np.array(prof["surface_m"]), color="tab:brown", lw=1.8, marker=marker,
                 label=when.strip()[3:] or "end")
        top.set_ylabel("surface height [m]")
        top.grid(alpha=0.3)
        top.legend(fontsize=8)
    axes[0][0].set_title(f"{title}: ground surface{when}")
    save_png(fig, path)


# ---------------------------------------------------------------------------------------------
# 3D: the plate from below and the crater as a height map, over the horizontal plane
# ---------------------------------------------------------------------------------------------

# The faces of VTK's 8-node hexahedron, each a loop of its local node numbers.
HEX_FACES = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
HEX_OPPOSITE = [(0, 1), (2, 4), (3, 5)]  # its pairs of opposite faces
# Where each face of the domain lies: (axis, 0 at min_m, 1 at max_m).
FACES = {"left": (0, 0), "right": (0, 1), "bottom": (1, 0), "top": (1, 1), "back": (2, 0),
         "front": (2, 1)}


class Horizontal:
    """The horizontal plane of a 3D run: its axes (h0, h1), the vertical axis, the symmetry
    planes across it [(0 or 1: which of h0, h1, coordinate)], the domain's horizontal box
    (or None) and the charge's axis (or None)."""

    def __init__(self, scenario, summary, vertical):
        self.v = vertical
        self.axes = [a for a in range(3) if a != vertical]
        sc = scenario or {}
        dom = sc.get("domain") if isinstance(sc.get("domain"), dict) else {}
        lo, hi = dom.get("min_m"), dom.get("max_m")
        self.box = None
        if all(isinstance(b, list) and len(b) == 3 for b in (lo, hi)):
            self.box = np.array([[float(lo[a]), float(hi[a])] for a in self.axes])
        self.planes = []
        for face in dom.get("symmetry_planes") or []:
            axis, side = FACES.get(face, (vertical, 0))
            if axis != vertical and self.box is not None:
                self.planes.append((self.axes.index(axis), float(self.box[self.axes.index(axis),
                                                                           side])))
        self.axis = charge_axis(sc, summary, self.axes)

    def images(self, xy):
        """xy (N x 2) and its mirror images through the symmetry planes."""
        out = [np.asarray(xy, dtype=float)]
        for k, c in self.planes:
            for a in list(out):
                b = a.copy()
                b[..., k] = 2.0 * c - b[..., k]
                out.append(b)
        return out

    def mirrored(self):
        """' (mirrored about x = 0 and y = 0: the whole model)', or '' without planes."""
        if not self.planes:
            return ""
        about = " and ".join(f"{AXES[self.axes[k]]} = {c:.3g} m" for k, c in self.planes)
        return f", mirrored about {about}"

    def label(self, k):
        return f"{AXES[self.axes[k]]} [m]"


def charge_axis(scenario, summary, axes):
    """The crater's axis (x, y): the probes' (summary.json), else the first detonation point of
    the scenario's first SPH part that has one; None if neither."""
    m = summary.get("metrics") if isinstance(summary.get("metrics"), dict) else {}
    ax, ay = as_float(m.get("crater_axis_x_m")), as_float(m.get("crater_axis_y_m"))
    if ax is not None and ay is not None:
        return (ax, ay)
    for p in scenario.get("parts") or []:
        det = p.get("detonation") if isinstance(p, dict) and p.get("method") == "sph" else None
        for d in det or []:
            pt = d.get("point_m") if isinstance(d, dict) else None
            if isinstance(pt, list) and len(pt) == 3:
                return (float(pt[axes[0]]), float(pt[axes[1]]))
    return None


def mark_axis(ax, hz, radius=None):
    if hz.axis is None:
        return
    for a in hz.images(np.array([hz.axis])):
        ax.plot(a[0, 0], a[0, 1], marker="+", color="k", ms=14, mew=1.8, zorder=6)
    if radius:
        ax.add_patch(Circle(hz.axis, radius, fill=False, ls="--", lw=1.2, color="k", zorder=6))


def bottom_footprints(grid, hz):
    """Each cell's bottom face projected on the horizontal plane: (polygons [K x 2], the face's
    mean height, von Mises [MPa] and eroded flags per cell); cells with non-finite points are
    left out. 8-node cells: of the hexahedron's pair of opposite faces with the largest
    footprint, the lower (by mean height); others: the convex hull of the cell's points. An
    eroded element's nodes that no live element holds any more are drawn at their reference
    (undeformed) place, wherever they flew: the element covers the hole it left, between the
    live elements around it and where it was."""
    pts = vtk_to_numpy(grid.GetPoints().GetData()).astype(float)
    cells = grid.GetCells()
    conn = vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64)
    offs = vtk_to_numpy(cells.GetOffsetsArray()).astype(np.int64)
    n = len(offs) - 1
    arr = vtk_arrays(grid.GetCellData())
    vm = np.asarray(arr.get("von_mises", np.full(n, np.nan)), float) / 1e6
    eroded = np.asarray(arr.get("eroded", np.zeros(n)), float) > 0.5
    if len(vm) != n or len(eroded) != n:
        return [], np.zeros(0), np.zeros(0), np.zeros(0, dtype=bool)
    disp = vtk_arrays(grid.GetPointData()).get("displacement")
    sizes = np.diff(offs)
    cell_of = np.repeat(np.arange(n), sizes)
    held = np.zeros(len(pts), dtype=bool)  # nodes of a live element
    held[conn[~eroded[cell_of]]] = True
    disp = np.asarray(disp, float) if disp is not None and len(disp) == len(pts) else None
    polys, heights, keep = [None] * n, np.full(n, np.nan), np.zeros(n, dtype=bool)
    hexes = np.flatnonzero(sizes == 8)
    if len(hexes):
        idx = conn[offs[hexes][:, None] + np.arange(8)]  # (H, 8) node numbers
        p = pts[idx]
        if disp is not None:  # an eroded element's loose nodes at their reference place
            loose = eroded[hexes][:, None] & ~held[idx]
            p = np.where(loose[..., None], p - disp[idx], p)
        faces = p[:, np.array(HEX_FACES)]  # (H, 6, 4, 3)
        # of the pair of opposite faces with the largest footprint (the plate's faces, however
        # the element is sheared), the lower one
        f = faces[..., hz.axes]
        area = np.abs((f[..., 0, 0] - f[..., 2, 0]) * (f[..., 1, 1] - f[..., 3, 1]) -
                      (f[..., 1, 0] - f[..., 3, 0]) * (f[..., 0, 1] - f[..., 2, 1]))  # (H, 6)
        pairs = np.array(HEX_OPPOSITE)  # (3, 2)
        best = pairs[np.argmax(np.nan_to_num(area[:, pairs].sum(axis=2), nan=-1.0), axis=1)]
        z = faces[..., hz.v].mean(axis=2)
        rows = np.arange(len(hexes))
        low = np.where(z[rows, best[:, 0]] <= z[rows, best[:, 1]], best[:, 0], best[:, 1])
        face = faces[rows, low]  # (H, 4, 3)
        ok = np.all(np.isfinite(face), axis=(1, 2))
        heights[hexes] = face[..., hz.v].mean(axis=1)
        keep[hexes] = ok
        xy = face[..., hz.axes]
        for c, q in zip(hexes[ok], xy[ok]):
            polys[c] = q
    for c in np.flatnonzero(sizes != 8):  # not crater's own meshes: the hull of the points
        q = pts[conn[offs[c]:offs[c + 1]]]
        if len(q) >= 3 and np.all(np.isfinite(q)):
            polys[c], heights[c], keep[c] = convex_hull(q[:, hz.axes]), q[:, hz.v].min(), True
    return ([p for p, k in zip(polys, keep) if k], heights[keep], vm[keep], eroded[keep])


def convex_hull(xy):
    """The convex hull of 2D points, counter-clockwise (Andrew's monotone chain)."""
    pts = sorted(set(map(tuple, np.asarray(xy, float))))
    if len(pts) < 3:
        return np.array(pts)

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1]) -
                                     (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out[:-1]
    return np.array(half(pts) + half(pts[::-1]))


def plate_panels(parts, frames, scenario, summary):
    """The frames of the plate figure: [(label, Frame)], the last frame and, when it differs,
    the one nearest probes.stress_time_s (the time of plate_peak_von_mises_pa)."""
    fem = [p for p in parts if p.method == "fem"]
    probes = scenario.get("probes") if isinstance((scenario or {}).get("probes"), dict) else {}
    if isinstance(probes.get("plate"), str) and any(p.name == probes["plate"] for p in fem):
        fem = [p for p in fem if p.name == probes["plate"]]
    last = next((f for f in reversed(frames) if any(p.name in f.files for p in fem)), None)
    if last is None:
        return fem, []
    panels = [("state at failure" if last.label == "failure" else "last frame", last)]
    t_stress = as_float(probes.get("stress_time_s")) if probes.get("plate") else None
    if t_stress is None and probes.get("plate"):
        t_stress = 6.0e-4  # the schema's default
    if t_stress is not None:
        cands = [f for f in frames if not f.label and any(p.name in f.files for p in fem)]
        near = min(cands, key=lambda f: abs(f.time - t_stress), default=None)
        if near is not None and near is not last and near.time > 0:
            panels.insert(0, (f"nearest to probes.stress_time_s = {t_stress * 1e3:.4g} ms",
                              near))
    return fem, panels


def plate_figure(path, fem, panels, hz, title):
    """The plate's underside: each element's bottom face (bottom_footprints) over the
    horizontal plane, the lowest drawn last (what is seen from below), coloured by von Mises
    stress; eroded elements hatched over light grey (grey where nothing is left above them: a
    hole through the plate); mirrored through the symmetry planes. False if nothing to draw."""
    data = []
    for label, frame in panels:
        live, dead, h, vm = [], [], [], []
        for p in fem:
            grid = read_grid(frame.files[p.name]) if p.name in frame.files else None
            if grid is None:
                continue
            polys, heights, v, er = bottom_footprints(grid, hz)
            for poly, hh, vv, e in zip(polys, heights, v, er):
                (dead if e else live).append(poly)
                if not e:
                    h.append(hh)
                    vm.append(vv)
        order = np.argsort(-np.asarray(h, float), kind="stable")  # the lowest last, on top
        live = [live[i] for i in order]
        vm = np.asarray(vm, float)[order]
        images = [hz.images(p) for p in live]  # each polygon and its mirror images
        data.append((label, frame, [q for im in images for q in im],
                     np.repeat(vm, len(images[0])) if images else vm,
                     [q for p in dead for q in hz.images(p)], len(dead)))
    data = [d for d in data if d[2] or d[4]]
    if not data:
        return False
    allv = np.concatenate([np.concatenate(d[2] + d[4]) for d in data])
    allv = allv[np.all(np.isfinite(allv), axis=1)]
    x0, y0 = allv.min(axis=0)
    x1, y1 = allv.max(axis=0)
    if hz.box is not None:  # the view stays on the domain (and its mirror images)
        bx = np.concatenate(hz.images(hz.box.T))
        x0, x1 = max(x0, bx[:, 0].min()), min(x1, bx[:, 0].max())
        y0, y1 = max(y0, bx[:, 1].min()), min(y1, bx[:, 1].max())
    pad = 0.04 * max(x1 - x0, y1 - y0, 1e-9)
    n = len(data)
    w = 6.2
    h = min(max(w * (y1 - y0) / max(x1 - x0, 1e-12), 3.0), 8.0)
    fig, axes = plt.subplots(1, n, figsize=(n * (w + 1.4), h + 1.2), squeeze=False,
                             constrained_layout=True)
    cmap = plt.get_cmap(QUANTITIES["von_mises"][2])
    for ax, (label, frame, live, vm, dead, n_dead) in zip(axes[0], data):
        fin = vm[np.isfinite(vm)]
        hi = float(np.percentile(fin, 99.5)) if len(fin) else 1.0
        norm = Normalize(0.0, hi if hi > 0 else 1.0)
        if dead:
            ax.add_collection(PolyCollection(dead, facecolors="0.85", edgecolors="none",
                                             zorder=1))
        if live:
            coll = PolyCollection(live, array=vm, cmap=cmap, norm=norm, edgecolors="face",
                                  linewidths=0.2, zorder=2)
            ax.add_collection(coll)
        if dead:
            ax.add_collection(PolyCollection(dead, facecolors="none", edgecolors="k",
                                             linewidths=0.4, hatch="xxxx", zorder=3))
            ax.legend(handles=[Patch(facecolor="0.85", edgecolor="k", hatch="xxxx",
                                     label=f"eroded ({n_dead} elements of the model)")],
                      fontsize=8, loc="upper right", framealpha=0.9)
        mark_axis(ax, hz)
        ax.set_xlim(x0 - pad, x1 + pad)
        ax.set_ylim(y0 - pad, y1 + pad)
        ax.set_aspect("equal")
        ax.set_xlabel(hz.label(0))
        ax.set_ylabel(hz.label(1))
        ax.set_title(f"t = {frame.time * 1e3:.4g} ms ({label})", fontsize=10)
        fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.9).set_label(
            QUANTITIES["von_mises"][1])
    fig.suptitle(f"{title}: the plate seen from below, von Mises stress{hz.mirrored()}")
    save_png(fig, path)
    return True


def column_index(xy, origin, pitch, shape):
    """The (i, j) column of each point and whether it lies in the grid."""
    ij = np.floor((np.asarray(xy, float) - origin) / pitch).astype(np.int64)
    return ij, np.all((ij >= 0) & (ij < np.array(shape)), axis=1)


def ground_top(grid, hz, columns, floor, carved, gap):
    """Per column (columns: origin, pitch, shape, g) the top of its ground: from the floor up,
    the grains' tops (centre + radius) until the first gap of more than `gap`, where the room
    `carved` (per column, the heights of the other parts at t = 0: the charge and the plate
    the soil was laid around) makes no gap (the probe's rule, on grains rather than cells);
    grains in flight (no contact and fast enough to rise more than their diameter,
    |v|^2 > 4 g r) left out. nan where no grain stands on the floor."""
    origin, pitch, shape, g = columns
    pts = vtk_to_numpy(grid.GetPoints().GetData()).astype(float)
    arr = vtk_arrays(grid.GetPointData())
    r = np.asarray(arr.get("radius", np.zeros(len(pts))), float)
    keep = np.all(np.isfinite(pts), axis=1) & np.isfinite(r)
    if "contacts" in arr and "velocity" in arr:
        v2 = np.asarray(speed(arr["velocity"]), float) ** 2
        keep &= ~((np.asarray(arr["contacts"], float) <= 0) & (v2 > 4.0 * g * r))
    ij, inside = column_index(pts[:, hz.axes], origin, pitch, shape)
    keep &= inside
    col = ij[keep, 0] * shape[1] + ij[keep, 1]
    lo, hi = pts[keep, hz.v] - r[keep], pts[keep, hz.v] + r[keep]
    order = np.lexsort((lo, col))
    col, lo, hi = col[order], lo[order], hi[order]
    room_lo = carved[0].ravel() - gap  # nan where there is no room: never bridged
    room_hi = carved[1].ravel() + gap
    top = np.full(shape[0] * shape[1], np.nan)
    starts = np.flatnonzero(np.r_[True, col[1:] != col[:-1]]) if len(col) else []
    for a, b in zip(starts, list(starts[1:]) + [len(col)]):
        c = col[a]
        reach = np.maximum.accumulate(np.r_[floor, hi[a:b]])[:-1]  # the top below each grain
        bridged = (reach >= room_lo[c]) & (lo[a:b] <= room_hi[c])
        broken = np.flatnonzero((lo[a:b] - reach > gap) & ~bridged)
        n = broken[0] if len(broken) else b - a
        if n > 0:
            top[c] = hi[a:a + n].max()
    return top.reshape(shape)


def carved_room(grids, hz, origin, pitch, shape):
    """Per column, the lowest and highest point of the other parts (SPH, FEM) at t = 0: the
    room the soil was laid around; nan where they have none."""
    lo, hi = np.full(shape, np.inf), np.full(shape, -np.inf)
    for grid in grids:
        pts = vtk_to_numpy(grid.GetPoints().GetData()).astype(float)
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        ij, inside = column_index(pts[:, hz.axes], origin, pitch, shape)
        np.minimum.at(lo, (ij[inside, 0], ij[inside, 1]), pts[inside, hz.v])
        np.maximum.at(hi, (ij[inside, 0], ij[inside, 1]), pts[inside, hz.v])
    ok = np.isfinite(lo)
    return np.where(ok, lo, np.nan), np.where(ok, hi, np.nan)


def crater_grid(grids0, hz, scenario):
    """(origin, pitch, shape, largest grain radius) of the columns: the width of
    probes.surface_bin_m, else 8 x the largest grain radius (the probe's), over the domain's
    horizontal extent (else the grains') in a whole number of columns."""
    pts = np.concatenate([vtk_to_numpy(gr.GetPoints().GetData()) for gr in grids0]).astype(float)
    rs = [vtk_arrays(gr.GetPointData()).get("radius") for gr in grids0]
    rmax = max((float(np.nanmax(r)) for r in rs if r is not None and len(r)), default=0.0)
    probes = (scenario or {}).get("probes")
    b = as_float(probes.get("surface_bin_m")) if isinstance(probes, dict) else None
    b = b if b and b > 0 else 8.0 * rmax
    if hz.box is not None:
        lo, hi = hz.box[:, 0], hz.box[:, 1]
    else:
        xy = pts[:, hz.axes]
        lo, hi = xy.min(axis=0) - rmax, xy.max(axis=0) + rmax
    ext = np.maximum(hi - lo, 1e-12)
    if not b > 0:
        b = float(ext.max()) / 20.0
    shape = tuple(int(max(1, round(e / b))) for e in ext)
    return lo, ext / np.array(shape), shape, rmax


def crater_map(soil, others, frames, hz, scenario):
    """The ground's change dz over the columns, last frame vs the first, and both frames; None
    when the soil has no two frames to compare."""
    first = min((f for f in frames if any(p.name in f.files for p in soil)),
                key=lambda f: f.time, default=None)
    last = next((f for f in reversed(frames) if any(p.name in f.files for p in soil)), None)
    if first is None or last is None or first is last:
        return None
    g = 9.81
    grav = ((scenario or {}).get("domain") or {}).get("gravity_m_s2")
    if isinstance(grav, list) and len(grav) == 3:
        g = float(np.linalg.norm(np.asarray(grav, float))) or 9.81

    def grids(frame, which):
        out = [read_grid(frame.files[p.name]) for p in which if p.name in frame.files]
        return [gr for gr in out if gr is not None and gr.GetNumberOfPoints()]

    grids0, grids1 = grids(first, soil), grids(last, soil)
    if not grids0:
        return None
    origin, pitch, shape, rmax = crater_grid(grids0, hz, scenario)
    carved = carved_room(grids(first, others), hz, origin, pitch, shape)
    # the floor: the bed's bottom at t = 0
    pts0 = np.concatenate([vtk_to_numpy(gr.GetPoints().GetData()) for gr in grids0])
    r0 = np.concatenate([vtk_arrays(gr.GetPointData()).get("radius",
                                                           np.zeros(gr.GetNumberOfPoints()))
                         for gr in grids0])
    floor = float(np.nanmin(pts0[:, hz.v] - r0))
    columns, gap = (origin, pitch, shape, g), 6.0 * rmax

    def top(gs):
        tops = [ground_top(gr, hz, columns, floor, carved, gap) for gr in gs]
        return np.fmax.reduce(tops) if tops else np.full(shape, np.nan)

    top0, top1 = top(grids0), top(grids1)
    # a column that had ground and has none left is a hole through the bed (the probe's rule):
    # its surface is the floor
    top1 = np.where(np.isfinite(top0) & ~np.isfinite(top1), floor, top1)
    return origin, pitch, top1 - top0, first, last


def crater_figure(path, cmap_data, hz, title, summary):
    origin, pitch, dz, first, last = cmap_data
    xe = origin[0] + pitch[0] * np.arange(dz.shape[0] + 1)
    ye = origin[1] + pitch[1] * np.arange(dz.shape[1] + 1)
    # mirror the grid through the symmetry planes (they are the domain's faces: grid edges)
    for k, c in hz.planes:
        edges = xe if k == 0 else ye
        if abs(c - edges[0]) <= abs(c - edges[-1]):
            edges2 = np.concatenate([2.0 * c - edges[:0:-1], edges])
            dz = np.concatenate([np.flip(dz, axis=k), dz], axis=k)
        else:
            edges2 = np.concatenate([edges, 2.0 * c - edges[-2::-1]])
            dz = np.concatenate([dz, np.flip(dz, axis=k)], axis=k)
        if k == 0:
            xe = edges2
        else:
            ye = edges2
    finite = np.isfinite(dz)
    lim = float(np.nanmax(np.abs(dz[finite]))) if np.any(finite) else 0.0
    scale, unit = (1.0, "m") if lim >= 0.1 else (1e3, "mm")
    lim = max(lim, 1e-3) * scale  # at least +-1 mm: a ground that did not move stays white
    w = 6.5
    h = min(max(w * (ye[-1] - ye[0]) / max(xe[-1] - xe[0], 1e-12), 3.0), 8.0)
    fig, ax = plt.subplots(figsize=(w + 1.6, h + 1.0), constrained_layout=True)
    mesh = ax.pcolormesh(xe, ye, np.ma.masked_invalid(dz.T * scale), cmap="RdBu",
                         norm=Normalize(-lim, lim), shading="flat")
    m = summary.get("metrics") if isinstance(summary.get("metrics"), dict) else {}
    radius = as_float(m.get("crater_radius_m"))
    mark_axis(ax, hz, radius if radius and radius > 0 else None)
    ax.set_xlim(xe[0], xe[-1])
    ax.set_ylim(ye[0], ye[-1])
    ax.set_aspect("equal")
    ax.set_xlabel(hz.label(0))
    ax.set_ylabel(hz.label(1))
    ax.set_facecolor("0.9")  # no ground here at t = 0
    fig.colorbar(mesh, ax=ax, shrink=0.9).set_label(f"ground surface change dz [{unit}]")
    when = "state at failure" if last.label == "failure" else f"t = {last.time * 1e3:.4g} ms"
    ax.set_title(f"{when} vs t = {first.time * 1e3:.4g} ms; columns "
                 f"{pitch[0]:.3g} x {pitch[1]:.3g} m"
                 + ("; +: the charge's axis" if hz.axis is not None else "")
                 + ("; dashed: crater_radius_m" if radius and radius > 0 else ""), fontsize=9)
    fig.suptitle(f"{title}: the crater as a height map{hz.mirrored()}")
    save_png(fig, path)


# ---------------------------------------------------------------------------------------------
# report.md
# ---------------------------------------------------------------------------------------------

# Metric names end in their unit (summary.json): the longest matching suffix wins.
UNIT_SUFFIXES = [("_m_s", "m/s"), ("_m2", "m^2"), ("_pa", "Pa"), ("_kg", "kg"), ("_j", "J"), ("_n", "N"),
                 ("_m", "m"), ("_s", "s"), ("_k", "K")]


def metric_unit(name):
    for suffix, unit in UNIT_SUFFIXES:
        if name.endswith(suffix):
            return unit
    return ""


def fmt_value(v, digits=6):
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return f"{v:.{digits}g}"
    if v is None:
        return "—"
    return md_escape(json.dumps(v) if isinstance(v, (dict, list)) else str(v))


def md_escape(s):
    return str(s).replace("|", "\\|").replace("\n", " ")


def result_flags(summary, metrics, err):
    """What a reader must know before trusting the numbers: a crater that reached the bottom of
    the bed (the box truncates it), a part that lost much of its mass out of the domain, an
    energy error above the guard's warning level. (Detonation products leaving the domain are
    not flagged: venting is what they do.)"""
    flags = []
    depth = as_float(metrics.get("crater_depth_m"))
    for p in summary.get("parts") or []:
        diag = p.get("diagnostics") if isinstance(p, dict) and isinstance(
            p.get("diagnostics"), dict) else {}
        bed = as_float(diag.get("packing_bed_height_m"))
        if depth is not None and bed and depth >= 0.98 * bed:
            flags.append(f"**The crater reached the bottom of the box**: crater depth "
                         f"{depth:.3g} m, the bed of '{md_escape(p.get('name', '?'))}' is "
                         f"{bed:.3g} m deep. The domain truncates the crater and what depends "
                         "on it; a wider and deeper domain (the paper scenes' `--level wide`) "
                         "tells how much.")
        left, mass = as_float(diag.get("left_domain_mass_kg")), as_float(p.get("mass_kg"))
        # (an explosive's products venting out is what they do; grains are the ground)
        if p.get("method") != "sph" and left and mass is not None and left > 0.5 * (left + mass):
            flags.append(f"Part '{md_escape(p.get('name', '?'))}': {left:.4g} kg left the "
                         f"domain, more than stays in it ({mass:.4g} kg).")
    if err is not None and abs(err) > 0.02:
        flags.append(f"Energy balance error {err * 100:.3g} %, above 2 % (time.energy_warn_error's "
                     "default): look at the energy figure before the numbers.")
    return flags


def build_report(run_dir, summary, parts, figures, snapshot_frames, plane, hist):
    sc = summary.get("scenario") if isinstance(summary.get("scenario"), dict) else {}
    name = sc.get("name", run_dir.name)
    dim = sc.get("dimension")
    lines = [f"# crater report: {md_escape(name)}", ""]
    lines += [f"Run directory `{run_dir.resolve()}`, written by crater {fmt_value(summary.get('crater_version'))}."
              " Figures: `crater report` (tools/report/crater_report.py).", ""]
    status = str(summary.get("status", "unknown"))
    rows = [("scenario", f"`{md_escape(name)}` ({md_escape(sc.get('file', '?'))}, "
                         f"hash {md_escape(sc.get('hash', '?'))})")]
    if dim in (2, 3):
        rows.append(("dimension", f"{dim}D" + (" (plane strain; masses per metre of depth)"
                                                 if dim == 2 else "")))
    rows.append(("status", f"**{md_escape(status)}**" + (
        f": {md_escape(summary['message'])}" if summary.get("message") else "")))
    rows.append(("steps", fmt_value(summary.get("steps"))))
    t_end, t_reached = as_float(sc.get("end_time_s")), as_float(summary.get("time_s"))
    rows.append(("time reached / end time",
                 f"{fmt_ms(t_reached)} / {fmt_ms(t_end)}"))
    ts = summary.get("time_step") if isinstance(summary.get("time_step"), dict) else {}
    if ts:
        rows.append(("time step", f"{fmt_value(ts.get('min_s'), 4)} to "
                                  f"{fmt_value(ts.get('max_s'), 4)} s (safety factor "
                                  f"{fmt_value(ts.get('safety_factor'), 3)})"))
    en = summary.get("energy") if isinstance(summary.get("energy"), dict) else {}
    e0 = (en.get("initial") or {}).get("total_j") if isinstance(en.get("initial"), dict) else None
    e1 = (en.get("final") or {}).get("total_j") if isinstance(en.get("final"), dict) else None
    err = as_float(en.get("balance_error"))
    if err is None and hist and hist.get("energy_error"):
        err = hist["energy_error"][-1]
    rows.append(("total energy, initial → final",
                 f"{fmt_value(as_float(e0), 5)} J → {fmt_value(as_float(e1), 5)} J"))
    rows.append(("energy error", f"{err * 100:.3g} %" if err is not None else "—"))
    run = summary.get("run") if isinstance(summary.get("run"), dict) else {}
    if run:
        ranks = run.get("ranks")
        on = (f"{fmt_value(ranks)} MPI ranks of {fmt_value(run.get('threads'))} thread(s)"
              if isinstance(ranks, int) and ranks > 1 else f"{fmt_value(run.get('threads'))} thread(s)")
        rows.append(("wall time", f"{fmt_value(as_float(run.get('wall_time_s')), 4)} s on {on}"))
        cmd = run.get("command") if isinstance(run.get("command"), dict) else {}
        argv = cmd.get("argv") if isinstance(cmd.get("argv"), list) else []
        if argv:
            rows.append(("command", "`" + md_escape(" ".join(str(a) for a in argv)) + "`"))
    lines += ["| | |", "| --- | --- |"] + [f"| {k} | {v} |" for k, v in rows] + [""]

    per_m = " per metre" if dim == 2 else ""
    lines += ["## Parts", "",
              "Mass at the end, what left the domain (SPH, DEM: `domain.outflow = \"remove\"`) "
              "and what eroded (FEM), in kg" + per_m + ".", "",
              "| part | method | count | mass | left the domain | eroded | notes |",
              "| --- | --- | ---: | ---: | ---: | ---: | --- |"]
    for p in summary.get("parts") or []:
        if not isinstance(p, dict):
            continue
        diag = p.get("diagnostics") if isinstance(p.get("diagnostics"), dict) else {}
        notes = []
        if "elements" in diag:
            notes.append(f"{fmt_value(diag.get('eroded_elements', 0))} of "
                         f"{fmt_value(diag['elements'])} elements eroded")
        if diag.get("wall_reflections"):
            notes.append(f"{fmt_value(diag['wall_reflections'])} wall reflections")
        left = as_float(diag.get("left_domain_mass_kg"))
        eroded = as_float(diag.get("eroded_mass_kg"))
        if diag.get("left_domain_count"):
            notes.append(f"{fmt_value(diag['left_domain_count'])} particles left the domain")
        lines.append(f"| {md_escape(p.get('name', '?'))} | {md_escape(p.get('method', '?'))} | "
                     f"{fmt_value(p.get('count'))} | {fmt_value(as_float(p.get('mass_kg')), 6)} | "
                     f"{fmt_value(left, 6) if left is not None else '—'} | "
                     f"{fmt_value(eroded, 6) if eroded is not None else '—'} | "
                     f"{'; '.join(notes)} |")
    lines.append("")

    metrics = summary.get("metrics") if isinstance(summary.get("metrics"), dict) else {}
    flags = result_flags(summary, metrics, err)
    if flags:
        lines += ["## Flags", ""] + [f"- {f}" for f in flags] + [""]
    lines += ["## Metrics", ""]
    if metrics:
        lines += ["| metric | value | unit |", "| --- | ---: | --- |"]
        for k, v in metrics.items():
            unit = metric_unit(k)
            value = fmt_value(v)
            if unit == "Pa" and as_float(v) is not None:
                value += f" ({as_float(v) / 1e6:.4g} MPa)"
            lines.append(f"| `{md_escape(k)}` | {value} | {unit} |")
    else:
        lines.append("None recorded in summary.json.")
    lines.append("")

    lines += time_section(run)

    contacts = summary.get("contacts") if isinstance(summary.get("contacts"), dict) else {}
    if contacts:
        lines += ["## Contacts at the end", "", "| quantity | value | unit |",
                  "| --- | ---: | --- |"]
        for k, v in contacts.items():
            lines.append(f"| `{md_escape(k)}` | {fmt_value(v)} | {metric_unit(k)} |")
        lines.append("")

    lines += ["## Figures", ""]
    if snapshot_frames:
        when = ", ".join(fmt_ms(f.time) + (" (failure)" if f.label else "")
                         for f in snapshot_frames)
        lines += [f"Snapshots at {when}; eroded elements hidden; grey: a part without the "
                  "quantity." + (f" 3D: the vertical {AXES[plane.h]}-{AXES[plane.v]} "
                                 f"{plane.label()} through the charge (particles within about "
                                 "a particle layer of it)." if plane.n is not None else ""),
                  ""]
    for title, fname, *caption in figures:
        lines += [f"### {title}", "", f"![{title}]({fname})", ""] + [c for c in caption if c] + (
            [""] if any(caption) else [])
    failures = sorted(p.failure.name for p in parts if p.failure)
    if failures:
        lines += ["The state at failure: " + ", ".join(f"`{f}`" for f in failures) + ".", ""]
    return "\n".join(lines) + "\n"


def time_section(run):
    """Where the loop's time went (summary.json run.time_by_part_s), and on MPI ranks each rank's
    stages with its time in MPI's calls (run.time_by_rank_s) and each part's share among the
    ranks (run.ranks_by_part): markdown lines, none when the summary has no breakdown."""
    by_part = run.get("time_by_part_s") if isinstance(run.get("time_by_part_s"), dict) else {}
    loop = as_float(run.get("loop_time_s"))
    if not by_part or not loop:
        return []
    stages = [(f"part `{md_escape(k)}`", as_float(v))
              for k, v in (by_part.get("parts") or {}).items()]
    stages += [(k, as_float(by_part.get(k))) for k in ("contacts", "probes", "output", "other")
               if as_float(by_part.get(k)) is not None]
    lines = ["## Where the time went", "",
             f"The time loop took {fmt_value(loop, 4)} s (`run.time_by_part_s` of summary.json"
             + ("; on ranks, rank 0's" if isinstance(run.get("ranks"), int) else "") + ").", "",
             "| stage | time [s] | share of the loop |", "| --- | ---: | ---: |"]
    for name, t in stages:
        if t is not None:
            lines.append(f"| {name} | {t:.3g} | {100 * t / loop:.1f} % |")
    lines.append("")
    by_rank = run.get("time_by_rank_s") if isinstance(run.get("time_by_rank_s"), dict) else {}
    loops = by_rank.get("loop") if isinstance(by_rank.get("loop"), list) else []
    if loops:
        mpi = by_rank.get("mpi") or []
        parts = by_rank.get("parts") if isinstance(by_rank.get("parts"), dict) else {}
        cols = [f"`{md_escape(k)}`" for k in parts] + ["contacts", "in MPI's calls"]
        lines += ["Each rank's stages (its waits for the others included; the time in MPI's "
                  "calls is what it spent waiting and moving bytes):", "",
                  "| rank | loop [s] | " + " | ".join(c + " [s]" for c in cols) + " |",
                  "| ---: | ---: | " + " | ".join("---:" for _ in cols) + " |"]
        for r, t in enumerate(loops):
            cells = [as_float(v[r]) if isinstance(v, list) and r < len(v) else None
                     for v in parts.values()]
            cont = by_rank.get("contacts") or []
            cells.append(as_float(cont[r]) if r < len(cont) else None)
            cells.append(as_float(mpi[r]) if r < len(mpi) else None)
            lines.append(f"| {r} | {fmt_value(as_float(t), 4)} | " + " | ".join(
                f"{c:.3g}" if c is not None else "—" for c in cells) + " |")
        lines.append("")
    shares = run.get("ranks_by_part") if isinstance(run.get("ranks_by_part"), dict) else {}
    if shares:
        lines += ["Each part's share among the ranks (`run.ranks_by_part`; the load ratio is the "
                  "busiest rank's load over the mean when the part last looked at its cuts, by "
                  f"{md_escape(str(run.get('balance', 'time')))}):", "",
                  "| part | owned (fewest – most) | load ratio | cuts made again |",
                  "| --- | ---: | ---: | ---: |"]
        for name, f in shares.items():
            if not isinstance(f, dict):
                continue
            lines.append(f"| `{md_escape(name)}` | {fmt_value(f.get('owned_min'))} – "
                         f"{fmt_value(f.get('owned_max'))} | "
                         f"{fmt_value(as_float(f.get('load_ratio')), 3)} | "
                         f"{fmt_value(f.get('rebalances'))} |")
        lines.append("")
    return lines


def fmt_ms(t):
    return f"{t * 1e3:.4g} ms" if t is not None else "—"


# ---------------------------------------------------------------------------------------------

def parse_args(argv):
    ap = argparse.ArgumentParser(
        prog="crater report",
        description="Figures (PNG) and report.md for a run directory of `crater run`.")
    ap.add_argument("dir", help="run directory (summary.json, <part>.pvd, history.csv)")
    ap.add_argument("--out", "-o", help="where to write the report (default: DIR/report)")
    ap.add_argument("--times", help="snapshot times in seconds, comma-separated (the nearest "
                                    "output frames); default: up to 4 spread over the run")
    return ap.parse_args(argv)


def main(argv):
    args = parse_args(argv)
    run_dir = Path(args.dir)
    if not run_dir.is_dir():
        raise InputError(f"{run_dir}: " + ("not a directory" if run_dir.exists()
                                           else "no such run directory"))
    summary = load_summary(run_dir)
    parts = find_parts(run_dir, summary)
    frames = collect_frames(parts, summary)
    chosen = select_frames(frames, args.times)
    out_dir = Path(args.out) if args.out else run_dir / "report"

    import_plotting()
    out_dir.mkdir(parents=True, exist_ok=True)
    for f in OUR_FILES:
        (out_dir / f).unlink(missing_ok=True)

    sc = summary.get("scenario") if isinstance(summary.get("scenario"), dict) else {}
    title = str(sc.get("name", run_dir.name))
    dim = sc.get("dimension")
    if dim not in (2, 3):  # summary.json does not say: 3D if the points are not all at z = 0
        grids = (read_grid(f) for frame in chosen for f in frame.files.values())
        grid = next((g for g in grids if g is not None), None)
        pts = vtk_to_numpy(grid.GetPoints().GetData()) if grid is not None else np.zeros((0, 3))
        dim = 3 if len(pts) and np.ptp(pts[:, 2]) > 0 else 2
    figures = []

    scenario = load_scenario(summary, run_dir)
    plane = (section_plane(parts, chosen[0], vertical_axis_3d(scenario)) if dim == 3
             else Plane())
    all_states = [load_states(parts, f, plane) for f in chosen]
    if any(all_states):
        dom = domain_box(scenario, plane)
        view = view_box(all_states, dom)
        note = view_note(all_states, chosen, view, dom)
        present = {"parts"} | {k for states in all_states for s in states for k in s.values}
        colours = part_colours(parts)
        for key, fname in SNAPSHOT_FILES.items():
            if key in present:
                snapshot_figure(out_dir / fname, key, chosen, all_states, view, colours, title,
                                plane)
                figures.append((f"Snapshots: {QUANTITIES[key][0]}", fname, note))
    else:
        warn("no frame could be read; no snapshots")

    hist = read_csv_columns(run_dir / "history.csv")
    if hist and "time_s" in hist and len(hist["time_s"]) >= 1:
        energy_figure(out_dir / ENERGY_FILE, hist, title)
        figures.append(("Energy history", ENERGY_FILE))
        vm = [c for c in hist if c.endswith("_max_von_mises_pa")]
        if vm:
            von_mises_history_figure(out_dir / VON_MISES_HISTORY_FILE, hist, vm, title)
            figures.append(("Peak von Mises stress of the plate", VON_MISES_HISTORY_FILE))
        if any(col in hist for col, _, _ in LINING_GAUGES):
            lining_figure(out_dir / LINING_FILE, hist, read_csv_columns(run_dir / "crown_line.csv"),
                          title)
            figures.append(("The tunnel lining's gauges", LINING_FILE, LINING_CAPTION))
    elif hist is None:
        warn(f"{run_dir / 'history.csv'}: absent; no energy history")

    prof = read_csv_columns(run_dir / "surface_profile.csv")
    if prof and any(cols <= prof.keys() and prof[x] for x, cols in
                    [("x_m", {"x_m", "vertical_displacement_m"}), ("r_m", {"r_m", "dz_m"})]):
        surface_figure(out_dir / SURFACE_FILE, prof, title, as_float(summary.get("time_s")))
        figures.append(("Ground surface settlement", SURFACE_FILE))

    if dim == 3:
        hz = Horizontal(scenario, summary, plane.v)
        fem, panels = plate_panels(parts, frames, scenario, summary)
        if panels and plate_figure(out_dir / PLATE_FILE, fem, panels, hz, title):
            figures.append(("The plate seen from below", PLATE_FILE, PLATE_CAPTION))
        soil = [p for p in parts if p.method == "dem"]
        probes = (scenario or {}).get("probes")
        if isinstance(probes, dict) and any(p.name == probes.get("soil") for p in soil):
            soil = [p for p in soil if p.name == probes["soil"]]
        others = [p for p in parts if p.method in ("sph", "fem")]
        crater = crater_map(soil, others, frames, hz, scenario) if soil else None
        if crater is not None:
            crater_figure(out_dir / CRATER_MAP_FILE, crater, hz, title, summary)
            figures.append(("The crater as a height map", CRATER_MAP_FILE, CRATER_CAPTION))

    (out_dir / REPORT_FILE).write_text(
        build_report(run_dir, summary, parts, figures, chosen, plane, hist))
    print(f"crater report: {out_dir / REPORT_FILE} and {len(figures)} figure(s)")
    return EXIT_OK


def import_plotting():
    """numpy, VTK and matplotlib, into this module's globals; exit 1 naming the Debian packages
    if one is missing."""
    global np, plt, Normalize, ScalarMappable, PolyCollection, EllipseCollection, Patch, Circle
    global vtkXMLUnstructuredGridReader, vtkXMLPUnstructuredGridReader, vtkCutter, vtkPlane
    global vtk_to_numpy
    try:
        import numpy as np
        os.environ.setdefault("MPLBACKEND", "Agg")
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.cm import ScalarMappable
        from matplotlib.collections import EllipseCollection, PolyCollection
        from matplotlib.colors import Normalize
        from matplotlib.patches import Circle, Patch
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkCommonCore import vtkObject
        from vtkmodules.vtkCommonDataModel import vtkPlane
        from vtkmodules.vtkFiltersCore import vtkCutter
        from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader
    except ImportError as e:
        print(f"crater report: error: {sys.executable} lacks a module ({e}); install the Debian "
              f"packages {DEBIAN_PACKAGES}", file=sys.stderr)
        sys.exit(EXIT_OTHER)
    vtkObject.GlobalWarningDisplayOff()  # unreadable files are reported here, in one line
    # numpy's warnings on empty or all-nan data (a part eroded away, a probe not measured) are
    # noise here: such data are left out of the figures
    warnings.filterwarnings("ignore", category=RuntimeWarning)


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        print(f"crater report: error: {e}", file=sys.stderr)
        sys.exit(EXIT_INPUT)
    except KeyboardInterrupt:
        print("crater report: interrupted", file=sys.stderr)
        sys.exit(EXIT_INTERRUPTED)
    except OSError as e:
        print(f"crater report: error: {e}", file=sys.stderr)
        sys.exit(EXIT_OTHER)
    except Exception as e:  # a bug here, not bad input: one line, the traceback on request
        if os.environ.get("CRATER_REPORT_DEBUG"):
            raise
        print(f"crater report: internal error: {type(e).__name__}: {e} "
              "(CRATER_REPORT_DEBUG=1 shows the traceback)", file=sys.stderr)
        sys.exit(EXIT_OTHER)
