#!/usr/bin/env bash
# Installs fibernet's build dependencies from Debian 12's packages (only what is missing), then builds.
# Usage: scripts/setup.sh [--all] [--no-build]
#   default: build only the fibernet executable (the README's main job needs nothing else);
#   --all: also the Python package, the tests and benchmarks (scripts/test.sh), and the packages the tests run;
#   --no-build: install packages only (with --all: the tests' packages too; scripts/sanitize.sh).
#   (The Python package alone: cmake --build build --target _fibernet; docs/python.md.)
set -euo pipefail
cd "$(dirname "$0")/.."
pkgs=(build-essential cmake pkg-config libeigen3-dev libsuitesparse-dev libopenblas-dev
      libnlopt-cxx-dev coinor-libipopt-dev catch2 libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libcgal-dev
      openmpi-bin libopenmpi-dev python3-matplotlib  # MPI: fibernet scan; matplotlib: the plot scripts
      pybind11-dev python3-dev python3-numpy)          # the Python package (docs/python.md)
# The test suite also runs LAMMPS and VTK on fibernet's exports, and pytest on the Python package.
test_pkgs=(lammps python3-vtk9 python3-pytest)
all=0 build=1
for a in "$@"; do
  case "$a" in
    --all) all=1 ;;
    --no-build) build=0 ;;
    *) echo "setup: unknown option '$a' (expected --all and/or --no-build)" >&2; exit 2 ;;
  esac
done
[ "$all" = 1 ] && pkgs+=("${test_pkgs[@]}")
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi
[ "$build" = 0 ] && exit 0
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >&2
if [ "$all" = 1 ]; then
  cmake --build build -j"$(nproc)" >&2
else
  cmake --build build -j"$(nproc)" --target fibernet >&2
fi
