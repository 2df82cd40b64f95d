#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite on the first OpenCL device
# (PoCL on a fresh machine; choose another with RTCL_DEVICE). Fails when no
# OpenCL device exists.
#
#   bash scripts/test.sh              # Release build in build/
#   bash scripts/test.sh --sanitize   # ASan + UBSan build in build-asan/ (CMakePresets.json "asan")
set -euo pipefail
cd "$(dirname "$0")/.."
sanitize=0
for arg in "$@"; do
  case "$arg" in
    --sanitize) sanitize=1 ;;
    *) echo "test.sh: unknown option $arg (use --sanitize)" >&2; exit 2 ;;
  esac
done

if [ "$sanitize" -eq 0 ]; then
  bash scripts/build.sh
  export POCL_CACHE_DIR="$PWD/build/pocl-cache"
  # Two test suites at a time (one process per GoogleTest suite): much of
  # the suite is host-bound (process start, mesh loading, builds), so the
  # two cores stay busy and the suite takes about half as long as one at a
  # time.
  ctest --test-dir build --output-on-failure -j 2 --timeout 600
  exit 0
fi

bash scripts/setup.sh
# PoCL's kernel cache is shared with the Release suite: the same kernels, and
# the sanitizers do not instrument device code (a cold cache costs the
# suite minutes of kernel compilation).
export POCL_CACHE_DIR="$PWD/build/pocl-cache"
mkdir -p "$POCL_CACHE_DIR"
cmake --preset asan -DRTCL_TEST_POCL_CACHE_DIR="$POCL_CACHE_DIR" >/dev/null
cmake --build build-asan -j "$(nproc)"
# Every report fails the test that triggers it. Leaks inside the OpenCL
# driver stack and Assimp are suppressed by library name, with reasons, in
# scripts/sanitizers/; nothing of rtcl's own is.
supp="$PWD/scripts/sanitizers"
# intercept_tls_get_addr=0: GCC 12's sanitizer runtime misreads some
# dynamic TLS blocks (a malloc'd block at the offset of a pre-2.25 glibc TLS
# header) and LeakSanitizer's exit-time tracer then dies with "Tracer caught
# signal 11" after the test passed, on both tries of the same test.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=0:intercept_tls_get_addr=0"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$supp/ubsan.supp"
# LeakSanitizer's exit-time scan crashes ("Tracer caught signal 11") when it
# stops PoCL's pool of worker threads (seen on the dragon test): one PoCL
# worker avoids it. No test is retried: a tracer crash fails its test like
# any report, to be fixed, not absorbed.
export POCL_MAX_PTHREAD_COUNT=1
# The registry-wide suites run every structure at one level here: the levels
# differ only in kernel code, which runs inside PoCL uninstrumented (the
# Release run above covers all three; precision_test still drives each
# level's host path).
export RTCL_TEST_PRECISIONS=robust
# Two test suites at a time: with one PoCL worker each, a suite uses about
# one core. The tests listed in scripts/sanitizers/release_only_tests.txt
# (with the reason) run in the Release suite only (tests/CMakeLists.txt
# leaves them out of this build's suites).
ctest --test-dir build-asan --output-on-failure -j 2 --timeout 900
