#!/usr/bin/env python3
"""Score `slamrig slam` on every corrected CARMEN log of the data folder.

Usage: scripts/score_real_logs.py SLAMRIG [--only NAME,...] [-- SLAM_ARGS...]
  e.g. scripts/score_real_logs.py build/apps/slamrig --only intel -- --algorithm pf --seed 2

For each `*-corrected.log.gz` in DATA/carmen_corrected (DATA is $SLAMRIG_DATA_DIR, else
../shared/datasets of the current folder, else of the repository's folder) this runs
`SLAMRIG slam LOG --out TMP SLAM_ARGS...`, reads TMP/trajectory.tum and compares its positions
with the log's corrected FLASER poses: the ATE RMSE after the rigid 2D motion that fits them
best (closed form). Estimate and reference are paired by stamp (0.5 ms buckets) when that pairs
at least 80 % of the scans, else scan by scan in file order. It prints one line per log and the
worst ATE. Python 3 standard library only, so it checks the project's own metric independently.
Exit status: 0 when every selected log ran and was scored, 1 otherwise, 2 for a bad command line.
"""
import gzip
import math
import os
import subprocess
import sys
import tempfile
import time

SUFFIX = "-corrected.log.gz"


def data_folder():
    """The data folder as slamrig finds it (SLAMRIG_DATA_DIR or ../shared/datasets)."""
    if os.environ.get("SLAMRIG_DATA_DIR"):
        return os.environ["SLAMRIG_DATA_DIR"]
    repository = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    for base in (os.getcwd(), repository):
        candidate = os.path.join(base, "..", "shared", "datasets")
        if os.path.isdir(candidate):
            return os.path.normpath(candidate)
    return os.path.normpath(os.path.join(os.getcwd(), "..", "shared", "datasets"))


def read_reference(path):
    """[(stamp, x, y)] of the FLASER lines: the corrected pose follows the n ranges."""
    poses = []
    with gzip.open(path, "rt", errors="replace") as log:
        for number, line in enumerate(log, 1):
            fields = line.split()
            if not fields or fields[0] != "FLASER":
                continue
            try:
                beams = int(fields[1])
                stamp = float(fields[8 + beams])
                poses.append((stamp, float(fields[2 + beams]), float(fields[3 + beams])))
            except (ValueError, IndexError):
                raise ValueError(f"{path}:{number}: FLASER: malformed line")
    return poses


def read_tum(path):
    """[(stamp, x, y)] of a TUM trajectory (`t x y z qx qy qz qw`)."""
    poses = []
    with open(path) as tum:
        for number, line in enumerate(tum, 1):
            if not line.strip() or line.startswith("#"):
                continue
            try:
                t, x, y = (float(v) for v in line.split()[:3])
            except ValueError:
                raise ValueError(f"{path}:{number}: not a TUM pose line")
            poses.append((t, x, y))
    return poses


def pair_indices(estimate_stamps, reference_stamps):
    """[(estimate index, reference index)] and how they were paired ('time' or 'index'): by stamp
    (0.5 ms buckets, the first reference of a bucket) when that pairs 80 % of the shorter, else
    in order."""
    bucket = lambda t: round(t * 2000)  # 0.5 ms
    first_at = {}
    for j, t in enumerate(reference_stamps):
        first_at.setdefault(bucket(t), j)
    by_time = [(i, first_at[bucket(t)]) for i, t in enumerate(estimate_stamps)
               if bucket(t) in first_at]
    if len(by_time) >= 0.8 * min(len(estimate_stamps), len(reference_stamps)):
        return by_time, "time"
    return [(i, i) for i in range(min(len(estimate_stamps), len(reference_stamps)))], "index"


def pair_poses(estimate, reference):
    """[((x, y) estimated, (x, y) reference)] and how they were paired ('time' or 'index')."""
    indices, how = pair_indices([p[0] for p in estimate], [p[0] for p in reference])
    return [(estimate[i][1:], reference[j][1:]) for i, j in indices], how


def aligned_rmse(pairs):
    """RMSE of the estimate's positions after the rotation and translation that best map them
    onto the reference (least squares: the angle of the centred cross-covariance)."""
    if not pairs:
        return math.inf
    n = len(pairs)
    mean_e = [sum(e[k] for e, _ in pairs) / n for k in (0, 1)]
    mean_r = [sum(r[k] for _, r in pairs) / n for k in (0, 1)]
    cos_sum = sin_sum = 0.0
    for (ex, ey), (rx, ry) in pairs:
        ex, ey = ex - mean_e[0], ey - mean_e[1]
        rx, ry = rx - mean_r[0], ry - mean_r[1]
        cos_sum += ex * rx + ey * ry
        sin_sum += ex * ry - ey * rx
    angle = math.atan2(sin_sum, cos_sum)
    c, s = math.cos(angle), math.sin(angle)
    squares = 0.0
    for (ex, ey), (rx, ry) in pairs:
        ex, ey = ex - mean_e[0], ey - mean_e[1]
        dx = c * ex - s * ey + mean_r[0] - rx
        dy = s * ex + c * ey + mean_r[1] - ry
        squares += dx * dx + dy * dy
    return math.sqrt(squares / n)


def parse_arguments(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if argv else 2)
    slamrig, rest, only = os.path.abspath(argv[0]), argv[1:], None
    if rest[:1] == ["--only"]:
        if len(rest) < 2:
            sys.exit("score_real_logs.py: --only needs NAME,...")
        only, rest = set(rest[1].split(",")), rest[2:]
    if rest[:1] == ["--"]:
        rest = rest[1:]
    elif rest:
        sys.exit(f"score_real_logs.py: unexpected argument '{rest[0]}' (slamrig's go after --)")
    return slamrig, only, rest


def main(argv):
    slamrig, only, slam_arguments = parse_arguments(argv)
    folder = os.path.join(data_folder(), "carmen_corrected")
    if not os.path.isdir(folder):
        print(f"score_real_logs.py: {folder}: no such folder (set SLAMRIG_DATA_DIR)", file=sys.stderr)
        return 1
    logs = sorted(f for f in os.listdir(folder) if f.endswith(SUFFIX))
    if only:
        unknown = only - {f[: -len(SUFFIX)] for f in logs}
        if unknown:
            print(f"score_real_logs.py: --only: no log named {', '.join(sorted(unknown))} in "
                  f"{folder}", file=sys.stderr)
            return 2
        logs = [f for f in logs if f[: -len(SUFFIX)] in only]
    print(f"{'log':<30} {'scans':>6} {'paired':>7} {'ATE RMSE m':>11} {'wall s':>7}")
    worst, ok = 0.0, True
    for log in logs:
        name, path = log[: -len(SUFFIX)], os.path.join(folder, log)
        with tempfile.TemporaryDirectory() as out:
            start = time.monotonic()
            run = subprocess.run([slamrig, "slam", path, "--out", out] + slam_arguments,
                                 capture_output=True, text=True)
            seconds = time.monotonic() - start
            if run.returncode != 0:
                last = (run.stderr.strip().splitlines() or ["(no message)"])[-1]
                print(f"{name:<30} failed (exit {run.returncode}): {last}")
                worst, ok = math.inf, False
                continue
            pairs, how = pair_poses(read_tum(os.path.join(out, "trajectory.tum")),
                                    read_reference(path))
        error = aligned_rmse(pairs)
        worst = max(worst, error)
        print(f"{name:<30} {len(pairs):>6} {how:>7} {error:>11.4f} {seconds:>7.1f}")
    print(f"worst ATE RMSE: {worst:.4f} m")
    return 0 if ok and logs else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
