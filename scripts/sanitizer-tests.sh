#!/usr/bin/env bash
# run_sanitizer_tests ROOT BUILD_DIR JOBS [CTEST_ARG...]: the test selection and the sanitizer
# options of the ASan + UBSan stages, shared by scripts/sanitize.sh (clang) and
# scripts/sanitize-gcc.sh (gcc). Every report is fatal; LeakSanitizer is on with the
# suppressions of tests/common/lsan.supp.
#
# Left out of the run:
# - label slow: minutes even without sanitizers (the Release stage skips them too);
# - label install: builds doc/example-consumer with the default flags against this ASan library;
# - MrptTools.*: preloads the ASan-built library into MRPT's stock observations2map, which is not
#   built with ASan (the runtime would have to come first in the process); the Release stage
#   runs it;
# - HeadlineFigures.*: the mapper on the whole mock-up and walk against their measured figures
#   (RMSE, coverage), a minute each here. Its subject is the numbers, which the Release stage
#   checks; the code it runs (reading, mapping, filling, the evaluation, the outputs) runs here
#   through Georeferenced.TheMapperGivesTheSameEvaluationAndRastersAtUtmCoordinates,
#   HostilePaths.* and the library's own tests (doc/reliability.md, section 3);
# - label release_only (RouteScale.*: routes of 50 to 1000 m, a scale figure; its code, the
#   tiled store, runs here through the library's own tests).
run_sanitizer_tests() {
  local root=$1 build_dir=$2 jobs=$3
  shift 3
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
  export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/tests/common/lsan.supp:print_suppressions=0}
  # Longest first: the Release stage's test times (when this stage follows it) order the tests,
  # so a long one does not start last and leave one core idle at the end.
  local release_costs=${MULTIBIN_BUILD_DIR:-$root/build}/Testing/Temporary/CTestCostData.txt
  if [ -f "$release_costs" ] && [ ! -f "$build_dir/Testing/Temporary/CTestCostData.txt" ]; then
    mkdir -p "$build_dir/Testing/Temporary"
    cp "$release_costs" "$build_dir/Testing/Temporary/"
  fi
  ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" -LE 'slow|install|release_only' \
    -E '^(MrptTools|HeadlineFigures)\.' "$@"
}
