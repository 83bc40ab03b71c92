#!/usr/bin/python3
"""Halo volumes and a strong-scaling model for a domain decomposition of a crater run (issue 29).

crater does not run on several ranks yet. This script measures what a decomposition of a real
scene would exchange, so that the design (docs/distributed.md) rests on figures:

1. It reads the entities of a run's frame with VTK's reader: SPH and DEM particles at their
   positions, FEM elements at their centres.
2. It cuts them into P subdomains by recursive coordinate bisection (RCB): the longest side of a
   box is cut where the cost on each side is in proportion to the ranks given to it, the cost of
   an entity being its method's cost per entity-step.
3. For each rank it counts its halo: the other ranks' entities within a method's cutoff of its
   box (DEM: the largest grain diameter plus the list's skin; SPH: the kernel's support, 2 h;
   FEM: one element size), and the neighbour ranks it would exchange with.
4. The model: the time of a step on P ranks is the largest rank's compute (its entities' cost,
   plus --ghost-cost times its halo's: binning the ghosts and evaluating the pairs that cross
   the cut on both sides, which the deterministic design of docs/distributed.md does) plus its
   exchanges (two per step, positions out and forces back: messages x latency +
   bytes / bandwidth) plus the global reductions (n_reductions x 2 ceil(log2 P) x latency); the
   efficiency is T(1) / (P T(P)).

Usage, from the repository root (a run directory with frame 0 written):
  /usr/bin/python3 tools/scaling/halo_model.py RUN_DIR [--frame K] [--ranks 2,4,...]
      [--latency-us A] [--bandwidth-gbs B] [--ghost-cost G] [--scale N_TARGET]
--scale N evaluates the model for a scene of N entities refined uniformly from this one (the halo
per rank depends only on the entities per rank when cutoffs shrink with the entity size, so the
measured halo(n) is reused at n = N / P).
--weak M evaluates weak scaling instead: M entities per rank, the scene refined to P x M on P
ranks. Each rank's share is then this scene's cut into n / M pieces, whatever P; what grows
with P is the reductions' tree (2 ceil(log2 P) latencies each). The efficiency is the time of
one rank alone with M entities (no halo, no messages) over the time of a rank among P.

Per entity-step costs default to the paper-3d coarse level's run (docs/performance.md: loop
1,164 s on 2 threads, 16,786 steps; charge 110 s, plate 184 s, soil 739 s, contacts and other
131 s spread over all entities), times 1.55 (the 2-thread speed-up measured on paper-20cm) for
one core: SPH 2.35 us, FEM 1.36 us, DEM 0.99 us, plus 0.14 us each for contacts and the rest.
"""
import argparse
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

COST_S = {"sph": 2.35e-6, "fem": 1.36e-6, "dem": 0.99e-6}
COST_SHARED_S = 0.14e-6
# Bytes a halo entity carries per step: out (positions, velocities, radius / h, mass, id ...)
# and back (forces, torques). FEM: shared nodes' positions and velocities, their forces.
BYTES_OUT = {"sph": 96, "dem": 96, "fem": 48}
BYTES_BACK = {"sph": 48, "dem": 48, "fem": 24}
REDUCTIONS_PER_STEP = 4  # stable step, energies, health and outflow counts, contact sums


def read(path):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersCore import vtkCellCenters
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    pd = grid.GetPointData()
    arrays = {pd.GetArrayName(i): vtk_to_numpy(pd.GetArray(i)) for i in range(pd.GetNumberOfArrays())}
    if grid.GetNumberOfCells() > 0 and grid.GetCell(0).GetNumberOfPoints() > 1:
        centres = vtkCellCenters()
        centres.SetInputData(grid)
        centres.Update()
        x = vtk_to_numpy(centres.GetOutput().GetPoints().GetData())
        lo, hi = grid.GetCell(0).GetBounds()[0::2], grid.GetCell(0).GetBounds()[1::2]
        size = max(h - l for l, h in zip(lo, hi))
        return "fem", x, size
    x = vtk_to_numpy(grid.GetPoints().GetData())
    if "smoothing_length" in arrays:
        return "sph", x, 2.0 * float(arrays["smoothing_length"].max())
    return "dem", x, 2.0 * float(arrays["radius"].max()) * 1.1


def entities(run_dir, frame):
    parts = []
    for pvd in sorted(Path(run_dir).glob("*.pvd")):
        files = [d.get("file") for d in ET.parse(pvd).getroot().iter("DataSet")]
        method, x, cutoff = read(Path(run_dir) / files[frame])
        parts.append((pvd.stem, method, x, cutoff))
    return parts


def rcb(x, w, ranks):
    """Boxes (lo, hi) and the owner of each point, by recursive coordinate bisection."""
    owner = np.zeros(len(x), dtype=np.int64)
    boxes = [None] * ranks

    def cut(idx, lo, hi, first, count):
        if count == 1:
            owner[idx] = first
            boxes[first] = (lo.copy(), hi.copy())
            return
        axis = int(np.argmax(hi - lo))
        left = count // 2
        order = idx[np.argsort(x[idx, axis], kind="stable")]
        cum = np.cumsum(w[order])
        k = int(np.searchsorted(cum, cum[-1] * left / count)) if len(order) else 0
        plane = x[order[k], axis] if len(order) else 0.5 * (lo[axis] + hi[axis])
        l_hi, r_lo = hi.copy(), lo.copy()
        l_hi[axis] = plane
        r_lo[axis] = plane
        cut(order[:k], lo, l_hi, first, left)
        cut(order[k:], r_lo, hi, first + left, count - left)

    lo, hi = x.min(axis=0) - 1e-9, x.max(axis=0) + 1e-9
    cut(np.arange(len(x)), lo, hi, 0, ranks)
    return boxes, owner


def decompose(parts, ranks, ghost_cost=0.0):
    x = np.concatenate([p[2] for p in parts])
    method = np.concatenate([[p[1]] * len(p[2]) for p in parts])
    cutoff = np.concatenate([np.full(len(p[2]), p[3]) for p in parts])
    w = np.array([COST_S[m] for m in method]) + COST_SHARED_S
    boxes, owner = rcb(x, w, ranks)
    out = []
    for r, (lo, hi) in enumerate(boxes):
        d = np.sqrt((np.maximum(0, np.maximum(lo - x, x - hi)) ** 2).sum(axis=1))
        halo = (owner != r) & (d <= cutoff)
        bytes_ = sum(BYTES_OUT[m] + BYTES_BACK[m] for m in method[halo])
        cost = float(w[owner == r].sum() + ghost_cost * w[halo].sum())
        out.append({"owned": int((owner == r).sum()), "cost_s": cost,
                    "halo": int(halo.sum()), "bytes": int(bytes_),
                    "neighbours": len(set(owner[halo].tolist()))})
    return out, float(w.sum())


def step_time(ranks_info, total_cost, ranks, latency, bandwidth, scale=1.0):
    worst = 0.0
    for r in ranks_info:
        comm = 2 * r["neighbours"] * latency + r["bytes"] * scale / bandwidth if ranks > 1 else 0
        worst = max(worst, r["cost_s"] * scale + comm)
    reduce = REDUCTIONS_PER_STEP * 2 * math.ceil(math.log2(ranks)) * latency if ranks > 1 else 0
    return worst + reduce


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--frame", type=int, default=0)
    ap.add_argument("--ranks", default="2,4,8,16,32,64,128,256,512,1024")
    ap.add_argument("--latency-us", type=float, default=0.25)
    ap.add_argument("--bandwidth-gbs", type=float, default=6.0)
    ap.add_argument("--ghost-cost", type=float, default=0.5,
                    help="a ghost's cost as a fraction of an owned entity's (default 0.5)")
    ap.add_argument("--scale", type=float, help="entities of a uniformly refined scene")
    ap.add_argument("--weak", type=float, help="weak scaling: entities per rank")
    a = ap.parse_args()
    parts = entities(a.run_dir, a.frame)
    n = sum(len(p[2]) for p in parts)
    lat, bw = a.latency_us * 1e-6, a.bandwidth_gbs * 1e9
    print(f"{a.run_dir}: {n} entities (" + ", ".join(
        f"{name} {m} {len(x)}, cutoff {c * 1e3:.0f} mm" for name, m, x, c in parts) + ")")
    print(f"latency {a.latency_us} us, bandwidth {a.bandwidth_gbs} GB/s, ghost cost "
          f"{a.ghost_cost}" +
          (f"; scaled to {a.scale:.0f} entities" if a.scale else ""))
    print("ranks  P_model  owned/rank  halo/rank (max)  halo/owned  neighbours (max)  "
          "MB/step (max rank)  step ms  efficiency")
    _, total = decompose(parts, 1)
    if a.weak:
        return weak(parts, n, total, a, lat, bw)
    target = a.scale or n
    for p in [int(v) for v in a.ranks.split(",")]:
        # Refined scene on P ranks = this scene at the same entities per rank.
        p_here = max(1, round(p * n / target))
        info, _ = decompose(parts, p_here, a.ghost_cost)
        factor = target / n * p_here / p  # work per rank relative to this scene's
        t1 = total * target / n
        tp = step_time(info, total, p, lat, bw, scale=factor)
        owned = np.mean([r["owned"] for r in info])
        halo = max(r["halo"] for r in info)
        print(f"{p:5d}  {p_here:7d}  {owned * factor:10.0f}  {halo:15d}  "
              f"{np.mean([r['halo'] for r in info]) / owned:10.2f}  "
              f"{max(r['neighbours'] for r in info):16d}  "
              f"{max(r['bytes'] for r in info) / 1e6:18.3f}  {tp * 1e3:7.3f}  "
              f"{t1 / (p * tp):10.2f}")
    return 0


def weak(parts, n, total, a, lat, bw):
    """Weak scaling at a.weak entities per rank (see the module's docstring)."""
    pieces = max(2, round(n / a.weak))
    info, _ = decompose(parts, pieces, a.ghost_cost)
    factor = a.weak / (n / pieces)  # work per rank relative to this scene's pieces
    t1 = total * a.weak / n  # one rank alone: its entities, no halo, no messages
    owned = np.mean([r["owned"] for r in info])
    print(f"weak scaling at {a.weak:.0f} entities per rank (this scene cut into {pieces} "
          f"pieces: halo/owned {np.mean([r['halo'] for r in info]) / owned:.2f}, at most "
          f"{max(r['neighbours'] for r in info)} neighbours)")
    print("ranks  entities  step ms  efficiency")
    for p in [int(v) for v in a.ranks.split(",")]:
        tp = step_time(info, total, p, lat, bw, scale=factor)
        print(f"{p:5d}  {p * a.weak:8.3g}  {tp * 1e3:7.3f}  {t1 / tp:10.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
