#!/usr/bin/env bash
# Sets up, builds and renders the built-in default scene to rtcl-default.png.
# Extra arguments go to `rtcl render` (e.g. --width 1024 --height 1024).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
./build/rtcl render -o rtcl-default.png "$@"
