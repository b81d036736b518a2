#!/usr/bin/env bash
# Builds the fuzzers' seed corpora under BUILD_DIR/fuzz_corpora/<target>/ from slices of the
# real files: the logs in $SLAMRIG_DATA_DIR (default ../shared/datasets beside the repository),
# the repository's worlds/, robots/, scenarios/ and worlds/maps/. Nothing here is committed: the
# slices are made afresh on every run (the hand-made seeds live in fuzz/corpus/<target>/).
# A missing dataset folder only leaves its slices out (the repository's own files still seed).
#
#   fuzz/make_corpora.sh BUILD_DIR [TARGET...]   # TARGETs: whose costly seeds to make (bag);
#                                                # default all
set -euo pipefail

if (($# < 1)); then
  echo "usage: $0 BUILD_DIR [TARGET...]" >&2
  exit 2
fi
repo=$(cd "$(dirname "$0")/.." && pwd)
out=$1/fuzz_corpora
data=${SLAMRIG_DATA_DIR:-$repo/../shared/datasets}
lines_head=12   # first lines of a log (its PARAM header and first messages)
lines_middle=6  # and a few from its middle

rm -rf "$out"
targets=(carmen npz ece276a_csv tum map_server world_yaml robot_yaml scenario_yaml sweep_yaml bag)
for t in "${targets[@]}"; do mkdir -p "$out/$t"; done

# Line `from` .. `from + count - 1` of a plain or gzip file.
slice() { # file from count
  zcat -f "$1" | tail -n +"$2" | head -n "$3" || true
}
# Number of lines of a plain or gzip file.
count_lines() { zcat -f "$1" | wc -l; }

# CARMEN logs (and the DP-SLAM log, which the reader must reject cleanly): head and middle
# slices, plain and gzip, and the middle slice turned into a TUM trajectory from FLASER poses.
shopt -s nullglob
for log in "$data"/carmen_corrected/*.log.gz "$data"/dpslam_loop5/*.log.gz; do
  name=$(basename "$log" .log.gz)
  n=$(count_lines "$log")
  slice "$log" 1 "$lines_head" >"$out/carmen/$name.head.log"
  slice "$log" $((n / 2)) "$lines_middle" >"$out/carmen/$name.middle.log"
  gzip -9 -n -c "$out/carmen/$name.head.log" >"$out/carmen/$name.head.log.gz"
  slice "$log" $((n / 2)) 200 | awk '$1 == "FLASER" {
      n = $2; t = $(n + 9); x = $(n + 3); y = $(n + 4); th = $(n + 5);
      printf "%s %s %s 0 0 0 %.9f %.9f\n", t, x, y, sin(th / 2), cos(th / 2) }' |
    head -n 8 >"$out/tum/$name.tum"
done

# ECE276A: csv slices (encoders, NUL, IMU) and npz archives cut to their first columns.
for enc in "$data"/ece276a_pr2_partial/encoders*.csv.gz; do
  number=$(basename "$enc" .csv.gz)
  number=${number#encoders}
  imu="$data/ece276a_pr2_partial/imu$number.csv.gz"
  n=$(count_lines "$enc")
  slice "$enc" 1 "$lines_head" >"$out/ece276a_csv/encoders$number.head.csv"
  {
    slice "$enc" $((n / 2)) "$lines_middle"
    if [[ -f $imu ]]; then
      printf '\0'
      slice "$imu" 1 "$lines_head"
    fi
  } >"$out/ece276a_csv/encoders_imu$number.csv"
done
npz_files=("$data"/ece276a_pr2_partial/*.npz)
if ((${#npz_files[@]} > 0)); then
  python3 - "$out/npz" "${npz_files[@]}" <<'PY'
# Keeps the first columns of every array (the last axis: time), so a seed is a few hundred bytes.
import ast, io, os, struct, sys, zipfile
out, files = sys.argv[1], sys.argv[2:]
keep = 6
for path in files:
    src = zipfile.ZipFile(path)
    dst_bytes = io.BytesIO()
    with zipfile.ZipFile(dst_bytes, 'w', zipfile.ZIP_DEFLATED) as dst:
        for name in src.namelist():
            b = src.read(name)
            major = b[6]
            hl = struct.unpack('<H' if major == 1 else '<I', b[8:10] if major == 1 else b[8:12])[0]
            at = 10 if major == 1 else 12
            header = ast.literal_eval(b[at:at + hl].decode('latin1'))
            shape, item = list(header['shape']), int(header['descr'][2:])
            body = b[at + hl:]
            if shape:
                n, k = shape[-1], min(shape[-1], keep)
                rows = len(body) // (n * item) if n else 0
                if header['fortran_order']:  # column-major: the first k columns come first
                    body = body[:rows * k * item]
                else:
                    body = b''.join(body[r * n * item:(r * n + k) * item] for r in range(rows))
                shape[-1] = k
            text = "{'descr': '%s', 'fortran_order': %s, 'shape': %s, }" % (
                header['descr'], header['fortran_order'], repr(tuple(shape)))
            text += ' ' * ((64 - (10 + len(text) + 1) % 64) % 64) + '\n'
            dst.writestr(name, b'\x93NUMPY\x01\x00' + struct.pack('<H', len(text)) +
                         text.encode('latin1') + body)
    base = os.path.splitext(os.path.basename(path))[0]
    open(os.path.join(out, base + '.npz'), 'wb').write(dst_bytes.getvalue())
PY
fi

# map_server: each map's YAML (image renamed to map.pgm), NUL, the image cropped to 24 x 16.
for yaml in "$repo"/worlds/maps/*.yaml; do
  pgm="$(dirname "$yaml")/$(sed -n 's/^image: *//p' "$yaml")"
  [[ -f $pgm ]] || continue
  {
    sed 's/^image:.*/image: map.pgm/' "$yaml"
    printf '\0'
    python3 - "$pgm" <<'PY'
import sys
b = open(sys.argv[1], 'rb').read()
tokens, at = [], 0
while len(tokens) < 4:  # magic, width, height, maxval (comments skipped)
    while b[at:at + 1].isspace(): at += 1
    if b[at:at + 1] == b'#':
        at = b.index(b'\n', at)
        continue
    end = at
    while not b[end:end + 1].isspace(): end += 1
    tokens.append(b[at:end]); at = end
at += 1
w, h = int(tokens[1]), int(tokens[2])
cw, ch = min(w, 24), min(h, 16)
rows = b''.join(b[at + r * w:at + r * w + cw] for r in range(ch))
sys.stdout.buffer.write(b'P5\n%d %d\n%s\n' % (cw, ch, tokens[3]) + rows)
PY
  } >"$out/map_server/$(basename "$yaml" .yaml)"
done

# The repository's own YAML files, whole.
cp "$repo"/worlds/*.yaml "$out/world_yaml/"
cp "$repo"/robots/*.yaml "$out/robot_yaml/"
cp "$repo"/scenarios/*.yaml "$out/scenario_yaml/"
cp "$repo"/scenarios/sweeps/*.yaml "$out/sweep_yaml/"

# ROS 2 bags as the simulator writes them, in both storages and every MCAP compression: 0.1 and
# 0.3 s of the small robot (360 beams at 10 Hz) with its lidar cut to 32 beams,
# so that a seed is 18 to 80 KiB. Needs BUILD_DIR/apps/slamrig (run_fuzzers.sh builds it).
slamrig=$1/apps/slamrig
if [[ -x $slamrig ]] && { (($# == 1)) || [[ " ${*:2} " == *" bag "* ]]; }; then
  bags=$(mktemp -d)
  sed 's/^  num_beams: .*/  num_beams: 32/; s/^  beams_per_revolution: .*/  beams_per_revolution: 32/' \
    "$repo/robots/small_diff.yaml" >"$bags/tiny.yaml"
  for format in mcap:none mcap:zstd mcap:lz4 sqlite3:; do
    storage=${format%%:*}
    compression=${format#*:}
    args=(--format "$storage")
    if [[ -n $compression ]]; then args+=(--compression "$compression"); fi
    for duration in 0.1 0.3; do
      name=$storage$compression$duration
      ASAN_OPTIONS=detect_leaks=0 "$slamrig" simulate office --robot "$bags/tiny.yaml" \
        --duration "$duration" --out "$bags/$name" "${args[@]}" >/dev/null
      cp "$bags/$name"/run/run_0.* "$out/bag/$name.bag"
    done
  done
  rm -rf "$bags"
fi

for t in "${targets[@]}"; do
  printf 'make_corpora: %-14s %3d seeds\n' "$t" "$(find "$out/$t" -type f | wc -l)"
done
