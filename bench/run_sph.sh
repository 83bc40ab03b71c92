#!/bin/bash
# SPH whole-run benchmarks (docs/performance.md): bench/run_sph.sh [CASE ...]; environment and
# output as bench/run_scenarios.sh. Default cases: tnt2d-10k tnt2d-100k tnt3d-65k.
HERE="$(cd "$(dirname "$0")" && pwd)"
[ $# -gt 0 ] || set -- tnt2d-10k tnt2d-100k tnt3d-65k
exec "$HERE/run_scenarios.sh" "$@"
