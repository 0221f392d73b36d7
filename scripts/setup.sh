#!/usr/bin/env bash
# Installs the Debian packages the project needs (only those missing), then configures and builds
# the project in Release into build/. Sourced by map-default.sh and test.sh; safe to run again.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${MULTIBIN_BUILD_DIR:-$root/build}

source "$root/scripts/install-packages.sh"
# The build, plus matplotlib for elevation-mapper's figures.
install_missing_packages "${multibin_build_packages[@]}" python3-matplotlib

cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DMULTIBIN_REQUIRE_PYTHON=ON >/dev/null  # the packages above hold all it needs
cmake --build "$build_dir" -j "$(nproc)"
