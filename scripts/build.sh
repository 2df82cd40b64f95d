#!/usr/bin/env bash
# Installs missing Debian packages, then configures and builds rtcl in build/:
# the library, the `rtcl` tool, the tests and the benchmarks.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# A build/ that scripts/render.sh configured (tests off, packages found then)
# is configured afresh, so that packages installed since are found.
fresh=()
if grep -qs '^RTCL_BUILD_TESTS:BOOL=OFF' build/CMakeCache.txt; then fresh=(--fresh); fi
# RTCL_PYTHON=ON: the Python module and its tests (ctest python_tests) are
# part of the suite, so a missing python3-dev, python3-numpy or pybind11-dev
# fails here instead of leaving python_tests out (AUTO, the CMake default,
# would build without them).
cmake "${fresh[@]}" -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DRTCL_BUILD_TESTS=ON -DRTCL_BUILD_BENCH=ON \
  -DRTCL_PYTHON=ON >/dev/null
cmake --build build -j "$(nproc)"
