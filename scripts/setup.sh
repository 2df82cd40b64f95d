#!/usr/bin/env bash
# Installs the Debian 12 packages rtcl needs (run as root). Idempotent:
# installs only packages that are missing.
#
#   bash scripts/setup.sh            # everything: build, tests, benchmarks, Python, MPI, fuzzing
#   bash scripts/setup.sh --render   # only what the library and the `rtcl` tool need (scripts/render.sh)
set -euo pipefail
render_only=0
for arg in "$@"; do
  case "$arg" in
    --render) render_only=1 ;;
    *) echo "setup.sh: unknown option $arg (use --render)" >&2; exit 2 ;;
  esac
done
packages=(
  build-essential cmake pkg-config ninja-build
  opencl-headers opencl-clhpp-headers ocl-icd-opencl-dev pocl-opencl-icd clinfo
  libglm-dev libopenimageio-dev libassimp-dev nlohmann-json3-dev libcli11-dev
)
if [ "$render_only" -eq 0 ]; then
  packages+=(
    openimageio-tools libgtest-dev libgmock-dev libbenchmark-dev libembree-dev python3 python3-matplotlib
    # Assimp's own test models: every OBJ, PLY and STL of them loads, or
    # Assimp agrees it has no triangles (tests/assimp_testmodels_test.cpp)
    assimp-testmodels
    # the Python module (python/, CMake option RTCL_PYTHON) and its tests;
    # python3-open3d is the tests' reference for point queries and camera rays
    python3-dev python3-numpy pybind11-dev python3-pytest python3-open3d
    # distributed render and bench under mpirun (CMake option RTCL_MPI)
    libopenmpi-dev openmpi-bin
    # fuzzing (scripts/fuzz.sh): clang with libFuzzer and the sanitizer
    # runtimes (libclang-rt-14-dev), llvm-symbolizer for readable reports
    clang libclang-rt-14-dev llvm
  )
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
