#!/usr/bin/env bash
# Checks `slamrig run --live` with Foxglove's own WebSocket client (live_check.mjs):
#   1. a short office run without --live: the results to compare with;
#   2. the same run with --live on a free port and --live-wait (held until the watcher
#      subscribes: it must see the run's first second), watched by @foxglove/ws-protocol's client
#      (subscriptions, every message decoded, the latched /tf_static, pacing at 2x real time
#      asked through the slamrig.pace parameter, an unsubscription), which disconnects
#      mid-run, beside a client that subscribes to everything, stops reading and is killed
#      (SIGKILL) mid-run; a second `--live` on the same port must fail at once, before its run;
#   3. the same run with a client that subscribes to everything and never reads: the run
#      still ends (the server drops what does not fit the client's queue);
#   4. a bad port is one line and a non-zero exit;
# and 2 and 3 end with the same metrics.json (but for its wall-clock values: realtime_factor,
# wall_time_s), trajectories and maps as 1.
# The client packages are installed from the npm registry into the build folder.
#
# Usage: live_foxglove_test.sh BUILD_DIR SLAMRIG_BINARY SOURCE_DIR
# Exit 0 on success, 1 on a failure, 77 (skipped) when node/npm or the registry is unavailable,
# unless CI=true, where that is a failure.
set -euo pipefail

build_dir=$1
slamrig=$2
source_dir=$3
here=$(cd "$(dirname "$0")" && pwd)
modules="$build_dir/node_live_check"

unavailable() {
  echo "live_foxglove_test: $1" >&2
  if [[ "${CI:-}" == "true" ]]; then exit 1; fi
  echo "live_foxglove_test: skipped" >&2
  exit 77
}
failed() {
  echo "live_foxglove_test: $1" >&2
  exit 1
}

command -v node >/dev/null || unavailable "node not found (scripts/install_deps.sh installs it)"
command -v npm >/dev/null || unavailable "npm not found (scripts/install_deps.sh installs it)"

# Pinned versions: the check must not change under us. Node 20 has no WebSocket of its own: `ws`.
packages=(
  @foxglove/ws-protocol@0.8.0 ws@8.18.3 @foxglove/rosmsg@5.0.5 @foxglove/rosmsg2-serialization@3.1.0
)
stamp="$modules/.installed"
if [[ ! -f "$stamp" || "$(cat "$stamp")" != "${packages[*]}" ]]; then
  mkdir -p "$modules"
  npm install --prefix "$modules" --no-audit --no-fund --silent "${packages[@]}" >&2 ||
    unavailable "npm install failed"
  echo "${packages[*]}" >"$stamp"
fi

work=$(mktemp -d "$build_dir/live_check.XXXXXX")
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
cd "$source_dir"
run_args=(office_loop --set duration_s=30 --quiet)

# A run whose expectations fail (a short run) still exits 3 with its report: that is fine here.
check_rc() {
  if [[ $2 -ne 0 && $2 -ne 3 ]]; then
    cat "$work/$1.err" >&2 || true
    failed "the $1 run exited $2"
  fi
}

# Starts `slamrig run --live 0 ARGS` as run NAME in the background; sets run_pid and port (from
# the line it says its address with).
start_live() {
  local name=$1
  shift
  "$slamrig" run "${run_args[@]}" --out "$work/$name" --live 0 "$@" >"$work/$name.out" \
    2>"$work/$name.err" &
  run_pid=$!
  pids+=("$run_pid")
  port=""
  for _ in $(seq 100); do
    port=$(sed -n 's|^live: Foxglove WebSocket on ws://127\.0\.0\.1:\([0-9]*\) .*|\1|p' \
      "$work/$name.err")
    if [[ -n $port ]]; then return 0; fi
    kill -0 "$run_pid" 2>/dev/null || break
    sleep 0.1
  done
  failed "$name: no address line: $(cat "$work/$name.err")"
}

# Waits for run_pid, at most $2 seconds.
wait_run() {
  local name=$1 limit=$2 rc=0
  for _ in $(seq $((limit * 10))); do
    kill -0 "$run_pid" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$run_pid" 2>/dev/null; then failed "the $name run did not end within $limit s"; fi
  wait "$run_pid" || rc=$?
  check_rc "$name" "$rc"
}

# The results of run NAME equal those of the plain run.
same_results() {
  node -e '
    const fs = require("fs");
    // Wall-clock values: the only ones a run may change from one time to the next.
    const strip = (v) => {
      if (Array.isArray(v)) return v.map(strip);
      if (v === null || typeof v !== "object") return v;
      const o = {};
      for (const [k, x] of Object.entries(v)) {
        if (k === "realtime_factor" || k === "wall_time_s" || k.includes("realtime_factor")) continue;
        o[k] = strip(x);
      }
      return o;
    };
    const [a, b] = process.argv.slice(1).map((f) => JSON.stringify(strip(JSON.parse(fs.readFileSync(f)))));
    if (a !== b) { console.error("metrics.json differs"); process.exit(1); }
  ' "$work/plain/metrics.json" "$work/$1/metrics.json" || failed "$1: metrics.json differs from the plain run's"
  local n=0
  for f in "$work/plain"/*.tum "$work/plain"/*.pgm; do
    cmp -s "$f" "$work/$1/$(basename "$f")" || failed "$1: $(basename "$f") differs from the plain run's"
    n=$((n + 1))
  done
  echo "live_foxglove_test: $1: the same metrics.json and $n trajectories and maps as without --live"
}

# 1. Without --live.
start=$(date +%s%N)
rc=0
"$slamrig" run "${run_args[@]}" --out "$work/plain" >"$work/plain.out" 2>"$work/plain.err" || rc=$?
check_rc plain "$rc"
plain_ms=$((($(date +%s%N) - start) / 1000000))

# 2. Watched from the start, with a second server on the same port refused before its run starts.
start_live watched --live-wait
rc=0
"$slamrig" run "${run_args[@]}" --out "$work/busy" --live "$port" >/dev/null 2>"$work/busy.err" || rc=$?
if [[ $rc -eq 0 || $rc -eq 3 ]]; then failed "a second --live on port $port exited $rc"; fi
if [[ $(wc -l <"$work/busy.err") -ne 1 ]] || ! grep -q "cannot listen on 127.0.0.1:$port" "$work/busy.err"; then
  failed "a port in use: expected one line naming it, got: $(cat "$work/busy.err")"
fi
if [[ -e "$work/busy" ]]; then failed "a port in use left a report folder"; fi
echo "live_foxglove_test: a port in use: $(cat "$work/busy.err")"
# The watcher first: the run starts when it subscribes. Then, beside it, a client that subscribes
# to everything, stops reading and vanishes (SIGKILL) mid-run.
node "$here/live_check.mjs" "$modules" watch "ws://127.0.0.1:$port" from-start &
watch_pid=$!
pids+=("$watch_pid")
sleep 2
node "$here/live_check.mjs" "$modules" stall "ws://127.0.0.1:$port" >"$work/vanish.out" 2>&1 &
vanish_pid=$!
pids+=("$vanish_pid")
sleep 3
kill -KILL "$vanish_pid" 2>/dev/null || failed "the vanishing client ended before it was killed"
wait "$vanish_pid" 2>/dev/null || true
grep -q "not reading any more" "$work/vanish.out" || failed "the vanishing client never subscribed"
rc=0
wait "$watch_pid" || rc=$?
if [[ $rc -ne 0 ]]; then failed "the watching client failed"; fi
wait_run watched 60
same_results watched

# 3. A client that never reads: the run ends anyway.
start=$(date +%s%N)
start_live stalled --live-pace 0
node "$here/live_check.mjs" "$modules" stall "ws://127.0.0.1:$port" >"$work/stall.out" 2>&1 &
stall_pid=$!
pids+=("$stall_pid")
wait_run stalled 60
stalled_ms=$((($(date +%s%N) - start) / 1000000))
kill "$stall_pid" 2>/dev/null || true
grep -q "not reading any more" "$work/stall.out" || failed "the stalling client never subscribed: $(cat "$work/stall.out")"
echo "live_foxglove_test: with a client that never reads the run took ${stalled_ms} ms (${plain_ms} ms without --live); $(grep '^live:' "$work/stalled.err" | tail -1)"
same_results stalled

# 4. A bad port.
rc=0
"$slamrig" run "${run_args[@]}" --out "$work/bad" --live 70000 >/dev/null 2>"$work/bad.err" || rc=$?
if [[ $rc -eq 0 || $rc -eq 3 || $(wc -l <"$work/bad.err") -ne 1 ]] || ! grep -q -- "--live" "$work/bad.err"; then
  failed "--live 70000: exit $rc, $(cat "$work/bad.err")"
fi
if [[ -e "$work/bad" ]]; then failed "a bad port left a report folder"; fi
echo "live_foxglove_test: passed"
