#!/usr/bin/env bash
# CI stage 3: the map's thread-safety contract (one writer, concurrent readers; doc/reliability.md,
# "Threads") under ThreadSanitizer. Builds only the library and tests/reliability/test_threads in a
# clang -fsanitize=thread build in build-tsan/ and runs it; any data race fails the stage.
#   MULTIBIN_TSAN_BUILD_DIR  build directory (default build-tsan/)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${MULTIBIN_TSAN_BUILD_DIR:-$root/build-tsan}

source "$root/scripts/install-packages.sh"
install_missing_packages "${multibin_build_packages[@]}" clang libclang-rt-14-dev llvm

tsan="-fsanitize=thread -fno-omit-frame-pointer"
CC=clang CXX=clang++ cmake -S "$root" -B "$build_dir" -G Ninja \
  -DCMAKE_BUILD_TYPE=Tsan \
  -DCMAKE_C_FLAGS_TSAN="-O1 -g $tsan" -DCMAKE_CXX_FLAGS_TSAN="-O1 -g $tsan" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=thread" \
  -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON >/dev/null
cmake --build "$build_dir" -j "$(nproc)" --target test_threads

export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}
export ASAN_SYMBOLIZER_PATH=${ASAN_SYMBOLIZER_PATH:-$(command -v llvm-symbolizer || true)}
"$build_dir/tests/reliability/test_threads"
echo "tsan.sh: no data race"
