"""The triaxial test of several packings at 4-10 mm, at 30-75 mm (x 7.5, g / 7.5; the coarse
level's grains of paper-3d) and at 45-112.5 mm (x 11.25; its demo level's), the means and
scatters of docs/validation.md's table ("DEM: the bed's properties do not depend on grain
size"); test_grain_size.py runs seed 1 only. Not a test (--scales=1,11.25 runs only those;
study.json keeps the scales of earlier invocations):

    CRATER_BIN=build/release/bin/crater CRATER_SOURCE_DIR=$PWD PYTHONPATH=tests/lib \\
      CRATER_TEST_TMP=/tmp/crater-grain-size OMP_NUM_THREADS=1 \\
      /usr/bin/python3 tests/verification/dem_grain_size/grain_size_study.py 1 2 3

(about 5 minutes per run on one core beside other jobs; CRATER_TEST_TMP/grain_size_study/
study.json has the numbers).
"""
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from crater_test import scratch  # noqa: E402
from test_grain_size import triaxial  # noqa: E402

KEYS = ("phi_peak", "e1_peak", "phi_residual", "psi", "dilation_rate", "solid_fraction",
        "solid_fraction_interior", "grains")

if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if not a.startswith("--scales=")]
    scales = [a for a in sys.argv[1:] if a.startswith("--scales=")]
    LAMS = [float(x) for x in scales[-1][9:].split(",")] if scales else [1.0, 7.5, 11.25]
    seeds = [int(a) for a in args] or [1, 2, 3]
    work = scratch("grain_size_study")
    table = {}
    for lam in LAMS:
        rows = {seed: triaxial(work, lam, seed)[0] for seed in seeds}
        for seed, a in rows.items():
            print(f"x{lam:g} seed {seed}: " + ", ".join(f"{k} {a[k]:.4g}" for k in KEYS))
        v = np.array([[a[k] for k in KEYS] for a in rows.values()], dtype=float)
        mean, sd = v.mean(0), v.std(0, ddof=1) if len(v) > 1 else 0 * v[0]
        print(f"x{lam:g} mean: " + ", ".join(f"{k} {m:.4g} +- {d:.2g}"
                                            for k, m, d in zip(KEYS, mean, sd)))
        table[f"x{lam:g}"] = {"seeds": {str(s): a for s, a in rows.items()},
                              "mean": dict(zip(KEYS, mean.tolist())),
                              "sd": dict(zip(KEYS, np.atleast_1d(sd).tolist()))}
    old = work / "study.json"
    if old.exists():  # keep the scales of an earlier invocation (--scales=...)
        table = {**json.loads(old.read_text()), **table}
    old.write_text(json.dumps(table, indent=1))
