"""A heap drained from a plate, as Zhou et al. 2002 form theirs; shared by
test_drained_heap_vs_liggghts.py and bench/peers/liggghts_drained_heap/run.py, and a study
that docs/validation.md, "DEM: angle of repose", quotes (about 2 minutes on 2 threads):

    CRATER_BIN=build/release/bin/crater /usr/bin/python3 \\
        tests/verification/dem_repose/drained_heap.py [mu=0.84] [rolling=0.02] [seed=7]

Spheres as repose_case.py's (same material, springs, rolling resistance, floor friction) are
laid on a jittered lattice of pitch 1.1 d, 27 x 22 x 27, in a box 30 d x 30 d with walls on
every side, and settle for 0.6 s. Then the side walls go (each stage is a new run from the last
state) and the domain's box becomes the plate: the floor is the only wall, and a sphere whose
centre passes the plate's edge is removed (domain.outflow = "remove"). After 2.5 s and 0.5 s
more, a pyramid of four flanks is left. Its angle: the highest sphere top in bins of width d
along x (and along z) within a strip |other axis| < 0.2 x the half-width, a line fitted between
20 % and 80 % of the apex height, on both axes.
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lib"))
from crater_test import SOURCE_DIR, read_pvd, read_vtu, run_scenario, scratch  # noqa: E402
from repose_case import (D, R_MAX, R_MIN, ROLLING, fitted_angle, scenario,  # noqa: E402
                         zhou_angle)

HALF = 0.15  # the plate's half-width [m]
# LIGGGHTS' heaps (bench/peers/liggghts_drained_heap/run.py writes them, the tests read them).
LIGGGHTS_HEAPS = SOURCE_DIR / "tests" / "data" / "liggghts_drained_heap.json"
LAYERS = 22
SETTLE_S, DRAIN_S = 0.6, (2.5, 0.5)  # the walled settling, then the stages on the bare plate


PITCH = 1.1 * D  # the lattice's


def lattice(seed, depth=None):
    """The settling's start: [(centre [m], radius [m])], y up, the plate's centre at x = z = 0;
    `depth` rows along z (default: as many as along x, the square plate)."""
    rng = np.random.default_rng(seed)
    n = int((2 * HALF - D) / PITCH) + 1
    nz = depth or n
    out = []
    for i in range(n):
        for j in range(LAYERS):
            for k in range(nz):
                c = np.array([(i - (n - 1) / 2) * PITCH, 0.6 * D + j * PITCH,
                              (k - (nz - 1) / 2) * PITCH])
                out.append((c + rng.uniform(-0.05 * D, 0.05 * D, 3), rng.uniform(R_MIN, R_MAX)))
    return out


def profile(points, radius, axis):
    """(bin centre |x| [m], highest sphere top [m]) in bins of width d along `axis` (0 or 2),
    within the strip |other axis| < 0.2 HALF."""
    other = 2 - axis
    sel = np.abs(points[:, other]) < 0.2 * HALF
    x = np.abs(points[sel, axis])
    top = points[sel, 1] + radius[sel]
    b = (x / D).astype(int)
    bins = np.unique(b)
    return (bins + 0.5) * D, np.array([top[b == k].max() for k in bins])


def flank(points, radius, axis):
    """(flank angle [deg], apex height [m]) along `axis`."""
    angle, apex, _ = fitted_angle(*profile(points, radius, axis))
    return angle, apex


def _run(d, mu, rolling, grains, end, walls, outflow, threads):
    (d / "case.toml").write_text(scenario(mu, grains, end, half=HALF, walls=walls,
                                          rolling=rolling, outflow=outflow))
    summary = run_scenario(d / "case.toml", d / "out", threads=threads, timeout=3600)
    _, frame = read_pvd(d / "out" / "heap.pvd")[-1]
    points, arrays, _, _ = read_vtu(d / "out" / frame)
    return list(zip(points, arrays["radius"], arrays["velocity"])), points, arrays, summary


def drain(mu=0.84, rolling=ROLLING, seed=7, threads=2, name=None):
    """Settles and drains the heap; returns one dict per drained stage: spheres left, flank
    angles [deg] along x and z, apex [m], kinetic energy [J]."""
    d = scratch(name or f"dem_repose_drained_mu{mu}_r{rolling}_s{seed}")
    grains = [(c, r, np.zeros(3)) for c, r in lattice(seed)]
    sides = ["bottom", "left", "right", "back", "front"]
    grains, *_ = _run(d, mu, rolling, grains, SETTLE_S, sides, "stop", threads)
    stages = []
    for end in DRAIN_S:
        grains, points, arrays, summary = _run(d, mu, rolling, grains, end, ["bottom"],
                                               "remove", threads)
        angles = [flank(points, arrays["radius"], axis) for axis in (0, 2)]
        stages.append({"spheres": len(grains), "flanks_deg": [a for a, _ in angles],
                       "apex_m": angles[0][1],
                       "kinetic_j": summary["energy"]["final"]["kinetic_j"]})
    return stages


def main(mu=0.84, rolling=ROLLING, seed=7, threads=2):
    for end, s in zip(DRAIN_S, drain(mu, rolling, seed, threads)):
        print(f"after {end} s more: {s['spheres']} spheres, flanks "
              + " / ".join(f"{a:.1f}" for a in s["flanks_deg"])
              + f" deg, apex {s['apex_m'] * 100:.1f} cm, kinetic energy {s['kinetic_j']:.1e} J",
              flush=True)
    print(f"Zhou et al. 2002 Eq. 5: {zhou_angle(mu, rolling=rolling):.1f} deg")


if __name__ == "__main__":
    kw = dict(a.split("=", 1) for a in sys.argv[1:])
    main(**{k: (int(v) if k in ("seed", "threads") else float(v)) for k, v in kw.items()})
