#!/bin/bash
# FEM element-loop benchmarks (bench/bench_fem_kernels.cpp; figures: docs/performance.md):
#   bench/run_fem.sh [FILTER]        # default FILTER ^BM_Fem (all three kernels)
# Builds crater_bench_kernels if needed (configuring BUILD with the release preset if it has no
# build.ninja), then runs the kernels at each thread count through OMP_NUM_THREADS.
# Environment:
#   BUILD=build/release   build directory (cmake --preset release -B BUILD)
#   THREADS="1 2"         thread counts (OMP_NUM_THREADS)
#   REPS=3                repetitions per kernel and thread count (median reported)
#   MIN_TIME=1            seconds per repetition (--benchmark_min_time)
#   JOBS=2                build parallelism
# One line per kernel and thread count:
#   case=BM_... threads=N elements=E element_steps_per_s=<median> cv=<coefficient of variation>
#   yielding=<share of elements yielding in a step> ms_per_step=<median>
# element_steps_per_s is Google Benchmark's items_per_second (elements x iterations / wall
# time); one iteration = compute_internal_forces + the central-difference node update.
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/.." && pwd)"
BUILD=${BUILD:-$ROOT/build/release}
THREADS=${THREADS:-"1 2"}
REPS=${REPS:-3}
MIN_TIME=${MIN_TIME:-1}
JOBS=${JOBS:-2}
PY=${PY:-/usr/bin/python3}
FILTER=${1:-^BM_Fem}

cd "$ROOT"
[ -f "$BUILD/build.ninja" ] || cmake --preset release -B "$BUILD" > /dev/null
cmake --build "$BUILD" -j"$JOBS" --target crater_bench_kernels > /dev/null
BIN="$BUILD/bench/crater_bench_kernels"

echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) $(nproc) cores, $BIN, filter=$FILTER reps=$REPS min_time=${MIN_TIME}s OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-unset}"
for th in $THREADS; do
  echo "# threads=$th load: $(cut -d' ' -f1-3 /proc/loadavg)"
  json=$(mktemp /tmp/crater_bench_fem.XXXXXX)
  OMP_NUM_THREADS=$th "$BIN" --benchmark_filter="$FILTER" --benchmark_min_time="$MIN_TIME" \
    --benchmark_repetitions="$REPS" --benchmark_report_aggregates_only=true \
    --benchmark_format=json > "$json"
  "$PY" - "$json" "$th" <<'PYEOF'
import json, sys
runs = json.load(open(sys.argv[1]))["benchmarks"]
agg = {}
for r in runs:
    agg.setdefault(r["run_name"], {})[r.get("aggregate_name", "single")] = r
for name, a in agg.items():
    med = a.get("median", a.get("single"))
    cv = a.get("cv", {}).get("items_per_second", float("nan"))
    print("case=%s threads=%s elements=%d element_steps_per_s=%.4g cv=%.3f yielding=%.3f "
          "ms_per_step=%.3f" % (name.replace("/real_time", ""), sys.argv[2], med["elements"],
                                med["items_per_second"], cv, med["yielding"], med["real_time"]))
PYEOF
  rm -f "$json"
done
