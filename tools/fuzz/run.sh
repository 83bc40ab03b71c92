#!/usr/bin/env bash
# Builds a libFuzzer target with clang (ASan + UBSan + coverage) and fuzzes it.
#   tools/fuzz/run.sh TARGET SECONDS [extra libFuzzer flags...]
#   tools/fuzz/run.sh scenario 600
#   tools/fuzz/run.sh scenario merge      # add the new inputs that reach new edges to the corpus
#   tools/fuzz/run.sh scenario minimise   # rebuild the corpus: seeds + a minimal set (-merge=1)
# TARGET is the <name> of tests/fuzz/fuzz_<name>.cpp. The seeds are tests/fuzz/corpus/TARGET
# (read only while fuzzing); new interesting inputs go to build/fuzz/corpus/TARGET, and `merge`
# adds those reaching new edges to tests/fuzz/corpus/TARGET (do that before committing). Findings
# (crash-*, timeout-*, oom-*, leak-*) are written to build/fuzz/findings/TARGET/: report them,
# then move them into tests/fuzz/crashes/TARGET/ once fixed, so `make test` replays them.
# A dictionary tests/fuzz/TARGET.dict is used when present. Environment: BUILD_DIR (build/fuzz),
# JOBS (2), CC / CXX (clang / clang++).
set -euo pipefail

if [ $# -lt 2 ]; then
  sed -n '2,13p' "$0" >&2
  exit 2
fi
target=$1
seconds=$2
shift 2

root=$(cd "$(dirname "$0")/../.." && pwd)
build=${BUILD_DIR:-$root/build/fuzz}
jobs=${JOBS:-2}
corpus=$root/tests/fuzz/corpus/$target
work=$build/corpus/$target
dict=$root/tests/fuzz/$target.dict
findings=$build/findings/$target

if [ ! -f "$root/tests/fuzz/fuzz_$target.cpp" ]; then
  echo "run.sh: no tests/fuzz/fuzz_$target.cpp" >&2
  exit 2
fi
for tool in "${CC:-clang}" "${CXX:-clang++}"; do
  command -v "$tool" >/dev/null || {
    echo "run.sh: $tool not found (Debian: apt-get install clang libclang-rt-dev)" >&2
    exit 1
  }
done

CC=${CC:-clang} CXX=${CXX:-clang++} cmake -S "$root" -B "$build" -G Ninja \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCRATER_FUZZ=ON -DCRATER_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target "crater_fuzz_$target"
bin=$build/tests/fuzz/crater_fuzz_$target

mkdir -p "$corpus" "$work" "$findings"
dict_flag=()
[ -f "$dict" ] && dict_flag=(-dict="$dict")
export OMP_NUM_THREADS=1
# Leak checks stay on; OpenMP's thread pool is not a leak with one thread.
export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

if [ "$seconds" = merge ] || [ "$seconds" = minimise ]; then
  # merge: adds to the corpus the fuzzer's new inputs that reach new edges; the files already
  # there stay (small diffs). minimise: rebuilds it: the named seeds (seed-*) stay, of the
  # others only those reaching new edges. Edges, not hit counts (-use_counters=0), keep the
  # corpus at a few hundred small files; smallest inputs first.
  tmp=$(mktemp -d)
  if [ "$seconds" = merge ]; then
    cp "$corpus"/* "$tmp"/
  else
    find "$corpus" -maxdepth 1 -type f -name 'seed-*' -exec cp {} "$tmp"/ \;
  fi
  "$bin" -merge=1 -use_counters=0 -timeout=10 -rss_limit_mb=2048 "$@" "$tmp" "$corpus" "$work"
  [ "$seconds" = minimise ] && find "$corpus" -type f -delete
  cp -n "$tmp"/* "$corpus"/
  rm -rf "$tmp"
  echo "run.sh: $corpus holds $(ls "$corpus" | wc -l) inputs, $(cat "$corpus"/* | wc -c) bytes"
  exit 0
fi

cd "$findings"
exec "$bin" "$work" "$corpus" "${dict_flag[@]}" -max_total_time="$seconds" -timeout=10 \
  -rss_limit_mb=2048 -max_len=8192 -print_final_stats=1 -artifact_prefix="$findings/" "$@"
