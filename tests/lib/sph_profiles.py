"""Helpers for the SPH verification tests (tests/verification/sph_*): runs, frames read back
with VTK, 1D profiles of 2D strips, and figures. Their scenarios are written with
scenario_blocks.py.

Run by Debian's /usr/bin/python3 (numpy, python3-vtk9; matplotlib only for figures).
"""
import csv
import os
import shutil
import time
from pathlib import Path

import numpy as np

from crater_test import SOURCE_DIR, TMP, read_pvd, read_vtu, run_scenario

# The Chapman-Jouguet state of scenario_blocks.TNT (Dobratz & Crawford 1985).
TNT_P_CJ = 21.0e9     # Pa, Dobratz & Crawford 1985
TNT_U_CJ = 1859.0     # m/s, Dobratz & Crawford 1985 (u = P_CJ / (rho0 D))
TNT_RHO_CJ = 2228.0   # kg/m^3


def run(scenario_path, out_dir, threads=1, sets=()):
    """Runs crater quietly; returns (summary, wall seconds). One thread by default: ctest runs
    tests in parallel, and oversubscribed OpenMP threads slow crater down several times."""
    t0 = time.monotonic()
    summary = run_scenario(scenario_path, out_dir, threads=threads, sets=sets)
    return summary, time.monotonic() - t0


# ---------------------------------------------------------------------------------------------
# Output
# ---------------------------------------------------------------------------------------------

def frames(out_dir, part):
    """[(time, path)] of a part's VTU frames, from its .pvd."""
    out_dir = Path(out_dir)
    return [(t, out_dir / f) for t, f in read_pvd(out_dir / f"{part}.pvd")]


def load_frame(path):
    """A frame as a dict: 'x' (N x 3 points), 'time', and every point array by name."""
    pts, arrays, _, t = read_vtu(path)
    d = dict(arrays)
    d["x"] = pts
    d["time"] = t
    return d


def frame_at(out_dir, part, t, rel_tol=1e-9):
    """The frame written at time t (frames land exactly on output times)."""
    for ft, p in frames(out_dir, part):
        if abs(ft - t) <= rel_tol * max(abs(t), 1e-300):
            return load_frame(p)
    raise AssertionError(f"no {part} frame at t = {t} in {out_dir}: "
                         f"{[ft for ft, _ in frames(out_dir, part)]}")


def read_history(out_dir):
    """history.csv as {column: numpy array}."""
    with open(Path(out_dir) / "history.csv") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise AssertionError(f"{out_dir}/history.csv has no rows")
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


# ---------------------------------------------------------------------------------------------
# Profiles
# ---------------------------------------------------------------------------------------------

def binned_mean(x, values, edges):
    """Mean of `values` over the particles in each bin [edges[k], edges[k+1]); (means, counts),
    NaN where a bin is empty."""
    x = np.asarray(x, float)
    values = np.asarray(values, float)
    idx = np.searchsorted(edges, x, side="right") - 1
    ok = (idx >= 0) & (idx < len(edges) - 1)
    n = len(edges) - 1
    counts = np.bincount(idx[ok], minlength=n).astype(float)
    sums = np.bincount(idx[ok], weights=values[ok], minlength=n)
    with np.errstate(invalid="ignore", divide="ignore"):
        means = np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)
    return means, counts


def profile(x, values, edges):
    """1D profile of a 2D strip: bin means of `values` over x (averaged across the strip),
    empty bins filled by linear interpolation between their neighbours. Returns
    (bin centres, profile)."""
    means, counts = binned_mean(x, values, edges)
    centres = 0.5 * (edges[:-1] + edges[1:])
    good = counts > 0
    if good.sum() < 2:
        raise AssertionError("fewer than two non-empty bins")
    return centres, np.interp(centres, centres[good], means[good])


def l1_relative(xc, prof, exact_fn, lo, hi, n_fine=20000):
    """integral_lo^hi |prof - exact| dx / integral_lo^hi |exact| dx, with the piecewise-linear
    profile through (xc, prof) and the exact solution on a fine midpoint grid."""
    xf = lo + (np.arange(n_fine) + 0.5) * (hi - lo) / n_fine
    ex = exact_fn(xf)
    pf = np.interp(xf, xc, prof)
    return float(np.sum(np.abs(pf - ex)) / np.sum(np.abs(ex)))


def last_crossing(xc, prof, level):
    """Largest x at which the piecewise-linear profile crosses `level` from above (going to
    +x), i.e. the position of a front running towards +x; linear interpolation between bins."""
    above = np.nonzero(prof >= level)[0]
    if len(above) == 0:
        raise AssertionError(f"profile never reaches {level}")
    k = above[-1]
    if k == len(prof) - 1:
        return float(xc[k])
    p0, p1 = prof[k], prof[k + 1]
    return float(xc[k] + (xc[k + 1] - xc[k]) * (p0 - level) / (p0 - p1))


# ---------------------------------------------------------------------------------------------
# Figures
# ---------------------------------------------------------------------------------------------

def write_figures_requested():
    return os.environ.get("CRATER_WRITE_FIGURES") == "1"


def pyplot():
    """matplotlib.pyplot on the Agg backend, or None when matplotlib is missing (then a figure
    is only an error if CRATER_WRITE_FIGURES=1 asked for it)."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        if write_figures_requested():
            raise
        return None
    return plt


def save_figure(fig, name):
    """Saves fig as CRATER_TEST_TMP/figures/<name>.png and, only with CRATER_WRITE_FIGURES=1,
    copies it to docs/figures/<name>.png. Returns the scratch path."""
    d = Path(TMP) / "figures"
    d.mkdir(parents=True, exist_ok=True)
    path = d / f"{name}.png"
    fig.savefig(path, dpi=120, bbox_inches="tight")
    if write_figures_requested():
        dest = Path(SOURCE_DIR) / "docs" / "figures"
        dest.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, dest / path.name)
    return path
