#!/usr/bin/env bash
# Set-up and build as scripts/setup.sh, then the whole CTest suite (C++ unit tests,
# plain-Python tests through `import blockforge`, pvpython tests through paraview.simple).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${BLOCKFORGE_BUILD_DIR:-$root/build}"
"$root/scripts/setup.sh"
cd "$build"
ctest --output-on-failure -j"$(nproc)" "$@"
