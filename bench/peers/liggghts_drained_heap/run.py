#!/usr/bin/python3
"""Runs the drained heap (in.drained_heap) in LIGGGHTS-PUBLIC 3.8.0 (Debian package `liggghts`)
for seeds 7, 8 and 9 and writes the heaps' flank angles that
tests/verification/dem_repose/test_drained_heap_vs_liggghts.py compares crater against.

Usage: /usr/bin/python3 bench/peers/liggghts_drained_heap/run.py [OUT_JSON]
(default tests/data/liggghts_drained_heap.json; 1-2.5 minutes per seed on one core, the
seeds run two at a time).

A variant, quoted in docs/validation.md ("DEM: angle of repose") and not checked by any test:
    /usr/bin/python3 bench/peers/liggghts_drained_heap/run.py --ridge N OUT_JSON
drains a ridge instead of the four-flanked pyramid: N lattice rows along z, periodic along z
(the deck's z walls left out), so that the heap is a slope between two flanks along x, as in a
slot with no front and rear walls. The flanks are measured as for the pyramid (the x profile
within |z| < 0.2 x the half-width); "flanks_deg" has that one number.

The lattice, the angle measurement and the material are drained_heap.py's and repose_case.py's;
the numbers LIGGGHTS needs are derived here as crater derives them (docs/theory.md, linear
spring): k_t = k_n 2(1 - nu)/(2 - nu), the dashpots c = 2 zeta sqrt(k m*) with zeta from the
restitution, passed as LIGGGHTS' gamma = c / m* (its hooke/stiffness multiplies by m*) for the
mean sphere (m* = m/2 between spheres, m against a wall; crater uses each pair's own m*, so
LIGGGHTS' dashpots differ from crater's by sqrt(m*_pair / m*_mean), at most 8 % over the radius
range), and the step 0.9 x 0.17 sqrt(m_min / max(k_n, k_t)) (crater's time.safety_factor times
its stiffness step).
"""
import json
import math
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
sys.path.insert(0, str(ROOT / "tests" / "lib"))
sys.path.insert(0, str(ROOT / "tests" / "verification" / "dem_repose"))
from drained_heap import (DRAIN_S, HALF, LIGGGHTS_HEAPS, PITCH, SETTLE_S, flank,  # noqa: E402
                          lattice)
from repose_case import KN, R_MAX, R_MIN, RHO, ROLLING, WALL_FRICTION  # noqa: E402

MU, NU, RESTITUTION, ROLLING_DAMPING, STEP_FRACTION, SAFETY = 0.84, 0.25, 0.4, 0.3, 0.17, 0.9
SEEDS = (7, 8, 9)


def variables(grains):
    kt = KN * 2 * (1 - NU) / (2 - NU)
    m_min = RHO * 4 / 3 * math.pi * min(r for _, r in grains)**3
    dt = SAFETY * STEP_FRACTION * math.sqrt(m_min / max(KN, kt))
    zeta = -math.log(RESTITUTION) / math.sqrt(math.pi**2 + math.log(RESTITUTION)**2)
    m = RHO * 4 / 3 * math.pi * (0.5 * (R_MIN + R_MAX))**3
    gamma = lambda k, m_eff: 2 * zeta * math.sqrt(k / m_eff)  # noqa: E731
    return {"kn": KN, "kt": kt, "gn_pp": gamma(KN, m / 2), "gn_pw": gamma(KN, m),
            "gt_pp": gamma(kt, m / 2), "gt_pw": gamma(kt, m), "mu": MU, "mw": WALL_FRICTION,
            "mr": ROLLING, "rd": ROLLING_DAMPING, "dt": dt, "half": HALF,
            "settle_steps": round(SETTLE_S / dt), "drain1_steps": round(DRAIN_S[0] / dt),
            "drain2_steps": round(DRAIN_S[1] / dt)}


def ridge_deck(directory):
    """in.drained_heap made periodic along z, without its z walls (--ridge)."""
    # One command per line (the deck continues long commands with "&").
    lines = (HERE / "in.drained_heap").read_text().replace("&\n", " ").splitlines()
    lines = [line.replace("boundary       f f f", "boundary       f f p") for line in lines
             if " wzl" not in line and " wzh" not in line]
    (directory / "in.drained_ridge").write_text("\n".join(lines) + "\n")
    return directory / "in.drained_ridge"


def run(seed, liggghts, work, ridge=None):
    d = work / f"seed{seed}"
    d.mkdir()
    grains = lattice(seed, depth=ridge)
    z_half = ridge * PITCH / 2 if ridge else HALF
    with open(d / "heap.data", "w") as f:
        f.write(f"drained heap, seed {seed}\n\n{len(grains)} atoms\n2 atom types\n\n"
                f"{-HALF} {HALF} xlo xhi\n-0.05 0.3 ylo yhi\n{-z_half} {z_half} zlo zhi\n\n"
                "Atoms\n\n")
        for i, (c, r) in enumerate(grains, 1):
            f.write(f"{i} 1 {2 * r!r} {RHO} {c[0]!r} {c[1]!r} {c[2]!r}\n")
    var = variables(grains)
    deck = ridge_deck(d) if ridge else HERE / "in.drained_heap"
    cmd = [liggghts, "-in", str(deck), "-log", "log.liggghts", "-screen", "none"]
    for k, v in var.items():
        cmd += ["-var", k, repr(v)]
    subprocess.run(cmd, cwd=d, check=True)
    stages = []
    for name in ("stage1", "stage2"):
        lines = (d / f"{name}.dump").read_text().splitlines()
        first = next(i for i, line in enumerate(lines) if line.startswith("ITEM: ATOMS")) + 1
        a = np.array([[float(v) for v in line.split()] for line in lines[first:]])
        angles = [flank(a[:, 1:4], a[:, 4], axis) for axis in ((0,) if ridge else (0, 2))]
        stages.append({"spheres": len(a), "flanks_deg": [round(x, 3) for x, _ in angles],
                       "apex_m": round(angles[0][1], 6)})
    return {"seed": seed, "stages": stages}, var


def main(out=LIGGGHTS_HEAPS, ridge=None):
    liggghts = shutil.which("liggghts") or shutil.which("lmp_auto")
    work = Path(tempfile.mkdtemp(prefix="liggghts_drained_heap."))
    try:
        with ThreadPoolExecutor(2) as pool:
            results = list(pool.map(lambda s: run(s, liggghts, work, ridge), SEEDS))
    finally:
        shutil.rmtree(work)
    doc = {"peer": "LIGGGHTS-PUBLIC 3.8.0 (Debian 12 package liggghts)",
           "deck": "bench/peers/liggghts_drained_heap/in.drained_heap",
           "variables": results[0][1], "runs": [r for r, _ in results]}
    if ridge:
        doc["ridge_rows"] = ridge
    Path(out).write_text(json.dumps(doc, indent=1) + "\n")
    for r, _ in results:
        print(f"seed {r['seed']}: " + "; ".join(
            f"{s['spheres']} spheres, flanks {' / '.join(f'{x:.1f}' for x in s['flanks_deg'])}"
            f" deg, apex {100 * s['apex_m']:.1f} cm" for s in r["stages"]))


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["--ridge"]:
        if len(args) != 3:
            sys.exit("usage: run.py --ridge ROWS OUT_JSON")
        main(args[2], ridge=int(args[1]))
    else:
        main(*args)
