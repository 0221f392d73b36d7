#!/usr/bin/env bash
# The gcc sanitizer stage: one gcc Debug build with AddressSanitizer + UndefinedBehaviorSanitizer
# into build-gcc-asan/, then the test selection of scripts/sanitize.sh (the clang stage) under
# it. Not part of scripts/test.sh or .ci/run (a second sanitizer build of everything does not
# fit CI's 30 minutes on 2 cores); run it by hand before a release. See doc/reliability.md.
#   MULTIBIN_GCC_ASAN_BUILD_DIR  build directory (default build-gcc-asan/)
#   MULTIBIN_JOBS                parallel compile and test jobs (default nproc)
# Arguments go to ctest (after the selection), e.g. -R ReadBudget.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${MULTIBIN_GCC_ASAN_BUILD_DIR:-$root/build-gcc-asan}
jobs=${MULTIBIN_JOBS:-$(nproc)}

source "$root/scripts/install-packages.sh"
install_missing_packages "${multibin_build_packages[@]}"
# -O1: Eigen at -O0 under ASan makes the suite several times slower; -g1: line tables are what
# the sanitizers' stack traces need, at a fraction of full debug information's compile time. The
# build type stays Debug (no NDEBUG: Eigen's and the library's assertions on). Every finding is
# fatal (-fno-sanitize-recover), so a test that triggers one fails. The fuzz targets need clang; their
# replay programs (ctest fuzz_corpus_replay_*) are built here.
san="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
CC=gcc CXX=g++ cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_C_FLAGS_DEBUG="-O1 -g1 $san" -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1 $san" \
  -DCMAKE_EXE_LINKER_FLAGS="$san" -DCMAKE_SHARED_LINKER_FLAGS="$san" \
  -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON -DMULTIBIN_BUILD_APPS=ON "${launcher[@]}" >/dev/null
cmake --build "$build_dir" -j "$jobs"

source "$root/scripts/sanitizer-tests.sh"
run_sanitizer_tests "$root" "$build_dir" "$jobs" "$@"
echo "sanitize-gcc.sh: all clean"
