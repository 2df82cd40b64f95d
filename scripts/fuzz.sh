#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/: clang, the library's sources with the
# fuzzer's instrumentation, ASan and UBSan) in build-fuzz/ and runs each for
# a bounded time. A crash, a leak, a hang (one input over 10 s), an
# allocation beyond the rss limit or (structures) a wrong answer fails the
# run; the failing input is saved under build-fuzz/artifacts/<target>/ and
# must then be added to tests/fuzz_regressions/<target>/ (replayed by ctest)
# and fixed.
#
#   bash scripts/fuzz.sh --ci                      # every target, 30 s each, two at a time (CI)
#   bash scripts/fuzz.sh --seconds 3600 --jobs 2   # a longer campaign
#   bash scripts/fuzz.sh --seconds 600 structures  # one target
#
# The corpus grown by a run is kept in build-fuzz/corpus/<target>/ and reused
# by the next run; the seeds in fuzz/corpus/<target>/ are never written.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=300
jobs=1
ci=0
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --ci) seconds=30; ci=1 ;;
    --seconds) seconds="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; exit 2 ;;
    *) targets+=("$1") ;;
  esac
  shift
done
if [ ${#targets[@]} -eq 0 ]; then
  targets=(mesh_loader scene_file ray_file structures)
fi

bash scripts/setup.sh
cmake -S fuzz -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build build-fuzz -j "$(nproc)"
# The structures target builds every kernel program before its first input
# (LLVMFuzzerInitialize). PoCL's kernel cache is the test suite's: the
# kernels do not depend on the host build, so after scripts/test.sh (as in
# CI) the programs are already compiled.
export POCL_CACHE_DIR="${POCL_CACHE_DIR:-$PWD/build/pocl-cache}"
mkdir -p "$POCL_CACHE_DIR"

# Leaks fail the run (libFuzzer's -detect_leaks); allocations above
# -rss_limit_mb / -malloc_limit_mb are reported as out-of-memory.
export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1:suppressions=$PWD/scripts/sanitizers/ubsan.supp}"
# Leaks inside Assimp on its error paths are suppressed by library name (see
# the file); a leak in rtcl's own code still fails the run.
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$PWD/scripts/sanitizers/lsan.supp:print_suppressions=0}"
# run_target <target>: fuzzes one target for $seconds; fails when it found
# something (its input saved under build-fuzz/artifacts/<target>/).
run_target() {
  local target="$1"
  local corpus="build-fuzz/corpus/$target" artifacts="build-fuzz/artifacts/$target"
  mkdir -p "$corpus" "$artifacts"
  # libFuzzer counts LLVMFuzzerInitialize into -max_total_time: the
  # structures target compiles its kernels first (minutes on a cold PoCL
  # cache), by running one seed.
  if [ "$target" = structures ]; then
    echo "fuzz.sh: structures: compiling the kernels"
    "./build-fuzz/${target}_fuzz" fuzz/corpus/structures/tetrahedron_vertices_edges >"build-fuzz/$target.log" 2>&1 ||
      { tail -n 60 "build-fuzz/$target.log" >&2; return 1; }
  fi
  echo "fuzz.sh: $target for ${seconds} s"
  # A hang is an input over 10 s; the structures target's over 60 s: an input
  # whose scene selects a program option no earlier one did (a deeper BVH
  # stack, another set of bvh-mixed's filters) compiles that program first.
  local timeout=10
  [ "$target" = structures ] && timeout=60
  local args=(-max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb=2048 -malloc_limit_mb=1024
              -artifact_prefix="$artifacts/" -print_final_stats=1)
  [ "$jobs" -gt 1 ] && args+=(-fork="$jobs" -ignore_crashes=0)
  # CI's structures run is reproducible: one fixed seed, whose first 600 s
  # ran clean (a 30 s run reaches some 40 inputs); longer campaigns pick a
  # random seed.
  [ "$ci" -eq 1 ] && [ "$target" = structures ] && args+=(-seed=2687970675)
  if ! "./build-fuzz/${target}_fuzz" "${args[@]}" "$corpus" "fuzz/corpus/$target" \
       $( [ -d "tests/fuzz_regressions/$target" ] && echo "tests/fuzz_regressions/$target" ) \
       >"build-fuzz/$target.log" 2>&1; then
    tail -n 60 "build-fuzz/$target.log" >&2
    echo "fuzz.sh: $target FAILED; inputs in $artifacts/ (add them to tests/fuzz_regressions/$target/)" >&2
    return 1
  fi
  grep -E "^(stat::number_of_executed_units|Done)" "build-fuzz/$target.log" || true
}

# CI runs two targets at a time, one per core (each gets its 30 s of one
# core); a campaign runs them one after the other, each with --jobs workers.
at_once=1
[ "$ci" -eq 1 ] && at_once=2
failed=()
for ((first = 0; first < ${#targets[@]}; first += at_once)); do
  batch=("${targets[@]:first:at_once}")
  pids=()
  for target in "${batch[@]}"; do
    run_target "$target" &
    pids+=($!)
  done
  for k in "${!batch[@]}"; do
    wait "${pids[k]}" || failed+=("${batch[k]}")
  done
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz.sh: failed: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz.sh: all targets ran ${seconds} s without a failure"
