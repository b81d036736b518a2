#!/usr/bin/env bash
# The installed slamrig works from an empty folder outside the repository: `cmake --install` into a
# temporary prefix, then the default `slamrig run` there must pass, with its scenario, world and
# robot taken from the prefix's share/slamrig (not from the source tree).
# Usage: install_test.sh BUILD_DIR
set -euo pipefail
build=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
mkdir "$tmp/work"
cd "$tmp/work"
"$tmp/prefix/bin/slamrig" run --quiet
grep -q "Resolved from $tmp/prefix/share/slamrig/scenarios/office_loop.yaml" out/office_loop/config.yaml
test -f out/office_loop/report.html
echo "install_test: installed slamrig run passed from $tmp/work"
