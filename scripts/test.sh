#!/usr/bin/env bash
# Quick start 2: check the library's structure (scripts/check-structure.sh: file and function
# sizes, after its self-test), set up, build, and run the test suite: ctest over the GoogleTest
# programs in the Release build, then the sanitizer stage (scripts/sanitize.sh: the same tests in a clang
# ASan + UBSan build, fuzz corpora replayed, a short fuzzing run per target).
# Then the ThreadSanitizer stage (scripts/tsan.sh: one writer and two readers on one map).
# Arguments go to the first ctest; MULTIBIN_SANITIZE=0 skips the sanitizer stages.
# MULTIBIN_CCACHE=0 builds without the compiler cache (see below).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# Compiler cache: with ccache installed and no launcher chosen, the builds of all three stages
# (configured afresh in a new clone) go through it, so a clone built before on this machine
# compiles only what changed.
if [ "${MULTIBIN_CCACHE:-1}" != 0 ] && command -v ccache >/dev/null &&
  [ -z "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ]; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache
fi
bash "$root/scripts/check-structure.sh" --with-self-test
source "$root/scripts/setup.sh"
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" -LE slow "$@"
if [ "${MULTIBIN_SANITIZE:-1}" != 0 ]; then
  bash "$root/scripts/sanitize.sh"
  bash "$root/scripts/tsan.sh"
fi
