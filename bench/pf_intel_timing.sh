#!/usr/bin/env bash
# Whole-process speed of the particle filter on intel-corrected (issue 33: 100 particles in
# <= 4 s with the default threads): runs `slamrig slam carmen_corrected/intel-corrected.log.gz --algorithm pf
# --set particles=100 [--set threads=T]` N times and prints each run's wall and CPU time (user +
# sys), the filter's own time from metrics.json (wall_time_s: the estimator, without reading the
# log and writing the map), and the medians. Every run must give the same trajectory (checked).
# On a shared machine the CPU figure is the one to quote.
#
# Usage: bench/pf_intel_timing.sh [BUILD_DIR] [RUNS] [THREADS]
#   BUILD_DIR  build folder holding apps/slamrig (default: build)
#   RUNS       runs, odd for a clean median (default: 5)
#   THREADS    the filter's worker threads (default: 0, the filter's default: one per processor
#              this process may use)
set -euo pipefail

usage() {
  sed -n '/^# Usage/,/^set/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
  exit 2
}
[[ "${1:-}" == "-h" || "${1:-}" == "--help" ]] && usage
build=${1:-build}
runs=${2:-5}
threads=${3:-0}
slamrig="$build/apps/slamrig"
[[ -x "$slamrig" ]] || { echo "pf_intel_timing: $slamrig not found (build target slamrig)" >&2; exit 2; }
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "pf_intel_timing: RUNS: a positive integer, got '$runs'" >&2; exit 2; }
[[ "$threads" =~ ^(0|[1-9][0-9]*)$ ]] || { echo "pf_intel_timing: THREADS: 0 or a positive integer, got '$threads'" >&2; exit 2; }
# What 0 gives: SLAMRIG_THREADS, else the processors of this process's affinity.
shown=$threads
((threads > 0)) || shown="${SLAMRIG_THREADS:-$(nproc)}"

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
walls=() cpus=() filters=()
TIMEFORMAT='%R %U %S'
for ((i = 0; i < runs; i++)); do
  rm -rf "$out/run"
  t=$( { time "$slamrig" slam carmen_corrected/intel-corrected.log.gz --algorithm pf \
           --set particles=100 --set threads="$threads" --quiet --out "$out/run" >/dev/null; } 2>&1)
  read -r real user sys <<<"$(tail -n 1 <<<"$t")"
  cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN {printf "%.3f", u + s}')
  filter=$(sed -n 's/^ *"wall_time_s": \([0-9.eE+-]*\),*$/\1/p' "$out/run/metrics.json" | head -n 1)
  [[ -n "$filter" ]] || { echo "pf_intel_timing: no wall_time_s in $out/run/metrics.json" >&2; exit 1; }
  if ((i == 0)); then
    cp "$out/run/trajectory.tum" "$out/first.tum"
  elif ! cmp -s "$out/run/trajectory.tum" "$out/first.tum"; then
    echo "pf_intel_timing: run $((i + 1)) gave another trajectory than run 1" >&2
    exit 1
  fi
  echo "run $((i + 1)): wall ${real} s, cpu ${cpu} s, filter ${filter} s" >&2
  walls+=("$real")
  cpus+=("$cpu")
  filters+=("$filter")
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
awk -v w="$(median "${walls[@]}")" -v c="$(median "${cpus[@]}")" -v f="$(median "${filters[@]}")" \
  -v n="$runs" -v t="$shown" \
  'BEGIN {printf "slam intel-corrected, pf, 100 particles, %d thread(s), median of %d: wall %.2f s, cpu %.2f s, filter %.2f s\n", t, n, w, c, f}'
