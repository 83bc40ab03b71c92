#!/bin/bash
# Runs the two-sphere Hertz-Mindlin collision (in.hertz_pair) in LIGGGHTS-PUBLIC 3.8.0 (Debian
# package `liggghts`) and writes the force-time curves that
# tests/verification/dem_liggghts/test_liggghts_force_time.py compares crater against.
# Usage: run.sh [OUT_CSV]   (default: tests/data/liggghts_hertz_pair_3d.csv in the repository)
# Cases: head_on (vn = 1 m/s, vt = 0) and oblique (vn = 1 m/s, vt = 1 m/s relative, 45 deg).
# Fixed step dt = 1e-8 s (0.45 % of the Rayleigh step 2.2227e-6 s), gap 1e-6 m, 1750 steps;
# the dump is written every step and every EVERY-th step (10: 1e-7 s) is kept in the CSV.
# Columns: case, step, time_s, fn_N, ft_N, overlap_m, with
#   n  = (x1 - x2)/|x1 - x2|  (from grain 2 to grain 1), t = (n_y, -n_x, 0) (~ +y)
#   fn = F1 . n  (> 0 repulsive),  ft = F1 . t,  overlap = R1 + R2 - |x1 - x2|
# F1 the total force on grain 1 (id 1, the one at -x), which is the contact force (no gravity).
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
OUT="${1:-$ROOT/tests/data/liggghts_hertz_pair_3d.csv}"
DT=1.0e-8; STEPS=1750; GAP=1.0e-6; EVERY=10
LIGGGHTS=${LIGGGHTS:-$(command -v liggghts || command -v lmp_auto)}
WORK=$(mktemp -d /tmp/liggghts_hertz_pair.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
# (LIGGGHTS writes log.liggghts into the working directory even for -h)
VERSION=$(cd "$WORK" && echo | "$LIGGGHTS" -h 2>/dev/null | sed -n 's/.*(Version \([^,]*\),.*/\1/p' | head -1 || true)
for c in "head_on 0.0" "oblique 1.0"; do
  set -- $c
  mkdir -p "$WORK/$1"
  (cd "$WORK/$1" && "$LIGGGHTS" -in "$HERE/in.hertz_pair" -log log.lammps -screen none \
      -var vn 1.0 -var vt "$2" -var gap $GAP -var dt $DT -var steps $STEPS -var every 1)
done
/usr/bin/python3 - "$WORK" "$OUT" "$VERSION" "$DT" "$EVERY" <<'PY'
import math, sys
work, out, version, dt, every = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]), int(sys.argv[5])

def frames(path):
    """Yields (step, {id: row}) from a LIGGGHTS `dump custom` file."""
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: TIMESTEP"):
            step = int(lines[i + 1]); n = int(lines[i + 3])
            cols = lines[i + 8].split()[2:]
            rows = {}
            for line in lines[i + 9:i + 9 + n]:
                v = dict(zip(cols, map(float, line.split())))
                rows[int(v["id"])] = v
            yield step, rows
            i += 9 + n
        else:
            i += 1

with open(out, "w") as f:
    f.write(f"# {version} (Debian 12 package liggghts), pair_style gran model hertz "
            "tangential history: two spheres R = 2.5 mm, rho = 1920 kg/m^3, E = 69.6 GPa, "
            "nu = 0.2, mu = 0.84, e = 0.5, no gravity, gap 1e-6 m, vn = 1 m/s relative; "
            f"oblique: vt = 1 m/s relative; dt = {dt:g} s, every {every}th step kept\n")
    f.write("# regenerate: bench/peers/liggghts_hertz_pair/run.sh "
            "(deck bench/peers/liggghts_hertz_pair/in.hertz_pair)\n")
    f.write("# fn = F1.n (n = (x1-x2)/|x1-x2|, > 0 repulsive), ft = F1.t (t = (n_y, -n_x, 0)), "
            "F1 = force on grain 1 (at -x); overlap = R1 + R2 - |x1-x2|\n")
    f.write("case,step,time_s,fn_N,ft_N,overlap_m\n")
    for case in ("head_on", "oblique"):
        for step, a in frames(f"{work}/{case}/dump.pair"):
            if step % every:
                continue
            p, q = a[1], a[2]
            d = [p["x"] - q["x"], p["y"] - q["y"], p["z"] - q["z"]]
            dist = math.sqrt(sum(c * c for c in d))
            n = [c / dist for c in d]
            t = [n[1], -n[0], 0.0]
            fvec = [p["fx"], p["fy"], p["fz"]]
            fn = sum(a_ * b_ for a_, b_ in zip(fvec, n))
            ft = sum(a_ * b_ for a_, b_ in zip(fvec, t))
            overlap = p["radius"] + q["radius"] - dist
            f.write(f"{case},{step},{step * dt:.10g},{fn:.10g},{ft:.10g},{overlap:.10g}\n")
print(f"wrote {out}")
PY
