#!/usr/bin/env bash
# The whole test suite, as CI runs it: dependencies, a Release build with warnings as errors,
# every ctest label (unit, integration, scenario), an ASan/UBSan build of the unit tests, and
# every reader of outside data over its fuzz corpus (libFuzzer, clang), and the clang-format
# check (last, so that a formatting slip never hides a test result). Build folders: build-ci/,
# build-asan/ and build-fuzz/ (all ignored by git).
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install_deps.sh

jobs=$(nproc)
echo "== Release build (warnings are errors)"
cmake -S . -B build-ci -DCMAKE_BUILD_TYPE=Release -DCMAKE_COMPILE_WARNING_AS_ERROR=ON >/dev/null
cmake --build build-ci -j"$jobs"

echo "== ASan/UBSan build"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSLAMRIG_SANITIZE=ON \
  -DSLAMRIG_BUILD_BENCHMARKS=OFF -DCMAKE_COMPILE_WARNING_AS_ERROR=ON >/dev/null
cmake --build build-asan -j"$jobs"

echo "== unit tests under ASan/UBSan"
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan -L unit --output-on-failure -j"$jobs"

echo "== fuzz corpora"
# Every reader over its seed corpus and regression inputs once, under libFuzzer + ASan/UBSan
# (clang; builds only the fuzz targets in build-fuzz/).
SLAMRIG_FUZZ_JOBS="$jobs" bash fuzz/run_fuzzers.sh --corpus-only

echo "== all tests (Release)"
ctest --test-dir build-ci --output-on-failure -j"$jobs"

echo "== clang-format"
mapfile -t sources < <(git ls-files '*.h' '*.cc')
clang-format --dry-run --Werror "${sources[@]}"
