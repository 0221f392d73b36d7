#!/usr/bin/env bash
# install_missing_packages PKG...: installs, with apt, those of the given Debian packages that are
# not installed yet (sudo when not root). Sourced by setup.sh, sanitize.sh and check-structure.sh.

# What any build of the project needs (compilers and tools, MRPT, Eigen, OpenCV, GoogleTest,
# Google Benchmark, nlohmann-json, zlib, libdeflate, libtiff and libgeotiff).
multibin_build_packages=(g++ cmake ninja-build pkg-config libmrpt-dev mrpt-apps mrpt-common
                         libeigen3-dev libopencv-dev libgtest-dev libbenchmark-dev
                         nlohmann-json3-dev zlib1g-dev libdeflate-dev libtiff-dev libgeotiff-dev)
# What scripts/check-structure.sh needs (file and function sizes of the library).
multibin_check_packages=(universal-ctags)
install_missing_packages() {
  local missing=() p sudo_cmd=""
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "Installing missing Debian packages: ${missing[*]}"
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
}
# The Python module (python/, doc/python.md): pybind11 and the headers to build it, numpy and
# pytest for its tests. Part of every build: scripts/setup.sh requires the module.
multibin_build_packages+=(pybind11-dev python3-dev python3-numpy python3-pytest)
