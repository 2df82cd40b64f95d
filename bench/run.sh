#!/usr/bin/env bash
# Builds rtcl_bench, runs the whole suite and prints the Markdown tables.
#
#   bash bench/run.sh [extra rtcl_bench / Google Benchmark flags]
#
# e.g. bash bench/run.sh --benchmark_filter=bunny
#      RTCL_BENCH_RES=256 bash bench/run.sh          (a quick check)
#
# Writes bench/results/latest.json (Google Benchmark JSON, every repetition)
# and bench/results/latest.md (the tables). Environment:
#   BUILD_DIR              build directory (default build-bench)
#   REPETITIONS            repetitions per benchmark (default 3; tables show medians)
#   RTCL_DEVICE            OpenCL device (index or name substring; default the first)
#   RTCL_BENCH_RES         image side in pixels (default 1024)
#   RTCL_BENCH_BRUTE_RAYS  rays brute force traces (default 16384)
#   RTCL_BENCH_THREADS     Embree's threads (default: all hardware threads)
#   RTCL_SCENES_DIR        meshes (default ../shared/scenes beside the repository)
#   POCL_CACHE_DIR         PoCL's kernel cache (default $BUILD_DIR/pocl-cache-bench)
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-build-bench}"
[[ "$build" = /* ]] || build="$root/$build"
results="$root/bench/results"

if [[ ! -f "$build/build.ninja" ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DRTCL_BUILD_TESTS=OFF
fi
ninja -C "$build" rtcl_bench

mkdir -p "$results"
export POCL_CACHE_DIR="${POCL_CACHE_DIR:-$build/pocl-cache-bench}"
"$build/bench/rtcl_bench" \
  --benchmark_repetitions="${REPETITIONS:-3}" \
  --benchmark_display_aggregates_only=true \
  --benchmark_out="$results/latest.json" \
  --benchmark_out_format=json \
  "$@"
echo
python3 "$root/bench/report.py" "$results/latest.json" -o "$results/latest.md"
# Debian's python3 (with python3-matplotlib), whatever python3 is first on PATH
if grep -q '"precision/' "$results/latest.json"; then
  /usr/bin/python3 "$root/bench/precision_report.py" "$results/latest.json" -o "$results/precision.md" \
    --plot "$results/precision.png"
fi
