#!/usr/bin/env bash
# CI stage 3: the map's thread-safety contract (one writer, concurrent readers; doc/reliability.md,
# "Threads") under ThreadSanitizer. Builds only the library and tests/map/test_threads in a
# clang -fsanitize=thread build in build-tsan/ and runs it; any data race fails the stage.
#   MULTIBIN_TSAN_BUILD_DIR  build directory (default build-tsan/)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${MULTIBIN_TSAN_BUILD_DIR:-$root/build-tsan}

source "$root/scripts/clang-sanitizer-build.sh"
configure_sanitizer_build "$root" "$build_dir" Tsan "-fsanitize=thread -fno-omit-frame-pointer" \
  "-fsanitize=thread"
cmake --build "$build_dir" -j "$(nproc)" --target test_threads

export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}
"$build_dir/tests/map/test_threads"
echo "tsan.sh: no data race"
