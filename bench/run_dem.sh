#!/bin/bash
# DEM whole-run benchmarks on the peers' scene (docs/performance.md): bench/run_dem.sh [CASE ...];
# environment and output as bench/run_scenarios.sh. Default cases: dem3d-45k dem2d-45k
# dem2d-160k.
HERE="$(cd "$(dirname "$0")" && pwd)"
[ $# -gt 0 ] || set -- dem3d-45k dem2d-45k dem2d-160k
exec "$HERE/run_scenarios.sh" "$@"
