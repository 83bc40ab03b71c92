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
/usr/bin/python3 - "$TMP/counts" "$TMP/run/summary.json" <<'PY'
import json, sys
counts = dict(line.split() for line in open(sys.argv[1]))
s = json.load(open(sys.argv[2]))
steps = s["steps"]
print(f"steps={steps} threads={s['run']['threads']} " + " ".join(
    f"{k}_per_step={int(v) / steps:.2f}" for k, v in counts.items()))
PY
