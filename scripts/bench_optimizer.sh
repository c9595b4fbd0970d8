#!/usr/bin/env bash
# Benchmark of the BlockOptimizer (not a test): both blade-passage templates on every
# machine in Data/, MinAngle classes before and after, time of the automatic run in process
# (median of 5, wall and CPU) and evaluations per second, the Laplacian / block-score
# baselines on the same control points, and the whole native command line (`blockforge
# TEMPLATE -i INPUT -o grid.xyz`, median of 5) with and without the optimizer. Writes
# Benchmark/OPTIMIZER.md and doc/optimizer_classes.png (the paper's Fig. 12 layout).
# Usage: scripts/bench_optimizer.sh [bench_optimizer options, e.g. --repetitions 1]
# Environment: BLOCKFORGE_BUILD_DIR (default ./build), BENCH_REPETITIONS (default 5).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${BLOCKFORGE_BUILD_DIR:-$root/build}"
repetitions="${BENCH_REPETITIONS:-5}"
"$root/scripts/setup.sh" python3-matplotlib
cmake --build "$build" --target bench_optimizer blockforge -j"$(nproc)" >/dev/null
cases=()
for input in Data/distributor/BladeGen.inf Data/rotor37/turbogrid/BladeGen.inf \
  Data/compressor/rotor.inf Data/turbine/Info.txt; do
  [ -f "$root/$input" ] || continue
  for template in axial_passage_oh axial_passage_h; do
    cases+=("Templates/$template.yaml" "$input")
  done
done
cd "$root"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Median of numbers, one a line.
median() {
  sort -g | awk '{v[NR] = $1} END {
    if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}

# Median wall time and median CPU time (user + system) of a whole process, in seconds: the
# CPU time depends little on what else runs on the machine, the wall time does.
median_seconds() {
  local times=() cpus=() start end
  for ((r = 0; r < repetitions; ++r)); do
    start=$(date +%s.%N)
    /usr/bin/time -f '%U %S' -o "$work/cpu" "$@" >/dev/null
    end=$(date +%s.%N)
    times+=("$(echo "$end - $start" | bc -l)")
    cpus+=("$(awk '{print $1 + $2}' "$work/cpu")")
  done
  echo "$(printf '%s\n' "${times[@]}" | median) $(printf '%s\n' "${cpus[@]}" | median)"
}

process="$work/process.csv"
echo "template,input,optimize_seconds,no_optimize_seconds,optimize_cpu_seconds" >"$process"
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
for ((c = 0; c < ${#cases[@]}; c += 2)); do
  template=${cases[c]} input=${cases[c + 1]}
  read -r with with_cpu < <(median_seconds "$build/bin/blockforge" "$template" -i "$input" \
    -o "$work/grid.xyz")
  read -r without _ < <(median_seconds "$build/bin/blockforge" "$template" -i "$input" \
    -o "$work/grid.xyz" --no-optimize)
  name=$(basename "$template" .yaml)
  echo "$name,$input,$with,$without,$with_cpu" >>"$process"
done

{
  echo "# BlockOptimizer benchmark"
  echo
  echo "\`scripts/bench_optimizer.sh $*\` at commit $(git rev-parse --short HEAD), $(nproc) cores," \
    "load average $load_before before the command lines, $(cut -d' ' -f1-3 /proc/loadavg) at the end," \
    "$(date -u +%Y-%m-%d)."
  echo "Classes: cells per MinAngle class 0-20 / 20-40 / 40-60 / 60-80 / 80-90 degrees."
  echo "In process (\`bench_optimizer\`): the automatic run alone, median of $repetitions."
  echo
  "$build/bin/bench_optimizer" --repetitions "$repetitions" --csv "$work/optimizer.csv" "$@" \
    "${cases[@]}"
  echo
  echo "Whole process, the native command line \`blockforge TEMPLATE -i INPUT -o grid.xyz\`"
  echo "(read, template, optimizer, mesh, Plot3D write), median of $repetitions, wall time (and CPU"
  echo "time, user + system, with the optimizer):"
  echo
  echo "| case | with the optimizer | --no-optimize | the optimizer's share |"
  echo "|---|---|---|---|"
  tail -n +2 "$process" | while IFS=, read -r name input with without with_cpu; do
    printf '| %s, %s | %.2f s (%.2f s) | %.2f s | %.2f s |\n' "$name" "$input" "$with" \
      "$with_cpu" "$without" "$(echo "$with - $without" | bc -l)"
  done
  echo
  echo "Where the smallest angles are held, what was tried and what lifts them (the skewed"
  echo "distributions, on by default): [OPTIMIZER_LIMITS.md](OPTIMIZER_LIMITS.md)."
} >Benchmark/OPTIMIZER.md
cp "$work/optimizer.csv" Benchmark/optimizer.csv
cp "$process" Benchmark/optimizer_process.csv
/usr/bin/python3 Benchmark/optimizer_figure.py Benchmark/optimizer.csv doc/optimizer_classes.png \
  Benchmark/optimizer_process.csv
cat Benchmark/OPTIMIZER.md
