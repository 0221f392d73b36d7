#!/usr/bin/env bash
# configure_sanitizer_build ROOT BUILD_DIR BUILD_TYPE SANITIZE_FLAGS LINK_FLAGS [CMAKE_ARG...]:
# the clang set-up shared by scripts/sanitize.sh and scripts/tsan.sh (sourced by both).
# Installs what is missing (the build's packages, clang with its sanitizer and libFuzzer
# runtimes, llvm for llvm-symbolizer: readable stack traces), then configures BUILD_DIR with clang
# for build type BUILD_TYPE: -O1 -g SANITIZE_FLAGS without NDEBUG (Eigen's and the library's
# assertions stay on), LINK_FLAGS for programs and shared libraries. Google Benchmark programs are
# left out (CMAKE_DISABLE_FIND_PACKAGE_benchmark): not run there, and among the heaviest files.
configure_sanitizer_build() {
  local root=$1 build_dir=$2 type=$3 flags=$4 link_flags=$5
  shift 5
  source "$root/scripts/install-packages.sh"
  install_missing_packages "${multibin_build_packages[@]}" clang libclang-rt-14-dev llvm
  local upper=${type^^}
  CC=clang CXX=clang++ cmake -S "$root" -B "$build_dir" -G Ninja \
    -DCMAKE_BUILD_TYPE="$type" \
    -DCMAKE_C_FLAGS_"$upper"="-O1 -g $flags" -DCMAKE_CXX_FLAGS_"$upper"="-O1 -g $flags" \
    -DCMAKE_EXE_LINKER_FLAGS="$link_flags" -DCMAKE_SHARED_LINKER_FLAGS="$link_flags" \
    -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON "$@" >/dev/null
  export ASAN_SYMBOLIZER_PATH=${ASAN_SYMBOLIZER_PATH:-$(command -v llvm-symbolizer || true)}
}
