#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite on the first OpenCL device
# (PoCL on a fresh machine; choose another with RTCL_DEVICE). Fails when no
# OpenCL device exists.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
export POCL_CACHE_DIR="$PWD/build/pocl-cache"
ctest --test-dir build --output-on-failure -j 1 --timeout 600
