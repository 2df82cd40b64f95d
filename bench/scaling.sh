#!/bin/sh
# The build-scaling table and plot (docs/benchmarks.md, "Build times"):
# `rtcl bench` on random soups and the tessellated surface of 1M, 4M, 16M
# and 32M triangles, each scene and structure of $ACCELS in its own process
# (a build's peak memory is measured as the rise of the process's peak
# resident memory, which memory freed earlier in the same process would
# hide), against Embree's default build of the same scene in the same
# process, primary rays checked against brute force; then the table
# (bench/scaling_table.py) and the plot (bench/plot_bench.py,
# OUT/bench-build.png).
#
#   bench/scaling.sh [OUT]        (default OUT: scaling)
#
# RTCL (default ./build/rtcl), ACCELS (default bvh,bvh-ploc), SIZES
# (triangle counts), SCENES (default "soup surface") and REPEAT (builds
# and timed launches per cell, default 3) override the defaults. Needs a
# quiet machine with 24 GiB for 32M triangles: run nothing else meanwhile.
set -eu
OUT=${1:-scaling}
RTCL=${RTCL:-./build/rtcl}
ACCELS=${ACCELS:-bvh,bvh-ploc}
SIZES=${SIZES:-1048576 4194304 16777216 33554432}
SCENES=${SCENES:-soup surface}
REPEAT=${REPEAT:-3}
mkdir -p "$OUT"
for scene in $SCENES; do
  for n in $SIZES; do
    for accel in $(echo "$ACCELS" | tr ',' ' '); do
      "$RTCL" bench --scene "$scene:count=$n" --accel "$accel" --rays primary --size 256 --repeat "$REPEAT" \
        --check-rays 256 -q -o "$OUT/$scene-$n-$accel" > /dev/null
      echo "written: $OUT/$scene-$n-$accel/bench.json"
    done
  done
done
/usr/bin/python3 "$(dirname "$0")/scaling_table.py" "$OUT"/*/bench.json | tee "$OUT/scaling.md"
/usr/bin/python3 "$(dirname "$0")/plot_bench.py" "$OUT"/*/bench.json -o "$OUT/bench"
