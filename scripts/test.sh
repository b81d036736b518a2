#!/usr/bin/env bash
# The whole test suite, as CI runs it, in two builds: dependencies; the clang-format check; a gcc
# Release build with warnings as errors and every ctest label (unit, integration, scenario,
# python); then one clang build with AddressSanitizer, UndefinedBehaviorSanitizer and libFuzzer
# instrumentation, for the unit tests and every reader of outside data over its fuzz corpus.
# Build folders build-ci/ and build-san/ (ignored by git); ccache is used when it is installed.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install_deps.sh

jobs=$(nproc)
failed=()

# Formatting first: it takes seconds, and a slip is reported with the test results, never
# instead of them.
echo "== clang-format"
mapfile -t sources < <(git ls-files '*.h' '*.cc')
if ! clang-format --dry-run --Werror "${sources[@]}"; then failed+=(clang-format); fi

launcher=()
if command -v ccache >/dev/null 2>&1; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  # Paths relative to the clone's parent, so that two clones side by side share cache entries.
  CCACHE_BASEDIR=$(cd .. && pwd)
  export CCACHE_BASEDIR
fi

echo "== Release build (warnings are errors)"
cmake -S . -B build-ci -DCMAKE_BUILD_TYPE=Release -DCMAKE_COMPILE_WARNING_AS_ERROR=ON \
  "${launcher[@]}" >/dev/null
cmake --build build-ci -j"$jobs"

echo "== all tests (Release)"
if ! ctest --test-dir build-ci --output-on-failure -j"$jobs"; then failed+=(ctest-release); fi

echo "== ASan/UBSan build (clang, libFuzzer instrumentation): the unit tests and the fuzz targets"
# One build serves both: every target gets ASan, UBSan and libFuzzer's coverage instrumentation;
# the unit tests are ordinary gtest binaries in it, the fuzz targets link libFuzzer.
# -O1 with line tables only: the sanitizers' reports keep file and line, and the build, CI's
# second longest stage, compiles and links far less than at -O2 -g. Without the unity build, so
# that every file of the libraries the unit tests link is compiled alone once: a missing include
# there fails here (apps/*.cc and the Python bridge are compiled in batches only).
CC=clang CXX=clang++ cmake -S . -B build-san -DSLAMRIG_FUZZ=ON -DSLAMRIG_SANITIZE=ON \
  -DSLAMRIG_UNITY_BUILD=OFF -DSLAMRIG_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
  -DCMAKE_COMPILE_WARNING_AS_ERROR=ON "${launcher[@]}" >/dev/null
cmake --build build-san -j"$jobs" --target slamrig_unit_tests

echo "== unit tests under ASan/UBSan"
if ! ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-san -L unit --output-on-failure -j"$jobs"; then
  failed+=(ctest-asan)
fi

echo "== fuzz corpora"
# Every reader over its seed corpus and regression inputs once, under libFuzzer with ASan/UBSan.
if ! SLAMRIG_FUZZ_BUILD_DIR=build-san SLAMRIG_FUZZ_JOBS="$jobs" \
  bash fuzz/run_fuzzers.sh --corpus-only; then
  failed+=(fuzz)
fi

if ((${#failed[@]} > 0)); then
  echo "test.sh: failed: ${failed[*]}" >&2
  exit 1
fi
echo "test.sh: all stages passed"
