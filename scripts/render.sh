#!/usr/bin/env bash
# The first image: installs what the library and the `rtcl` tool need, builds
# only those two in build/, and renders the built-in default scene to
# rtcl-default.png. Extra arguments go to `rtcl render` (e.g. --width 1024
# --height 1024; docs/cli.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --render
# Tests and benchmarks off here; scripts/build.sh turns them back on.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DRTCL_BUILD_TESTS=OFF -DRTCL_BUILD_BENCH=OFF >/dev/null
cmake --build build -j "$(nproc)" --target rtcl_cli
./build/rtcl render -o rtcl-default.png "$@"
