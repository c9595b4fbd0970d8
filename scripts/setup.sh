#!/usr/bin/env bash
# Installs the Debian packages BlockForge needs (only those missing; quiet when all are
# there), then configures and builds it in ./build. Safe to run again.
# Usage: scripts/setup.sh [extra Debian packages...]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${BLOCKFORGE_BUILD_DIR:-$root/build}"

packages=(cmake g++ make pkg-config
  paraview paraview-dev python3-paraview python3-numpy libopenmpi-dev qtbase5-dev libutfcpp-dev
  libeigen3-dev libyaml-cpp-dev libmuparser-dev libgtest-dev libnlopt-cxx-dev xvfb
  openfoam cgns-convert libcgns-dev
  qttools5-dev qttools5-dev-tools qtxmlpatterns5-dev-tools "$@")
missing=()
for package in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
    missing+=("$package")
done
if ((${#missing[@]})); then
  echo "blockforge setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq >/dev/null
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

log="$build/setup.log"
mkdir -p "$build"
if ! cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >"$log" 2>&1; then
  cat "$log"
  echo "blockforge setup: configuration failed (log: $log)" >&2
  exit 1
fi
if ! cmake --build "$build" -j"$(nproc)" >>"$log" 2>&1; then
  grep -E "error|Error" "$log" | head -40
  echo "blockforge setup: build failed (log: $log)" >&2
  exit 1
fi
