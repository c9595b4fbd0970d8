#!/usr/bin/env bash
# Benchmark (not a test): set-up and build as scripts/setup.sh plus OpenFOAM (blockMesh),
# Google Benchmark and GNU time; then bench_core (core throughput, one thread, medians of
# repetitions) and Benchmark/benchmark.py (blockMesh vs BlockForge, GridQuality vs
# vtkMeshQuality, peak memory), which writes Benchmark/RESULTS.md.
# Usage: scripts/benchmark.sh [benchmark.py options, e.g. --quick]
# Environment: BLOCKFORGE_BUILD_DIR (default ./build), BENCH_REPETITIONS (default 5).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${BLOCKFORGE_BUILD_DIR:-$root/build}"
repetitions="${BENCH_REPETITIONS:-5}"

"$root/scripts/setup.sh" openfoam libbenchmark-dev time

log="$build/benchmark-build.log"
if ! cmake --build "$build" --target bench_core -j"$(nproc)" >"$log" 2>&1; then
  grep -E "error|Error" "$log" | head -40
  echo "blockforge benchmark: building bench_core failed (log: $log)" >&2
  exit 1
fi
bench=""
for candidate in "$build/bin/bench_core" "$build/Benchmark/bench_core"; do
  [ -x "$candidate" ] && bench="$candidate" && break
done
if [ -z "$bench" ]; then
  echo "blockforge benchmark: bench_core not built (is libbenchmark-dev installed?)" >&2
  exit 1
fi

echo "== bench_core: medians of $repetitions repetitions (one thread, in memory)"
json="$build/bench_core.json"
rm -f "$json"
# Console: the context lines and the medians only; all aggregates go to the JSON file.
"$bench" --benchmark_repetitions="$repetitions" --benchmark_report_aggregates_only=true \
  --benchmark_out="$json" --benchmark_out_format=json 2>&1 |
  grep -vE "_(mean|stddev|cv) |Library was built as DEBUG" || true
[ -s "$json" ] || { echo "blockforge benchmark: bench_core failed" >&2; exit 1; }

echo
echo "== benchmark.py: blockMesh vs BlockForge, GridQuality vs vtkMeshQuality, memory"
# shellcheck source=/dev/null
source "$build/blockforge-env.sh"
/usr/bin/python3 "$root/Benchmark/benchmark.py" --core-json "$json" "$@"
