#!/usr/bin/env bash
# Whole-process speed of recording a simulated run (issue 12, item 4): runs
# `slamrig simulate office --duration S --format F [--compression C]` N times and prints each
# run's wall and CPU time (user + sys) and the medians with the real-time factors they give.
# The office run is the ECE276A robot: 1081-beam lidar at 40 Hz, IMU at 100 Hz, encoders at
# 40 Hz, and the truth at every scan. On a shared machine the CPU figure is the one to quote.
#
# Usage: bench/simulate_bag_timing.sh [BUILD_DIR] [FORMAT] [SECONDS] [RUNS] [COMPRESSION]
#   BUILD_DIR    build folder holding apps/slamrig (default: build)
#   FORMAT       mcap, sqlite3 or carmen (default: mcap)
#   SECONDS      simulated seconds (default: 120)
#   RUNS         runs, odd for a clean median (default: 5)
#   COMPRESSION  zstd, lz4 or none, MCAP only (default: zstd)
set -euo pipefail

usage() {
  sed -n '/^# Usage/,/^set/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
  exit 2
}
[[ "${1:-}" == "-h" || "${1:-}" == "--help" ]] && usage
build=${1:-build}
format=${2:-mcap}
seconds=${3:-120}
runs=${4:-5}
compression=${5:-zstd}
slamrig="$build/apps/slamrig"
[[ -x "$slamrig" ]] || { echo "simulate_bag_timing: $slamrig not found (build target slamrig)" >&2; exit 2; }
[[ "$format" =~ ^(mcap|sqlite3|carmen)$ ]] || { echo "simulate_bag_timing: FORMAT: mcap, sqlite3 or carmen, got '$format'" >&2; exit 2; }
[[ "$seconds" =~ ^[0-9]+([.][0-9]+)?$ ]] || { echo "simulate_bag_timing: SECONDS: a positive number, got '$seconds'" >&2; exit 2; }
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "simulate_bag_timing: RUNS: a positive integer, got '$runs'" >&2; exit 2; }
extra=()
if [[ "$format" == "mcap" ]]; then extra=(--compression "$compression"); fi

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
walls=() cpus=()
TIMEFORMAT='%R %U %S'
for ((i = 0; i < runs; i++)); do
  rm -rf "$out/run"
  t=$( { time "$slamrig" simulate office --duration "$seconds" --format "$format" "${extra[@]}" \
           --out "$out/run" >/dev/null; } 2>&1)
  read -r real user sys <<<"$t"
  cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN {printf "%.3f", u + s}')
  echo "run $((i + 1)): wall ${real} s, cpu ${cpu} s" >&2
  walls+=("$real")
  cpus+=("$cpu")
done
size=$(du -sk "$out/run" | cut -f1)
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
wall=$(median "${walls[@]}")
cpu=$(median "${cpus[@]}")
awk -v s="$seconds" -v w="$wall" -v c="$cpu" -v f="$format ${extra[*]:-}" -v n="$runs" -v k="$size" \
  'BEGIN {printf "simulate office %g s --format %s, median of %d: wall %.3f s (%.0fx real time), cpu %.3f s (%.0fx); output %d KiB\n", s, f, n, w, s / w, c, s / c, k}'
