#!/bin/bash
# The DEM peers on the scenes of bench/run_dem.sh, to run right after it (same machine state):
#   bench/run_dem_peers.sh [CASE ...]       default: dem3d-45k dem2d-45k dem2d-160k
# Environment:
#   PEERS=<repo>/../shared/peers   the peers' decks (README.md there: install, versions)
#   THREADS="1 2"                  MPI ranks (the Debian builds have no OpenMP)
#   REPS=3                         repetitions per configuration (median reported)
#   STEPS=2000                     timed steps (the peers' "Loop time": setup excluded)
#   CODES="liggghts lammps-hh lammps-hm"   which peers (those not installed are skipped)
# Prints per repetition, then per configuration
#   peer=CODE case=CASE ranks=N particles=P steps=S particle_steps_per_s=<median>
# Cases: dem3d-45k = in.dem3d (30 x 30 x 50 spheres), dem2d-45k = in.dem2d (300 x 150 disks),
# dem2d-160k = in.dem2d with nx = ny = 400 (crater's dem2d-160k: a 2 m x 2 m bed).
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
PEERS=${PEERS:-$(cd "$HERE/../.." && pwd)/shared/peers}
THREADS=${THREADS:-"1 2"}
REPS=${REPS:-3}
STEPS=${STEPS:-2000}
CODES=${CODES:-"liggghts lammps-hh lammps-hm"}
[ $# -gt 0 ] || set -- dem3d-45k dem2d-45k dem2d-160k
# shellcheck source=/dev/null
. "$PEERS/common.sh"

deck_args() {  # CASE -> dimension and -var overrides
  case $1 in
    dem3d-45k) echo "3" ;;
    dem2d-45k) echo "2" ;;
    dem2d-160k) echo "2 -var nx 400 -var ny 400" ;;
    *) echo "unknown case $1" >&2; exit 2 ;;
  esac
}

for case_name in "$@"; do
  read -r dim vars <<< "$(deck_args "$case_name")"
  for code in $CODES; do
    case $code in
      liggghts) bin=liggghts; deck="$PEERS/liggghts/in.dem${dim}d"; extra=() ;;
      lammps-hh) bin=lmp; deck="$PEERS/lammps/in.dem${dim}d"; extra=(-nocite -var model hh) ;;
      lammps-hm) bin=lmp; deck="$PEERS/lammps/in.dem${dim}d"; extra=(-nocite -var model hm) ;;
      *) echo "unknown peer $code" >&2; exit 2 ;;
    esac
    if ! command -v "$bin" > /dev/null; then
      echo "# peer=$code: $bin not installed, skipped"
      continue
    fi
    for np in $THREADS; do
      echo "# peer=$code case=$case_name ranks=$np load: $(cut -d' ' -f1-3 /proc/loadavg)"
      vals=()
      for r in $(seq 1 "$REPS"); do
        work=$(mktemp -d /tmp/crater_peer.XXXXXX)
        # shellcheck disable=SC2086
        (cd "$work" && $(mpi_prefix "$np") "$bin" "${extra[@]}" -log log -screen none -in "$deck" \
          -var steps "$STEPS" $vars > /dev/null)
        read -r loop steps atoms pss < <(parse_loop "$work/log")
        echo "rep=$r start=$(date -u +%H:%M:%S) loop_s=$loop particles=$atoms steps=$steps" \
          "particle_steps_per_s=$pss"
        vals+=("$pss")
        rm -rf "$work"
      done
      echo "peer=$code case=$case_name ranks=$np particles=$atoms steps=$steps" \
        "particle_steps_per_s=$(median "${vals[@]}")"
    done
  done
done
