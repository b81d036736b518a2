#!/usr/bin/env bash
# Runs scripts/fault_test.sh N times (default 50) with both cores loaded by two busy loops, and
# reports "K of N passed". Each failing run's output is kept in BUILD_DIR/fault_test_loop/.
# Not for CI: it takes N times the fault test's minute or two. Needs what fault_test.sh needs.
# To go on building meanwhile, give it a folder holding a copy of the binary as apps/slamrig.
#
#   scripts/fault_test_loop.sh [N] [BUILD_DIR]
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
runs=${1:-50}
build=$(cd "${2:-$repo/build}" && pwd)
[[ $runs =~ ^[1-9][0-9]*$ ]] || {
  echo "fault_test_loop: N must be a positive integer, got '$runs'" >&2
  exit 2
}
logs=$build/fault_test_loop
rm -rf "$logs"
mkdir -p "$logs"

# The load: one busy loop per core, stopped by pid however the script ends.
load_pids=()
stop_load() { for pid in "${load_pids[@]}"; do kill "$pid" 2>/dev/null || true; done; }
trap stop_load EXIT
for _ in $(seq "$(nproc)"); do
  yes >/dev/null &
  load_pids+=($!)
done

passed=0 skipped=0
for i in $(seq "$runs"); do
  # A rebuild replacing the binary mid-loop would fail every run for nothing.
  [[ -x $build/apps/slamrig ]] || {
    echo "fault_test_loop: $build/apps/slamrig is gone (rebuilt?); stopped after $((i - 1))" >&2
    exit 1
  }
  code=0
  bash "$repo/scripts/fault_test.sh" "$build" >"$logs/run_$i.log" 2>&1 || code=$?
  if ((code == 0)); then
    passed=$((passed + 1))
    rm -f "$logs/run_$i.log"
  elif ((code == 77)); then
    skipped=$((skipped + 1))
  else
    echo "run $i failed (exit $code): $(grep -m 1 'FAILED' "$logs/run_$i.log" || tail -n 1 "$logs/run_$i.log")"
  fi
  echo "after $i: $passed passed"
done
note=""
((skipped == 0)) || note=" ($skipped skipped: fault_test.sh could not mount a tmpfs)"
echo "fault_test_loop: $passed of $runs passed$note, with $(nproc) cores loaded"
((passed == runs))
