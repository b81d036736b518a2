#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, -DSLAMRIG_FUZZ=ON, in build-fuzz/) and runs them.
#
#   fuzz/run_fuzzers.sh [SECONDS_PER_TARGET] [TARGET...]   fuzz each target (default 60 s)
#   fuzz/run_fuzzers.sh --corpus-only [TARGET...]          CI: every corpus input once
#
# Corpora: build-fuzz/fuzz_corpora/<target>/ (slices of real files, fuzz/make_corpora.sh; new
# inputs the fuzzer finds are added there), fuzz/corpus/<target>/ (hand-made) and
# fuzz/regressions/<target>/ (inputs that once crashed). Crashes, leaks, timeouts (-timeout=10)
# and out-of-memory (-rss_limit_mb=2048) land in build-fuzz/fuzz_artifacts/<target>/; logs in
# build-fuzz/fuzz_logs/<target>.log (SLAMRIG_FUZZ_BUILD_DIR picks another build folder). Exits
# non-zero if any target failed.
# SLAMRIG_FUZZ_KEEP_GOING=1 fuzzes on past crashes (libFuzzer -fork=1 -ignore_crashes=1 ...),
# collecting every artifact of a long run instead of stopping at the first.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=60
corpus_only=0
if (($# > 0)); then
  if [[ $1 == --corpus-only ]]; then
    corpus_only=1
    shift
  elif [[ $1 =~ ^[0-9]+$ ]]; then
    seconds=$1
    shift
  fi
fi
all_targets=(carmen npz ece276a_csv tum map_server world_yaml robot_yaml scenario_yaml sweep_yaml bag)
targets=("$@")
if ((${#targets[@]} == 0)); then targets=("${all_targets[@]}"); fi

build=${SLAMRIG_FUZZ_BUILD_DIR:-build-fuzz}
jobs=${SLAMRIG_FUZZ_JOBS:-2}
if [[ ! -f $build/CMakeCache.txt ]]; then
  CC=clang CXX=clang++ cmake -S . -B "$build" -DSLAMRIG_FUZZ=ON -DSLAMRIG_BUILD_BENCHMARKS=OFF \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_COMPILE_WARNING_AS_ERROR=ON >/dev/null
fi
build_targets=()
for t in "${targets[@]}"; do build_targets+=(--target "fuzz_$t"); done
# The bag seeds are bags the simulator writes (fuzz/make_corpora.sh runs this build's slamrig).
if [[ " ${targets[*]} " == *" bag "* ]]; then build_targets+=(--target slamrig); fi
cmake --build "$build" -j"$jobs" "${build_targets[@]}" >"$build/fuzz_build.log" 2>&1 ||
  {
    tail -n 40 "$build/fuzz_build.log"
    exit 1
  }
bash fuzz/make_corpora.sh "$build" "${targets[@]}" >/dev/null

mkdir -p "$build/fuzz_logs"
failed=()
printf '%-14s %12s %8s %s\n' target executions seconds result
for t in "${targets[@]}"; do
  artifacts=$build/fuzz_artifacts/$t
  rm -rf "$artifacts"
  mkdir -p "$artifacts"
  corpora=("$build/fuzz_corpora/$t")
  for extra in fuzz/corpus/$t fuzz/regressions/$t; do
    if [[ -d $extra ]]; then corpora+=("$extra"); fi
  done
  flags=(-rss_limit_mb=2048 -timeout=10 -print_final_stats=1 "-artifact_prefix=$artifacts/")
  if ((corpus_only)); then
    flags+=(-runs=0)
  else
    # A bag seed holds its message definitions (schemas) besides a few messages: 128 KiB.
    max_len=8192
    if [[ $t == bag ]]; then max_len=131072; fi
    flags+=("-max_total_time=$seconds" "-max_len=$max_len")
    if [[ ${SLAMRIG_FUZZ_KEEP_GOING:-0} == 1 ]]; then
      flags+=(-fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1)
    fi
  fi
  log=$build/fuzz_logs/$t.log
  status=ok
  start=$(date +%s)
  # Leaks are reported too (the readers own no global state that would excuse one).
  if ! ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    nice "$build/fuzz/fuzz_$t" "${flags[@]}" "${corpora[@]}" >"$log" 2>&1; then
    status="FAILED (see $log)"
    failed+=("$t")
  fi
  elapsed=$(($(date +%s) - start))
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  if [[ -z $execs ]]; then # fork mode: the last '#N:' progress line
    execs=$(sed -n 's/^#\([0-9]*\):.*/\1/p' "$log" | tail -n 1)
  fi
  crashes=$(find "$artifacts" -type f | wc -l)
  if ((crashes > 0)) && [[ $status == ok ]]; then
    status="FAILED ($crashes artifacts in $artifacts)"
    failed+=("$t")
  fi
  printf '%-14s %12s %8s %s\n' "$t" "${execs:-?}" "$elapsed" "$status"
done
if ((${#failed[@]} > 0)); then
  echo "run_fuzzers: failed: ${failed[*]}" >&2
  exit 1
fi
