#!/usr/bin/env bash
# CI stage 2: one clang build with AddressSanitizer + UndefinedBehaviorSanitizer (+ libFuzzer
# instrumentation) into build-asan/, the fast test suite under it, then the fuzz corpora replayed
# and each libFuzzer target fuzzed for a short while. See doc/reliability.md.
#   FUZZ_SECONDS  seconds of fuzzing per target (default 30; 0 = replay the corpora only)
#   MULTIBIN_ASAN_BUILD_DIR  build directory (default build-asan/)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${MULTIBIN_ASAN_BUILD_DIR:-$root/build-asan}
fuzz_seconds=${FUZZ_SECONDS:-30}
jobs=$(nproc)

# Every sanitizer finding is fatal (-fno-sanitize-recover), so a test that triggers one fails.
source "$root/scripts/clang-sanitizer-build.sh"
san="-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=all -fno-omit-frame-pointer"
configure_sanitizer_build "$root" "$build_dir" Sanitize "$san" "-fsanitize=address,undefined" \
  -DMULTIBIN_BUILD_APPS=ON -DMULTIBIN_FUZZ=ON
cmake --build "$build_dir" -j "$jobs"

source "$root/scripts/sanitizer-tests.sh"
run_sanitizer_tests "$root" "$build_dir" "$jobs"

# Fuzz targets: replay the committed corpora (every input once), then fuzz each for a while.
# New inputs go to a scratch corpus in the build tree; the committed ones stay as they are. A
# crash, a sanitizer report, a leak or an out-of-memory (> 2 GB) fails the stage; the reproducer
# is left in build-asan/fuzz-<target>-crash-*.
for target in map_deserialize ini_options observation_insert rawlog_read; do
  exe="$build_dir/tests/fuzz/fuzz_$target"
  corpus="$root/tests/fuzz/corpus/$target"
  scratch="$build_dir/fuzz-corpus/$target"
  log="$build_dir/fuzz-$target.log"
  mkdir -p "$scratch"
  echo "== fuzz_$target: replay $(ls "$corpus" | wc -l) inputs"
  "$exe" -runs=0 -artifact_prefix="$build_dir/fuzz-$target-crash-" "$corpus" > "$log" 2>&1 ||
    { tail -n 40 "$log"; exit 1; }
  grep -E '^#[0-9]+.*DONE' "$log" || true
  seconds=$fuzz_seconds
  if [ "$seconds" -gt 0 ]; then
    echo "== fuzz_$target: fuzz ${seconds} s"
    "$exe" -max_total_time="$seconds" -print_final_stats=1 \
      -artifact_prefix="$build_dir/fuzz-$target-crash-" "$scratch" "$corpus" > "$log" 2>&1 ||
      { tail -n 40 "$log"; exit 1; }
    grep -E '^#[0-9]+.*DONE|^stat::(number_of_executed_units|peak_rss_mb)' "$log" || true
  fi
done
echo "sanitize.sh: all clean"
