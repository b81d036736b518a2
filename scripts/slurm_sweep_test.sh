#!/usr/bin/env bash
# The Slurm sweep backend against the local one: starts a private single-node Slurm
# (scripts/slurm_local.sh, under BUILD_DIR/slurm_test/), runs a 12-row sweep (2 durations x 2
# particle counts x 3 seeds of a few seconds of the office scenario) with --backend local
# --jobs 1 and with --backend slurm, and checks that both results.csv hold the same rows in
# grid order (wall time aside), also after resuming with rows missing. Stops the daemons by pid on exit, pass or fail.
#
#   scripts/slurm_sweep_test.sh [BUILD_DIR]   # default build; needs BUILD_DIR/apps/slamrig
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
binary=$build/apps/slamrig
work=$build/slurm_test
[[ -x $binary ]] || {
  echo "slurm_sweep_test: no $binary (build the slamrig target)" >&2
  exit 1
}
rm -rf "$work"
mkdir -p "$work"
trap 'bash "$repo/scripts/slurm_local.sh" stop "$work/cluster"' EXIT
eval "$(bash "$repo/scripts/slurm_local.sh" start "$work/cluster")"

cat >"$work/sweep.yaml" <<YAML
scenario: $repo/scenarios/office_loop.yaml
seeds: 3
parameters:
  duration_s: [2, 3]
  slam.pf.particles: [5, 10]
metrics: [pf.ate_rmse_m, dead_reckoning.ate_rmse_m]
YAML

# Exit 3: the short runs miss the scenario's expectations (rows say fail); anything else fails.
run_sweep() { # out_dir args...
  local out=$1 code=0
  shift
  "$binary" sweep "$work/sweep.yaml" --out "$out" --quiet "$@" || code=$?
  if ((code != 0 && code != 3)); then
    echo "slurm_sweep_test: slamrig sweep $* exited $code" >&2
    exit 1
  fi
}
start=$(date +%s.%N)
run_sweep "$work/local" --jobs 1
mid=$(date +%s.%N)
run_sweep "$work/slurm" --backend slurm
end=$(date +%s.%N)

strip_wall() { sed 's/,[^,]*$//' "$1"; }
rows=$(($(wc -l <"$work/slurm/results.csv") - 1))
if ((rows != 12)); then
  echo "slurm_sweep_test: FAILED: $rows rows from Slurm, expected 12" >&2
  exit 1
fi
if ! diff <(strip_wall "$work/local/results.csv") <(strip_wall "$work/slurm/results.csv"); then
  echo "slurm_sweep_test: FAILED: Slurm rows differ from the local ones (diff above)" >&2
  exit 1
fi
# Resume: drop 5 rows from the Slurm results; a second sweep submits only those (one array of
# 5 tasks) and ends with the same file.
head -n 8 "$work/slurm/results.csv" >"$work/slurm/results.csv.part"
mv "$work/slurm/results.csv.part" "$work/slurm/results.csv"
resumed=$("$binary" sweep "$work/sweep.yaml" --out "$work/slurm" --backend slurm --quiet || true)
if [[ $resumed != *"(7 from an earlier sweep, 5 now)"* ]]; then
  echo "slurm_sweep_test: FAILED: resumed sweep said: $resumed" >&2
  exit 1
fi
if ! diff <(strip_wall "$work/local/results.csv") <(strip_wall "$work/slurm/results.csv"); then
  echo "slurm_sweep_test: FAILED: resumed Slurm rows differ from the local ones" >&2
  exit 1
fi

awk -v a="$start" -v b="$mid" -v c="$end" \
  'BEGIN { printf "slurm_sweep_test: ok, 12 identical rows (local %.1f s, slurm %.1f s)\n", b - a, c - b }'
