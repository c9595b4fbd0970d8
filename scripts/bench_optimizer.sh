#!/usr/bin/env bash
# Benchmark of the BlockOptimizer (not a test): both blade-passage templates on every
# machine in Data/, MinAngle classes before and after, time of the automatic run (median
# of 5), evaluations per second, and the Laplacian / block-score baselines on the same
# control points. Writes Benchmark/OPTIMIZER.md.
# Usage: scripts/bench_optimizer.sh [bench_optimizer options, e.g. --repetitions 1]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${BLOCKFORGE_BUILD_DIR:-$root/build}"
"$root/scripts/setup.sh"
cmake --build "$build" --target bench_optimizer -j"$(nproc)" >/dev/null
cases=()
for input in Data/distributor/BladeGen.inf Data/rotor37/turbogrid/BladeGen.inf \
  Data/compressor/rotor.inf Data/turbine/Info.txt; do
  [ -f "$root/$input" ] || continue
  for template in axial_passage_oh axial_passage_h; do
    cases+=("Templates/$template.yaml" "$input")
  done
done
cd "$root"
{
  echo "# BlockOptimizer benchmark"
  echo
  echo "\`scripts/bench_optimizer.sh $*\` at commit $(git rev-parse --short HEAD), $(nproc) cores, $(date -u +%Y-%m-%d)."
  echo "Classes: cells per MinAngle class 0-20 / 20-40 / 40-60 / 60-80 / 80-90 degrees."
  echo
  "$build/bin/bench_optimizer" "$@" "${cases[@]}"
} >Benchmark/OPTIMIZER.md
cat Benchmark/OPTIMIZER.md
