#!/usr/bin/env bash
# Cost per scan against the map's size (issue 33, item 1: "per-scan cost within 1.5x from the
# smallest to the largest, for each estimator"). Generates the office of seed 1 at three sizes
# (32 x 32, 100 x 100 and 316 x 316 m: 1,000, 10,000 and 100,000 m^2), drives the same length on
# each (DRIVE_S seconds at 1 m/s on its route, laps repeated where the world is small) with the
# SICK LMS-200 profile (180 beams, 80 m, 5 Hz), and runs `slamrig slam run.log --algorithm A` on
# each log RUNS times. Prints, per estimator and size, the map area the run reached (its map's
# bounding box), the median of the estimator's own time per scan (metrics.json wall_time_s over
# the scans: without reading the log and writing the outputs) and of the whole process, and the
# ratio of the largest map's per-scan time to the smallest's.
#
# Usage: bench/map_size_timing.sh [BUILD_DIR] [RUNS] [DRIVE_S] [ALGORITHMS]
#   BUILD_DIR   build folder holding apps/slamrig (default: build)
#   RUNS        runs per estimator and size, odd for a clean median (default: 3)
#   DRIVE_S     simulated seconds of driving (default: 600, 3,000 scans)
#   ALGORITHMS  comma-separated (default: pf,graph,icp-odometry,rbpf)
set -euo pipefail

usage() {
  sed -n '/^# Usage/,/^set/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
  exit 2
}
[[ "${1:-}" == "-h" || "${1:-}" == "--help" ]] && usage
build=${1:-build}
runs=${2:-3}
drive_s=${3:-600}
algorithms=${4:-pf,graph,icp-odometry,rbpf}
here=$(cd "$(dirname "$0")/.." && pwd)
slamrig="$build/apps/slamrig"
[[ -x "$slamrig" ]] || { echo "map_size_timing: $slamrig not found (build target slamrig)" >&2; exit 2; }
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "map_size_timing: RUNS: a positive integer, got '$runs'" >&2; exit 2; }
[[ "$drive_s" =~ ^[1-9][0-9]*$ ]] || { echo "map_size_timing: DRIVE_S: a positive integer, got '$drive_s'" >&2; exit 2; }

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
median() { sort -g | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }

sizes=(32 100 316)
for s in "${sizes[@]}"; do
  "$slamrig" world generate office --seed 1 --set width_m="$s" --set height_m="$s" \
    --set speed_m_s=1.0 --set laps=20 --out "$out/world$s" >/dev/null
  "$slamrig" simulate "$out/world$s/world.yaml" --robot "$here/robots/sick_lms200_1deg.yaml" \
    --duration "$drive_s" --out "$out/run$s" --quiet
done

printf '%-13s %9s %8s %10s %14s %11s\n' estimator world_m2 scans map_m2 per_scan_ms process_s
IFS=, read -r -a algos <<<"$algorithms"
for a in "${algos[@]}"; do
  first="" last=""
  for s in "${sizes[@]}"; do
    per_scan=() process=()
    for ((i = 0; i < runs; i++)); do
      rm -rf "$out/slam"
      TIMEFORMAT='%R'
      if ! t=$( { time "$slamrig" slam "$out/run$s/run.log" --algorithm "$a" --quiet \
                    --out "$out/slam" >/dev/null 2>"$out/slam.err"; } 2>&1); then
        echo "map_size_timing: slamrig slam --algorithm $a on the ${s} m office failed:" \
          "$(tail -n 1 "$out/slam.err")" >&2
        exit 1
      fi
      wall=$(sed -n 's/^ *"wall_time_s": \([0-9.eE+-]*\),*$/\1/p' "$out/slam/metrics.json" | head -n 1)
      [[ -n "$wall" ]] || { echo "map_size_timing: no wall_time_s in metrics.json ($a, $s m)" >&2; exit 1; }
      scans=$(grep -c '^ROBOTLASER1' "$out/run$s/run.log")
      per_scan+=("$(awk -v w="$wall" -v n="$scans" 'BEGIN {printf "%.4f", 1000 * w / n}')")
      process+=("$(tail -n 1 <<<"$t")")
    done
    # The map's bounding box from its map_server yaml and image header.
    res=$(sed -n 's/^resolution: *//p' "$out/slam/map.yaml")
    read -r w h < <(head -c 256 "$out/slam/map.pgm" | sed '/^#/d' | tr -s ' \n' ' ' |
      awk '{print $2, $3}')
    map_m2=$(awk -v w="$w" -v h="$h" -v r="$res" 'BEGIN {printf "%.0f", w * h * r * r}')
    ms=$(printf '%s\n' "${per_scan[@]}" | median)
    printf '%-13s %9d %8d %10s %14s %11s\n' "$a" $((s * s)) "$scans" "$map_m2" "$ms" \
      "$(printf '%s\n' "${process[@]}" | median)"
    [[ -z "$first" ]] && first=$ms
    last=$ms
  done
  awk -v a="$a" -v f="$first" -v l="$last" \
    'BEGIN {printf "%-13s largest / smallest per-scan time: %.2fx\n", a, l / f}'
done
