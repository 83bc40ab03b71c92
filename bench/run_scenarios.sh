#!/bin/bash
# Whole-run benchmarks of the crater binary (figures: docs/performance.md).
#
# Usage:
#   bench/run_scenarios.sh CASE ...              # e.g. tnt2d-10k dem3d-45k
#   bench/run_scenarios.sh --list                # the cases with file, steps and --set overrides
#   bench/run_scenarios.sh --file F.toml --steps S [--name NAME] [--set key=VALUE ...]  # ad hoc
#   bench/run_sph.sh, bench/run_dem.sh           # the SPH and the DEM cases
# Environment:
#   CRATER=build/release/bin/crater   the binary
#   THREADS="1 2"                     thread counts (crater run --threads N)
#   REPS=3                            repetitions per configuration (median reported)
#   KEEP=0                            1: keep the run directories (printed)
#
# Each repetition runs
#   crater run FILE --out TMPDIR/run --force --quiet --threads N --set output.vtu=false \
#              --set time.max_steps=STEPS [--set ...]
# and reads summary.json: parts[0].count, steps, run.wall_time_s, run.loop_time_s. It prints
#   particle_steps_per_s = particles x steps / run.wall_time_s
#   loop_particle_steps_per_s = particles x steps / run.loop_time_s
# (for FEM parts "particles" are the elements: element-steps per second)
# and the whole-process wall time (exec to exit, measured here). run.wall_time_s includes the
# setup (lattice or packing, first neighbour list and forces, summary); run.loop_time_s is the
# time loop alone, what LAMMPS and LIGGGHTS print as "Loop time" (the peers' figures). The DEM
# cases run the peers' 2000 steps. steal_s is the CPU time the hypervisor took from this VM
# during the repetition (all CPUs); repetitions with a large steal_s are not representative.
# The last line of each configuration is
#   case=... threads=N particles=P steps=S particle_steps_per_s=<median>
#            loop_particle_steps_per_s=<median> process_s=<median>
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/.." && pwd)"
CRATER=${CRATER:-$ROOT/build/release/bin/crater}
THREADS=${THREADS:-"1 2"}
REPS=${REPS:-3}
KEEP=${KEEP:-0}
PY=${PY:-/usr/bin/python3}
SC="$HERE/scenarios"

# name | file | steps | --set overrides (space separated key=value)
CASES=(
  "tnt2d-10k|$SC/sph_tnt_2d.toml|1500|parts.charge.spacing_m=0.0018"
  "tnt2d-100k|$SC/sph_tnt_2d.toml|200|parts.charge.spacing_m=0.00056"
  "tnt3d-65k|$SC/sph_tnt_3d.toml|60|parts.charge.spacing_m=0.004"
  "tnt3d-34k|$SC/sph_tnt_3d.toml|100|parts.charge.spacing_m=0.005"
  "dambreak2d|$SC/sph_dam_break_2d.toml|500|"
  "dem3d-45k|$SC/dem_bed_3d.toml|2000|"
  "dem2d-45k|$SC/dem_bed_2d.toml|2000|"
  "dem2d-160k|$SC/dem_bed_2d.toml|300|parts.bed.region.max_m=[2.0,2.0] domain.max_m=[2.0,2.4]"
  "fem-plate-16k|$SC/fem_plate_2d.toml|1000|"
  "fem-block-104k|$SC/fem_block_3d.toml|100|"
)

median() {
  printf '%s\n' "$@" | sort -g |
    awk '{a[NR]=$1} END{ if (NR%2) print a[(NR+1)/2]; else printf "%.6g\n", (a[NR/2]+a[NR/2+1])/2 }'
}
now() { date +%s.%N; }
# CPU time stolen by the hypervisor so far, all CPUs, in clock ticks (/proc/stat "cpu" field 9)
steal_ticks() { awk '/^cpu /{print $9}' /proc/stat; }
TCK=$(getconf CLK_TCK)

# run_case NAME FILE STEPS [key=value ...]
run_case() {
  local name=$1 file=$2 steps=$3
  shift 3
  local sets=(--set output.vtu=false --set "time.max_steps=$steps")
  local kv
  for kv in "$@"; do sets+=(--set "$kv"); done
  local th r tmp out t0 t1 started line pss=() proc=() lps=() parts="" nsteps="" wall p status allc thr tsim loop lp
  for th in $THREADS; do
    pss=(); proc=(); lps=()
    echo "# case=$name threads=$th file=${file#"$ROOT"/} steps=$steps sets=[$*] load: $(cut -d' ' -f1-3 /proc/loadavg)"
    for r in $(seq 1 "$REPS"); do
      # crater owns its run directory (it refuses one holding files it did not write): the run
      # goes into a fresh subdirectory, its console output beside it.
      tmp=$(mktemp -d /tmp/crater_bench.XXXXXX)
      out="$tmp/run"
      t0=$(now)
      local started
      started=$(date -u +%H:%M:%S)
      local st0
      st0=$(steal_ticks)
      if ! "$CRATER" run "$file" --out "$out" --force --quiet --threads "$th" "${sets[@]}" \
        > "$tmp/stdout.txt" 2>&1; then
        echo "ERROR: crater run failed (run directory $out):" >&2
        cat "$tmp/stdout.txt" >&2
        return 1
      fi
      t1=$(now)
      # particles steps wall_s pss status (and all parts' counts)
      line=$("$PY" - "$out/summary.json" <<'PYEOF'
import json, sys
s = json.load(open(sys.argv[1]))
n = s["parts"][0]["count"]
st = s["steps"]
w = s["run"]["wall_time_s"]
loop = s["run"]["loop_time_s"]
allc = "+".join(str(p["count"]) for p in s["parts"]) if len(s["parts"]) > 1 else "-"
print(n, st, w, "%.6g" % (n * st / w), s["status"], allc, s["run"]["threads"], "%.4g" % s["time_s"],
      loop, "%.6g" % (n * st / loop))
PYEOF
)
      read -r parts nsteps wall p status allc thr tsim loop lp <<< "$line"
      if [ "$status" != completed ] || [ "$nsteps" != "$steps" ] || [ "$thr" != "$th" ]; then
        echo "ERROR: status=$status steps=$nsteps (wanted $steps) threads=$thr; see $out" >&2
        return 1
      fi
      local ps stolen
      ps=$(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.3f", b-a}')
      stolen=$(awk -v a="$st0" -v b="$(steal_ticks)" -v t="$TCK" 'BEGIN{printf "%.2f", (b-a)/t}')
      echo "rep=$r start=$started threads=$th particles=$parts steps=$nsteps wall_time_s=$wall loop_time_s=$loop process_s=$ps sim_time_s=$tsim steal_s=$stolen particle_steps_per_s=$p loop_particle_steps_per_s=$lp$([ "$allc" = - ] || echo " part_counts=$allc")"
      pss+=("$p"); proc+=("$ps"); lps+=("$lp")
      if [ "$KEEP" = 1 ]; then echo "# kept $tmp"; else rm -rf "$tmp"; fi
    done
    echo "case=$name threads=$th particles=$parts steps=$steps particle_steps_per_s=$(median "${pss[@]}") loop_particle_steps_per_s=$(median "${lps[@]}") process_s=$(median "${proc[@]}")"
  done
}

lookup() {
  local c
  for c in "${CASES[@]}"; do
    if [ "${c%%|*}" = "$1" ]; then echo "$c"; return 0; fi
  done
  echo "unknown case '$1' (bench/run_scenarios.sh --list)" >&2
  return 1
}

[ -x "$CRATER" ] || { echo "no crater binary at $CRATER (cmake --build build/release --target crater_cli)" >&2; exit 1; }
echo "# crater: $("$CRATER" --version 2>/dev/null | head -1) ($CRATER), $(date -u +%Y-%m-%dT%H:%M:%SZ), $(nproc) cores, OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-unset}"

if [ "${1:-}" = --list ]; then
  printf '%s\n' "${CASES[@]}" | tr '|' '\t'
  exit 0
fi

if [ "${1:-}" = --file ]; then
  file=$2; steps=""; name=custom; sets=()
  shift 2
  while [ $# -gt 0 ]; do
    case $1 in
      --steps) steps=$2; shift 2 ;;
      --name) name=$2; shift 2 ;;
      --set) sets+=("$2"); shift 2 ;;
      *) echo "unknown option $1" >&2; exit 2 ;;
    esac
  done
  [ -n "$steps" ] || { echo "--steps is required" >&2; exit 2; }
  run_case "$name" "$file" "$steps" "${sets[@]}"
  exit 0
fi

[ $# -gt 0 ] || { echo "usage: bench/run_scenarios.sh CASE ... (--list shows them)" >&2; exit 2; }
for name in "$@"; do
  IFS='|' read -r n file steps setstr <<< "$(lookup "$name")"
  read -r -a sets <<< "$setstr"
  run_case "$n" "$file" "$steps" "${sets[@]}"
done
