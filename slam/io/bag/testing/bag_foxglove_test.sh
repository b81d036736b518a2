#!/usr/bin/env bash
# Cross-checks slamrig's ROS 2 bags with Foxglove's independent readers (issue 12, item 3):
# writes MCAP (zstd, lz4, none) and sqlite3 bags of one synthetic run, installs the readers from
# the npm registry into the build folder (never the source tree), and runs bag_check.mjs, which
# decodes every message and compares it with expected.json.
#
# Usage: bag_foxglove_test.sh BUILD_DIR WRITE_TOOL
# Exit 0 on success, 1 on a mismatch, 77 (skipped) when node/npm or the registry is unavailable,
# unless CI=true, where that is a failure.
set -euo pipefail

build_dir=$1
tool=$2
here=$(cd "$(dirname "$0")" && pwd)
modules="$build_dir/node_bag_check"
out="$build_dir/bag_check_out"

unavailable() {
  echo "bag_foxglove_test: $1" >&2
  if [[ "${CI:-}" == "true" ]]; then exit 1; fi
  echo "bag_foxglove_test: skipped" >&2
  exit 77
}

command -v node >/dev/null || unavailable "node not found"
command -v npm >/dev/null || unavailable "npm not found"

# Pinned versions: the check must not change under us.
packages=(
  @mcap/core@2.2.2 @mcap/nodejs@1.0.2 @foxglove/rosbag2-web@4.1.1 @foxglove/sql.js@0.0.4
  @foxglove/rosmsg@5.0.5 @foxglove/rosmsg2-serialization@3.1.0 @foxglove/wasm-zstd@1.0.1
  @foxglove/wasm-lz4@1.0.2 @foxglove/crc@0.0.3 js-yaml@4.3.2
)
stamp="$modules/.installed"
if [[ ! -f "$stamp" || "$(cat "$stamp")" != "${packages[*]}" ]]; then
  mkdir -p "$modules"
  npm install --prefix "$modules" --no-audit --no-fund --silent "${packages[@]}" >&2 ||
    unavailable "npm install failed"
  echo "${packages[*]}" >"$stamp"
fi

"$tool" "$out"
node "$here/bag_check.mjs" "$modules" "$out"
