#!/usr/bin/env bash
# Checks `slamrig run --record` with Foxglove's own readers (record_check.mjs):
#   1. an office run's run.mcap: every message decoded (with the file's schemas and with
#      Foxglove's ROS 2 Humble definitions), topics, types, counts, clock order, and
#      /<config>/pose against <config>.tum;
#   2. the same run again gives the same run.mcap bytes (nothing of the wall clock enters);
#   3. runs with a graph and with landmark estimators (graph and landmark markers, events), a
#      kidnapping, a camera (images, the layout's image panel), and `slamrig slam --record` on
#      a log;
#   4. a run killed with SIGKILL mid-run leaves no run.mcap, and its run.mcap.partial is
#      refused by the indexed reader and decoded by the stream reader up to the cut.
# The readers are installed from the npm registry into the build folder (never the source tree).
#
# Usage: record_foxglove_test.sh BUILD_DIR SLAMRIG_BINARY SOURCE_DIR [PART]
# PART: office (1, 2 and 4), estimators (3) or all (the default); CTest runs the two parts side by
# side.
# Exit 0 on success, 1 on a failure, 77 (skipped) when node/npm or the registry is unavailable,
# unless CI=true, where that is a failure.
set -euo pipefail

build_dir=$1
slamrig=$2
source_dir=$3
part=${4:-all}
case $part in
  office | estimators | all) ;;
  *)
    echo "record_foxglove_test: PART must be office, estimators or all, got '$part'" >&2
    exit 2
    ;;
esac
here=$(cd "$(dirname "$0")" && pwd)
modules="$build_dir/node_record_check"

unavailable() {
  echo "record_foxglove_test: $1" >&2
  if [[ "${CI:-}" == "true" ]]; then exit 1; fi
  echo "record_foxglove_test: skipped" >&2
  exit 77
}

command -v node >/dev/null || unavailable "node not found (scripts/install_deps.sh installs it)"
command -v npm >/dev/null || unavailable "npm not found (scripts/install_deps.sh installs it)"

# Pinned versions: the check must not change under us.
packages=(
  @mcap/core@2.2.2 @mcap/nodejs@1.0.2 @mcap/support@1.1.0 @foxglove/rosmsg@5.0.5
  @foxglove/rosmsg2-serialization@3.1.0 @foxglove/rosmsg-msgs-common@3.2.3
)
stamp="$modules/.installed"
mkdir -p "$modules"
# The parts may run at once: one installs while the other waits on the lock.
exec 9>"$modules.lock"
flock 9
if [[ ! -f "$stamp" || "$(cat "$stamp")" != "${packages[*]}" ]]; then
  npm install --prefix "$modules" --no-audit --no-fund --silent "${packages[@]}" >&2 ||
    unavailable "npm install failed"
  echo "${packages[*]}" >"$stamp"
fi
flock -u 9

work=$(mktemp -d "$build_dir/record_check.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$source_dir"

# A run whose expectations fail (a short run) still exits 3 with its report: that is fine here.
run() {
  local rc=0
  "$slamrig" run "$@" --quiet >/dev/null || rc=$?
  if [[ $rc -ne 0 && $rc -ne 3 ]]; then
    echo "record_foxglove_test: slamrig run $* exited $rc" >&2
    exit 1
  fi
}

office() {
  # 1 and 2: the office run, twice.
  run office_loop --record --set duration_s=60 --out "$work/a"
  node "$here/record_check.mjs" "$modules" full "$work/a" "$source_dir/foxglove/slamrig.json"
  run office_loop --record --set duration_s=60 --out "$work/b"
  if ! cmp "$work/a/run.mcap" "$work/b/run.mcap"; then
    echo "record_foxglove_test: the same run gave different run.mcap bytes" >&2
    exit 1
  fi
  echo "record_foxglove_test: the same run gives the same run.mcap ($(stat -c %s "$work/a/run.mcap") bytes)"

  killed
}

estimators() {
  # 3: graph SLAM with loop closures, EKF-SLAM with landmarks, a kidnapping (events).
  run generated_office --record --set duration_s=90 --out "$work/graph"
  node "$here/record_check.mjs" "$modules" full "$work/graph" "$source_dir/foxglove/slamrig.json"
  run pillars --record --set duration_s=60 --out "$work/pillars"
  node "$here/record_check.mjs" "$modules" full "$work/pillars"
  run kidnapping --record --set duration_s=90 --out "$work/kidnap"
  node "$here/record_check.mjs" "$modules" full "$work/kidnap"

  # A robot with a camera: the images and their mounts, and the layout's image panel.
  run office_camera --record --set duration_s=8 --out "$work/camera"
  node "$here/record_check.mjs" "$modules" full "$work/camera" "$source_dir/foxglove/slamrig.json"

  # `slamrig slam LOG --record` on a log (a simulated CARMEN log: ODOM lines, no IMU).
  "$slamrig" simulate office --duration 30 --out "$work/log" --quiet
  "$slamrig" slam "$work/log/run.log" --out "$work/slam" --record --quiet >/dev/null
  node "$here/record_check.mjs" "$modules" full "$work/slam"

}

killed() {
  # 4: SIGKILL mid-run.
  "$slamrig" run office_loop --record --out "$work/killed" --quiet >/dev/null 2>&1 &
  pid=$!
  # Until the recording has a few chunks on disk (at most 60 s), then the kill.
  for _ in $(seq 600); do
    size=$(stat -c %s "$work/killed/run.mcap.partial" 2>/dev/null || echo 0)
    if [[ $size -gt 4000000 ]]; then break; fi
    sleep 0.1
  done
  kill -KILL "$pid"
  wait "$pid" 2>/dev/null || true
  if [[ -e "$work/killed/run.mcap" ]]; then
    echo "record_foxglove_test: a killed run left a run.mcap" >&2
    exit 1
  fi
  if [[ -e "$work/killed/metrics.json" ]]; then
    echo "record_foxglove_test: a killed run left a metrics.json" >&2
    exit 1
  fi
  if [[ ! -e "$work/killed/run.mcap.partial" ]]; then
    echo "record_foxglove_test: the killed run left no run.mcap.partial to check" >&2
    exit 1
  fi
  node "$here/record_check.mjs" "$modules" partial "$work/killed/run.mcap.partial"
}

case $part in
  office) office ;;
  estimators) estimators ;;
  all)
    office
    estimators
    ;;
esac
echo "record_foxglove_test: $part passed"
