#!/usr/bin/env bash
# The main job on the bundled default example: set-up, build, then the whole pipeline
# (template -> block model -> transfinite grid -> quality) on the default template,
# writing the grid to out/<template>.vtm and printing a quality summary.
# Usage: scripts/example.sh [template.yaml] [-p NAME=EXPR ...] [-d DENSITY]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${BLOCKFORGE_BUILD_DIR:-$root/build}"
"$root/scripts/setup.sh"

template="$root/Templates/cylinder_in_box.yaml"
if [ $# -gt 0 ] && [[ "$1" != -* ]]; then
  template="$1"
  shift
fi
name=$(basename "$template" .yaml)
# shellcheck source=/dev/null
source "$build/blockforge-env.sh"
exec /usr/bin/python3 -m blockforge "$template" -o "$root/out/$name.vtm" "$@"
