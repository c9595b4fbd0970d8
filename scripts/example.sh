#!/usr/bin/env bash
# The main job on the bundled default example: set-up, build, then the whole pipeline
# (point data -> template -> block model -> optimized control points (BlockOptimizer;
# --no-optimize skips it) -> transfinite grid -> quality), writing the grid
# to out/<template>.vtm (plus its pieces in out/<template>/) and printing a quality summary.
# Default: the O-grid template Templates/axial_passage_oh.yaml on the distributor's point
# data (-i Data/distributor/BladeGen.inf), written to out/axial_passage_oh.vtm.
# Usage: scripts/example.sh [template.yaml] [-i input] [-p NAME=EXPR ...] [-d DENSITY]
#          [--no-optimize]
#   A template given without -i is applied without input (templates without inputs);
#   -i alone replaces the default input of the default template.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${BLOCKFORGE_BUILD_DIR:-$root/build}"
"$root/scripts/setup.sh"

template="$root/Templates/axial_passage_oh.yaml"
input=("-i" "$root/Data/distributor/BladeGen.inf")
if [ $# -gt 0 ] && [[ "$1" != -* ]]; then
  template="$1"
  input=()
  shift
fi
for argument in "$@"; do
  case "$argument" in
    -i | --input | --input=*) input=() ;;
  esac
done
name=$(basename "$template" .yaml)
# shellcheck source=/dev/null
source "$build/blockforge-env.sh"
exec /usr/bin/python3 -m blockforge "$template" ${input[@]+"${input[@]}"} -o "$root/out/$name.vtm" "$@"
