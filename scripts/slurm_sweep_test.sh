#!/usr/bin/env bash
# The Slurm sweep backend against the local one: starts a private single-node Slurm
# (scripts/slurm_local.sh, under BUILD_DIR/slurm_test/), runs a 12-row sweep (2 durations x 2
# particle counts x 3 seeds of a few seconds of the office scenario) with --backend local
# --jobs 1 and with --backend slurm, and checks that both results.csv hold the same rows in
# grid order (wall time aside), also after resuming with rows missing, after a task killed with
# scancel (redone on resume) and after Ctrl-C of the sweep (the array cancelled). Stops the
# daemons by pid on exit, pass or fail.
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

# Sorted rows, wall time aside: a row redone on resume is appended after the others.
sorted_rows() { tail -n +2 "$1" | sed 's/,[^,]*$//' | sort; }
check_rows() { # what
  if ! diff <(sorted_rows "$work/local/results.csv") <(sorted_rows "$work/slurm/results.csv"); then
    echo "slurm_sweep_test: FAILED: $1: rows differ from the local ones (diff above)" >&2
    exit 1
  fi
  local twice
  twice=$(tail -n +2 "$work/slurm/results.csv" | cut -d, -f1 | sort | uniq -d)
  if [[ -n $twice ]]; then
    echo "slurm_sweep_test: FAILED: $1: rows twice: $twice" >&2
    exit 1
  fi
}
drop_rows() { # keep the header and the first N rows
  head -n $(($1 + 1)) "$work/slurm/results.csv" >"$work/slurm/results.csv.part"
  mv "$work/slurm/results.csv.part" "$work/slurm/results.csv"
}
# The job id the sweep printed on stderr ("slurm: job N, ..."), once it has.
job_of() { # stderr_file
  local job=""
  for _ in $(seq 300); do
    job=$(sed -n 's/^slurm: job \([0-9]*\),.*/\1/p' "$1")
    [[ -n $job ]] && break
    sleep 0.1
  done
  echo "$job"
}

# A task killed with scancel mid-run leaves no row; the sweep says so, and the next sweep runs
# that row again: 12 rows, none twice. (A task can win the race and finish before scancel:
# then the same rows are dropped and it is tried again.)
set -m # background sweeps get their own process group (for the Ctrl-C below)
cancelled=""
for attempt in 1 2 3; do
  drop_rows 8
  "$binary" sweep "$work/sweep.yaml" --out "$work/slurm" --backend slurm \
    >"$work/scancel.out" 2>"$work/scancel.err" &
  pid=$!
  job=$(job_of "$work/scancel.err")
  task=""
  for _ in $(seq 600); do # a task running its `slamrig run` child
    task=$(squeue -h -j "$job" -t R -o %K 2>/dev/null | head -n 1)
    if [[ -n $task ]] && pgrep -f -- "$work/slurm/runs/$(printf %04d "$task")" >/dev/null; then
      break
    fi
    task=""
    sleep 0.05
  done
  [[ -n $task ]] && scancel "${job}_$task"
  code=0
  wait "$pid" || code=$?
  if [[ -n $task ]] && ! grep -q "^slurm: row $task left no result" "$work/scancel.err"; then
    echo "slurm_sweep_test: attempt $attempt: task $task finished before scancel" >&2
    continue
  fi
  if [[ -z $task || $code != 3 ]]; then
    echo "slurm_sweep_test: FAILED: scancel: no running task found or exit $code" >&2
    cat "$work/scancel.err" >&2
    exit 1
  fi
  cancelled=$task
  break
done
if [[ -z $cancelled ]]; then
  echo "slurm_sweep_test: FAILED: every scancel came after its task had finished" >&2
  exit 1
fi
if (($(wc -l <"$work/slurm/results.csv") != 12)); then
  echo "slurm_sweep_test: FAILED: after scancel of row $cancelled, not 11 rows" >&2
  exit 1
fi
resumed=$("$binary" sweep "$work/sweep.yaml" --out "$work/slurm" --backend slurm --quiet || true)
if [[ $resumed != *"(11 from an earlier sweep, 1 now)"* ]]; then
  echo "slurm_sweep_test: FAILED: the sweep after scancel said: $resumed" >&2
  exit 1
fi
check_rows "resumed after scancel of row $cancelled"

# Ctrl-C (SIGINT to the sweep's process group) cancels the job array: exit 130, the job leaves
# the queue, and the next sweep runs what is missing.
drop_rows 8
"$binary" sweep "$work/sweep.yaml" --out "$work/slurm" --backend slurm \
  >"$work/ctrl_c.out" 2>"$work/ctrl_c.err" &
pid=$!
job=$(job_of "$work/ctrl_c.err")
sleep 0.5
kill -INT -- -"$pid"
code=0
wait "$pid" || code=$?
if ((code != 130)) || ! grep -q "^slurm: cancelled job $job" "$work/ctrl_c.err" ||
  [[ $(tail -n 1 "$work/ctrl_c.err") != "slamrig: interrupted by SIGINT"* ]]; then
  echo "slurm_sweep_test: FAILED: Ctrl-C of the Slurm sweep: exit $code" >&2
  cat "$work/ctrl_c.err" >&2
  exit 1
fi
if [[ -n $(squeue -h -j "$job" -o %i 2>/dev/null) ]]; then
  echo "slurm_sweep_test: FAILED: job $job still queued after Ctrl-C" >&2
  exit 1
fi
"$binary" sweep "$work/sweep.yaml" --out "$work/slurm" --backend slurm --quiet >/dev/null || true
check_rows "resumed after Ctrl-C"

awk -v a="$start" -v b="$mid" -v c="$end" \
  'BEGIN { printf "slurm_sweep_test: ok, 12 identical rows (local %.1f s, slurm %.1f s); " \
          "scancel and Ctrl-C lost and doubled nothing\n", b - a, c - b }'
