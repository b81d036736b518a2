#!/usr/bin/env bash
# Faults that lose nothing (issue 14): `slamrig run`, `simulate`, `slam` and `sweep` writing
# into a full disk (a small tmpfs), into a read-only folder (a tmpfs remounted ro), and stopped
# by SIGTERM or SIGINT after seeded random delays. Every time: exit != 0 (74 for an output
# that cannot be written, 128 + signal for a signal), one line on stderr naming the file or the
# signal, no temporary file left, no completion marker (metrics.json for run and slam,
# sim.yaml for simulate), and every file that is there byte-identical to the one an
# uninterrupted command wrote. A stopped sweep leaves no child running, and the same sweep run
# again (with space, writable again) ends with exactly the rows of an uninterrupted sweep, each
# once. Needs root for mount(8); exits 77 (skipped) with a message when mounting is refused.
#
#   scripts/fault_test.sh [BUILD_DIR]   # default build; needs BUILD_DIR/apps/slamrig
set -euo pipefail
set -m # each background command in its own process group: SIGINT goes to all of it, as Ctrl-C
repo=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
binary=$build/apps/slamrig
work=$build/fault_test
mnt=$work/mnt
[[ -x $binary ]] || {
  echo "fault_test: no $binary (build the slamrig target)" >&2
  exit 1
}
if mountpoint -q "$mnt" 2>/dev/null; then umount "$mnt"; fi
rm -rf "$work"
mkdir -p "$mnt"
cleanup() {
  if mountpoint -q "$mnt" 2>/dev/null; then umount "$mnt" || umount -l "$mnt"; fi
}
trap cleanup EXIT
if ! mount -t tmpfs -o size=1m tmpfs "$mnt" 2>"$work/mount.err"; then
  echo "fault_test: SKIPPED: mount -t tmpfs is not permitted here ($(head -n 1 "$work/mount.err"))"
  exit 77
fi
umount "$mnt"

fail() {
  echo "fault_test: FAILED: $*" >&2
  exit 1
}
RANDOM=14 # seeded: the same delays on every run

# The commands under test, each with its output folder and its completion marker.
cat >"$work/sweep.yaml" <<YAML
scenario: $repo/scenarios/office_loop.yaml
seeds: 2
parameters:
  duration_s: [2, 3]
metrics: [pf.ate_rmse_m, dead_reckoning.ate_rmse_m]
YAML
command_of() { # name out_dir
  case $1 in
  simulate) echo "$binary simulate office --duration 30 --out $2" ;;
  simulate_mcap) echo "$binary simulate office --duration 30 --format mcap --out $2" ;;
  slam) echo "$binary slam $work/ref/simulate/run.log --particles 20 --quiet --out $2" ;;
  run) echo "$binary run office_loop --set duration_s=6 --set slam.pf.particles=20 --quiet --out $2" ;;
  sweep) echo "$binary sweep $work/sweep.yaml --jobs 2 --quiet --out $2" ;;
  esac
}
marker_of() {
  case $1 in
  simulate*) echo sim.yaml ;;
  slam | run) echo metrics.json ;;
  sweep) echo summary.html ;;
  esac
}
# Files that hold wall-clock time and so differ between two identical commands.
timed_file() { [[ $1 == */metrics.json || $1 == */report.html || $1 == */results.csv ]]; }

# Runs a command to completion; `ok` exit codes are 0 and 3 (a short run misses expectations).
run_ok() { # name out_dir
  local code=0
  $(command_of "$1" "$2") >"$2.stdout" 2>"$2.stderr" || code=$?
  ((code == 0 || code == 3)) || fail "$1 exited $code: $(cat "$2.stderr")"
}

# Waits until slamrig (not the shell forked before the exec) catches both signals (SigCgt in
# /proc/PID/status): before that it is still being loaded and the default action applies, so
# delays count from here.
wait_ready() { # pid
  local mask
  for _ in $(seq 1000); do
    # exe first: a mask read before it could still be the shell's.
    if [[ $(readlink "/proc/$1/exe" 2>/dev/null) == "$binary" ]]; then
      mask=$(sed -n 's/^SigCgt:\s*//p' "/proc/$1/status" 2>/dev/null || true)
      [[ -n $mask ]] && (((0x$mask & 0x4002) == 0x4002)) && return 0
    fi
    kill -0 "$1" 2>/dev/null || return 0
    sleep 0.01
  done
}

# Reference outputs, uninterrupted; `slam` reads the simulated log. The time each takes from
# wait_ready to its end is what the signal delays are drawn from: the fastest of three runs, so
# that a reference slowed by a burst of load elsewhere does not push the delays past the end.
mkdir -p "$work/ref" "$work/timing"
declare -A work_ms
for name in simulate simulate_mcap slam run sweep; do
  for attempt in 1 2 3; do
    out=$work/ref/$name
    if ((attempt > 1)); then out=$work/timing/$name.$attempt; fi
    $(command_of "$name" "$out") >"$out.stdout" 2>"$out.stderr" &
    pid=$!
    wait_ready "$pid"
    start=$(date +%s%N)
    code=0
    wait "$pid" || code=$?
    ms=$((($(date +%s%N) - start) / 1000000))
    ((code == 0 || code == 3)) || fail "$name exited $code: $(cat "$out.stderr")"
    if [[ -z ${work_ms[$name]:-} ]] || ((ms < work_ms[$name])); then work_ms[$name]=$ms; fi
  done
done
rm -rf "$work/timing"
rows() { tail -n +2 "$1" | sed 's/,[^,]*$//' | sort; } # results.csv rows, wall time aside
rows "$work/ref/sweep/results.csv" >"$work/ref/sweep.rows"
[[ $(wc -l <"$work/ref/sweep.rows") == 4 ]] || fail "the reference sweep has not 4 rows"

# No temporary file, no marker, and every file present is the reference's, byte for byte.
check_folder() { # name out_dir what
  local name=$1 dir=$2 what=$3 ref=$work/ref/$1 f
  [[ -d $dir ]] || return 0
  if find "$dir" -name '*.tmp*' | grep -q .; then
    fail "$what: temporary files left: $(find "$dir" -name '*.tmp*' | head -n 3 | tr '\n' ' ')"
  fi
  if [[ $name != sweep && -e $dir/$(marker_of "$name") ]]; then
    fail "$what: $(marker_of "$name") written: the folder looks complete"
  fi
  # The list is read whole before the loop: find as a process substitution (`< <(find ...)`)
  # is not waited for, and could still be exiting, with `dir` on its command line, when
  # check_no_children looks for processes naming `dir`.
  local files
  files=$(find "$dir" -type f)
  while IFS= read -r f; do
    [[ -n $f ]] || continue
    local rel=${f#"$dir"/}
    timed_file "$f" && continue
    [[ $name == sweep && $rel == runs/*/log.txt ]] && continue # the run's own error line
    [[ -f $ref/$rel ]] || fail "$what: $rel is not in the uninterrupted output"
    cmp -s "$f" "$ref/$rel" || fail "$what: $rel differs from the uninterrupted one"
  done <<<"$files"
}
# Exactly one line on stderr, matching `pattern`.
check_stderr() { # file pattern what
  local lines
  lines=$(wc -l <"$1")
  ((lines == 1)) || fail "$3: $lines lines on stderr, expected one: $(head -c 600 "$1")"
  grep -Eq -- "$2" "$1" || fail "$3: stderr '$(cat "$1")' does not match '$2'"
}
# A process as /proc shows it: state, parent, executable and command line.
process_info() { # pid
  local state ppid exe cmd
  state=$(sed -n 's/^State:\s*//p' "/proc/$1/status" 2>/dev/null) || true
  ppid=$(sed -n 's/^PPid:\s*//p' "/proc/$1/status" 2>/dev/null) || true
  exe=$(readlink "/proc/$1/exe" 2>/dev/null) || true
  cmd=$(tr '\0' ' ' <"/proc/$1/cmdline" 2>/dev/null) || true
  if [[ -z $state ]]; then
    echo "pid $1: gone by the time it was read"
  else
    echo "pid $1: state ${state:-?}, parent ${ppid:-?}, exe ${exe:-(none)}, command ${cmd:-(none)}"
  fi
}
# No slamrig process still has `dir` on its command line (a sweep's child, or one between fork
# and exec) once the sweep has exited: the sweep waits for every child it started. One look, no
# grace period. Only this build's slamrig counts: a tool naming `dir` (this script's own find or
# cmp, which are waited for anyway) is no child of the sweep. Everything pgrep saw is listed as
# /proc showed it.
check_no_children() { # dir what
  local pids pid seen="" left=0
  pids=$(pgrep -f -- "$1") || true
  for pid in $pids; do
    [[ $(readlink "/proc/$pid/exe" 2>/dev/null) == "$binary" ]] && left=$((left + 1))
    seen+="$(process_info "$pid"); "
  done
  ((left == 0)) || fail "$2: $left slamrig processes left running; pgrep -f saw: $seen"
}
# The sweep in `dir` run again to the end gives the reference rows, each once.
check_resume() { # dir what
  run_ok sweep "$1"
  rows "$1/results.csv" >"$1.rows"
  diff -q "$work/ref/sweep.rows" "$1.rows" >/dev/null ||
    fail "$2: resumed sweep's rows differ: $(diff "$work/ref/sweep.rows" "$1.rows" | head -n 5)"
  local ids
  ids=$(tail -n +2 "$1/results.csv" | cut -d, -f1 | sort | uniq -d)
  [[ -z $ids ]] || fail "$2: rows run twice: $ids"
}

# 1. Signals at random points: delays in [5 %, 60 %] of the command's uninterrupted work time
# (the reference's time varies with the machine's load, so not up to its end). A command done
# before all four of its signals gets up to four more, each at a quarter of the delays.
interrupted=0 finished=0
for name in simulate simulate_mcap slam run sweep; do
  stopped=0 sent=0
  for signal in TERM INT TERM INT TERM INT TERM INT; do
    sent=$((sent + 1))
    if ((sent > 4 && stopped > 0)); then break; fi
    delay_ms=$((work_ms[$name] * (5 + RANDOM % 56) / 100))
    if ((sent > 4)); then delay_ms=$((delay_ms / 4)); fi
    out=$work/signal/$name.$signal.$delay_ms
    mkdir -p "$(dirname "$out")"
    what="$name, SIG$signal after $delay_ms ms"
    $(command_of "$name" "$out") >"$out.stdout" 2>"$out.stderr" &
    pid=$!
    wait_ready "$pid"
    sleep "$(printf '%d.%03d' $((delay_ms / 1000)) $((delay_ms % 1000)))"
    # SIGINT to the process group (Ctrl-C), SIGTERM to the process alone (kill PID).
    if [[ $signal == INT ]]; then target=-$pid; else target=$pid; fi
    kill -s "$signal" -- "$target" 2>/dev/null || true
    code=0
    wait "$pid" || code=$?
    if ((code == 0 || code == 3)); then
      # It was done before the signal came: then it is complete.
      [[ -e $out/$(marker_of "$name") ]] || fail "$what: exit $code without $(marker_of "$name")"
      finished=$((finished + 1))
      continue
    fi
    expected=$((128 + $(kill -l "$signal")))
    ((code == expected)) || fail "$what: exit $code, expected $expected: $(cat "$out.stderr")"
    check_stderr "$out.stderr" "^slamrig: interrupted by SIG$signal" "$what"
    check_folder "$name" "$out" "$what"
    if [[ $name == sweep ]]; then
      check_no_children "$out" "$what"
      check_resume "$out" "$what"
    fi
    interrupted=$((interrupted + 1))
    stopped=$((stopped + 1))
  done
  # A command done before its signal proves nothing: each must have been stopped.
  ((stopped >= 1)) || fail "$name: all $sent signals came after it was done"
done
((interrupted >= 10)) || fail "only $interrupted of 20 signals came before the command was done"

# 2. A full disk: a tmpfs of about half of what the command writes.
for name in simulate simulate_mcap slam run sweep; do
  kib=$(du -sk "$work/ref/$name" | cut -f1)
  mount -t tmpfs -o "size=$((kib / 2 + 4))k" tmpfs "$mnt"
  out=$mnt/$name
  what="$name on a full disk ($((kib / 2 + 4)) KiB of $kib)"
  code=0
  $(command_of "$name" "$out") >"$work/full.stdout" 2>"$work/full.stderr" || code=$?
  ((code == 74)) || fail "$what: exit $code, expected 74: $(cat "$work/full.stderr")"
  check_stderr "$work/full.stderr" "^slamrig: error: $mnt/.*No space left on device" "$what"
  check_folder "$name" "$out" "$what"
  if [[ $name == sweep ]]; then
    check_no_children "$out" "$what"
    mount -o remount,size=$((kib * 2 + 64))k "$mnt"
    check_resume "$out" "$what, resumed with space"
  fi
  umount "$mnt"
done

# 3. A read-only folder: fails at once, before the work, and writes nothing.
for name in simulate slam run sweep; do
  mount -t tmpfs -o size=64m tmpfs "$mnt"
  mkdir -p "$mnt/$name"
  mount -o remount,ro "$mnt"
  out=$mnt/$name
  what="$name into a read-only folder"
  code=0
  $(command_of "$name" "$out") >"$work/ro.stdout" 2>"$work/ro.stderr" || code=$?
  ((code == 74)) || fail "$what: exit $code, expected 74: $(cat "$work/ro.stderr")"
  check_stderr "$work/ro.stderr" "^slamrig: error: $out: .*Read-only file system" "$what"
  [[ -z $(ls -A "$out") ]] || fail "$what: wrote $(ls -A "$out")"
  if [[ $name == sweep ]]; then
    mount -o remount,rw "$mnt"
    check_resume "$out" "$what, run again writable"
  fi
  umount "$mnt"
done

echo "fault_test: ok: $interrupted commands interrupted ($finished done before the signal)," \
  "5 on a full disk, 4 into a read-only folder; resumed sweeps gave the reference rows"
