#!/usr/bin/env bash
# Whole-process speed of recording a simulated run as a ROS 2 bag (issue 12, item 5): runs
# `slamrig simulate office --duration S --format F` N times and prints the median wall time and
# CPU time (user + sys) of the process and the real-time factors they give.
#
# Usage: bench/simulate_bag_timing.sh [BUILD_DIR] [FORMAT] [SECONDS] [RUNS]
set -euo pipefail
build=${1:-build}
format=${2:-mcap}
seconds=${3:-120}
runs=${4:-5}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
walls=() cpus=()
for ((i = 0; i < runs; i++)); do
  rm -rf "$out/run"
  TIMEFORMAT='%R %U %S'
  t=$( { time "$build/apps/slamrig" simulate office --duration "$seconds" --format "$format" \
           --out "$out/run" >/dev/null; } 2>&1)
  read -r real user sys <<<"$t"
  walls+=("$real")
  cpus+=("$(echo "$user + $sys" | bc)")
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
wall=$(median "${walls[@]}")
cpu=$(median "${cpus[@]}")
echo "simulate office ${seconds} s --format ${format}, median of ${runs}:" \
  "wall ${wall} s ($(echo "scale=0; $seconds / $wall" | bc)x real time)," \
  "cpu ${cpu} s ($(echo "scale=0; $seconds / $cpu" | bc)x)"
