#!/usr/bin/env bash
# Quick start 2: set up, build, and run the test suite (ctest over the GoogleTest programs).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/scripts/setup.sh"
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" -LE slow "$@"
