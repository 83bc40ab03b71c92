#!/bin/bash
# OpenMP fork-joins and barriers per step of a whole run (docs/performance.md, "Barriers per
# step"): the synchronisation a step costs, which bounds the speed-up of small models.
#
# Usage:
#   bench/count_regions.sh SCENARIO [crater run options ...]
#   e.g. bench/count_regions.sh paper-20cm --set scenario.end_time_s=5e-4 --threads 2
# Environment:
#   CRATER=build/release/bin/crater                   the binary
#   SHIM=build/release/bench/libcrater_omp_regions.so  the counting library (bench/omp_regions)
#
# Runs `crater run SCENARIO --out TMPDIR --force --quiet ...` with the library preloaded (it
# forwards every call to libgomp unchanged) and prints, per step of the run (steps from
# summary.json; the setup's regions are included, so use a run of a few hundred steps or more):
#   forked       parallel regions that forked a team (each ends in a join: a barrier)
#   kept_serial  parallel regions whose `if` kept them on one thread (loops below parallel_min)
#   barrier      explicit barriers, summed over the threads
#   loop_end     barriers ending worksharing loops inside regions, summed over the threads
# and, with SITES=N, the N call sites that fork most per step (the function that holds the
# region, named by `nm -C` of the binary), with their kept-serial regions per step.
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/.." && pwd)"
CRATER=${CRATER:-$ROOT/build/release/bin/crater}
SHIM=${SHIM:-$ROOT/build/release/bench/libcrater_omp_regions.so}
[ $# -ge 1 ] || { sed -n '2,18p' "$0"; exit 2; }
[ -f "$SHIM" ] || { echo "no $SHIM: build the bench targets first (cmake --build build/release)"; exit 2; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
scenario=$1
shift
CRATER_OMP_COUNTS="$TMP/counts" LD_PRELOAD="$SHIM" \
  "$CRATER" run "$scenario" --out "$TMP/run" --force --quiet --set output.vtu=false "$@"
/usr/bin/python3 - "$TMP/counts" "$TMP/run/summary.json" "${SITES:-0}" "$CRATER" <<'PY'
import bisect, json, subprocess, sys
lines = [line.split() for line in open(sys.argv[1])]
counts = {l[0]: l[1] for l in lines if len(l) == 2}
s = json.load(open(sys.argv[2]))
steps = s["steps"]
print(f"steps={steps} threads={s['run']['threads']} " + " ".join(
    f"{k}_per_step={int(v) / steps:.2f}" for k, v in counts.items()))
top = int(sys.argv[3])
sites = [l for l in lines if l[0] == "site"]
if top > 0 and sites:
    symbols = {}  # object -> sorted [(address, name)]
    def name_of(obj, offset):
        if obj not in symbols:
            out = subprocess.run(["nm", "-C", "--defined-only", obj], capture_output=True,
                                 text=True).stdout.splitlines()
            table = []
            for row in out:
                parts = row.split(" ", 2)
                if len(parts) == 3 and parts[1] in "tTwW":
                    table.append((int(parts[0], 16), parts[2]))
            symbols[obj] = sorted(table)
        table = symbols[obj]
        k = bisect.bisect_right(table, (offset, chr(0x10FFFF))) - 1
        return table[k][1] if k >= 0 else "?"
    sites.sort(key=lambda l: -int(l[3]))
    print("forked/step kept/step  site")
    for _, offset, obj, fork, kept in sites[:top]:
        if obj == "?" or not obj.startswith("/"):  # the main program: the binary run
            obj = sys.argv[4]
        name = name_of(obj, int(offset, 16))
        print(f"{int(fork) / steps:11.2f} {int(kept) / steps:9.2f}  {name[:150]}")
PY
