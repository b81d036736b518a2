#!/usr/bin/env python3
"""How good is a corrected CARMEN log's reference? Its error, measured without ground truth.

Usage: scripts/reference_floor.py LOG LABEL=TRAJECTORY.tum [LABEL=TRAJECTORY.tum ...]
       scripts/reference_floor.py --self-test
  e.g. scripts/reference_floor.py ../shared/datasets/carmen_corrected/edmonton-corrected.log.gz \\
           pf=out/pf/trajectory.tum graph=out/graph/trajectory.tum rbpf=out/rbpf/trajectory.tum

The corrected logs' poses are GMapping's own estimate, not ground truth. Two measures say how far
they can be trusted, for the reference and for each estimate given:

- Map crispness: every return within 15 m, placed by the trajectory's pose of its scan, marks
  its 5 cm cell; a trajectory whose scans agree with one another marks fewer cells (a wall seen
  twice from a wrong pose is drawn twice). Only scans every trajectory places are counted, so
  the counts compare like with like; they do not depend on a rigid motion of the whole map.
- The N-cornered hat: with independent errors, the squared aligned RMSE between trajectories i
  and j is s_i^2 + s_j^2; the least-squares s_k over every pair (at least three trajectories,
  the reference counted) estimates each one's own error, the reference's included. Estimates
  that share a bias (the same scans, the same matcher) look better together than they are, so
  s_reference is an upper bound on what the reference gets wrong only where they are
  independent: read it with the crispness.

Trajectories are paired with the log's scans by stamp (0.5 ms) when that pairs 80 % of them,
else in file order, as scripts/score_real_logs.py does. Needs NumPy (exit 77 without it).
"""
import gzip
import math
import os
import sys

try:
    import numpy as np
except ImportError:
    print("reference_floor.py: needs NumPy (python3-numpy)", file=sys.stderr)
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from score_real_logs import aligned_rmse as pairs_rmse, pair_indices  # noqa: E402

RANGE_M = 15.0
CELL_M = 0.05


def read_scans(path):
    """[(stamp, pose (x, y, yaw), ranges, angle_min, angle_increment)] of the FLASER lines."""
    scans = []
    opener = gzip.open if path.endswith(".gz") else open
    try:
        with opener(path, "rt", errors="replace") as log:
            for number, line in enumerate(log, 1):
                fields = line.split()
                if not fields or fields[0] != "FLASER":
                    continue
                try:
                    n = int(fields[1])
                    ranges = np.array([float(v) for v in fields[2:2 + n]])
                    pose = tuple(float(v) for v in fields[2 + n:5 + n])
                    stamp = float(fields[8 + n])
                except (ValueError, IndexError):
                    sys.exit(f"{path}:{number}: FLASER: malformed line")
                if n < 1 or len(ranges) != n or len(pose) != 3:
                    sys.exit(f"{path}:{number}: FLASER: malformed line")
                increment = math.pi / n if n % 2 == 0 else math.pi / max(n - 1, 1)
                scans.append((stamp, pose, ranges, -math.pi / 2, increment))
    except OSError as error:
        sys.exit(f"{path}: {error.strerror or error}")
    if not scans:
        sys.exit(f"{path}: no FLASER line")
    return scans


def read_tum(path):
    """[(stamp, x, y, yaw)] of a TUM trajectory (`t x y z qx qy qz qw`)."""
    poses = []
    try:
        with open(path) as tum:
            for number, line in enumerate(tum, 1):
                if not line.strip() or line.startswith("#"):
                    continue
                values = line.split()
                try:
                    t, x, y, _, qx, qy, qz, qw = (float(v) for v in values[:8])
                except ValueError:
                    sys.exit(f"{path}:{number}: not a TUM pose line (t x y z qx qy qz qw)")
                yaw = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
                poses.append((t, x, y, yaw))
    except OSError as error:
        sys.exit(f"{path}: {error.strerror}")
    return poses


def pair(estimate, scans):
    """{scan index: (x, y, yaw)} of the estimate, paired as scripts/score_real_logs.py pairs."""
    indices, _ = pair_indices([p[0] for p in estimate], [s[0] for s in scans])
    return {j: estimate[i][1:] for i, j in indices}


def aligned_rmse(a, b):
    """RMSE of a's positions (N x 2) after the rigid 2D motion that best maps them onto b's:
    scripts/score_real_logs.py's metric."""
    return pairs_rmse([(tuple(p), tuple(q)) for p, q in zip(a.tolist(), b.tolist())])


def occupied_cells(scans, poses, indices):
    """Distinct CELL_M cells marked by the returns within RANGE_M of the scans `indices`."""
    cells = []
    for i in indices:
        _, _, ranges, angle_min, increment = scans[i]
        x, y, yaw = poses[i]
        keep = (ranges > 0.05) & (ranges < RANGE_M)
        angles = yaw + angle_min + increment * np.nonzero(keep)[0]
        r = ranges[keep]
        cells.append(np.floor(np.stack([x + r * np.cos(angles), y + r * np.sin(angles)], 1) / CELL_M))
    return len(np.unique(np.concatenate(cells).astype(np.int64), axis=0))


def cornered_hat(labels, rmse):
    """Each trajectory's own error s_k from s_i^2 + s_j^2 = rmse(i, j)^2 (least squares)."""
    pairs = [(i, j) for i in range(len(labels)) for j in range(i + 1, len(labels))]
    design = np.zeros((len(pairs), len(labels)))
    for row, (i, j) in enumerate(pairs):
        design[row, i] = design[row, j] = 1.0
    squares = np.array([rmse[i][j] ** 2 for i, j in pairs])
    variances = np.linalg.lstsq(design, squares, rcond=None)[0]
    return [math.sqrt(max(v, 0.0)) for v in variances]


def self_test():
    """The hat recovers known independent errors; a noisier trajectory marks more cells."""
    rng = np.random.default_rng(1)
    truth = np.cumsum(rng.normal(0.0, 1.0, (20000, 2)), axis=0)
    sigmas = [0.05, 0.08, 0.1, 0.15]  # per axis: each trajectory's RMSE is sigma * sqrt(2)
    noisy = [truth + rng.normal(0.0, s, truth.shape) for s in sigmas]
    rmse = [[aligned_rmse(a, b) for b in noisy] for a in noisy]
    own = cornered_hat([str(s) for s in sigmas], rmse)
    failures = [f"sigma {s}: hat {o:.4f}, expected {s * math.sqrt(2):.4f}"
                for s, o in zip(sigmas, own) if abs(o - s * math.sqrt(2)) > 0.1 * s * math.sqrt(2)]
    ranges = np.full(181, 5.0)
    scans = [(0.0, None, ranges, -math.pi / 2, math.pi / 180)] * 200
    still = {i: (0.0, 0.0, 0.0) for i in range(200)}
    shaken = {i: tuple(rng.normal(0.0, 0.05, 3)) for i in range(200)}
    if not occupied_cells(scans, still, range(200)) < occupied_cells(scans, shaken, range(200)):
        failures.append("a shaken trajectory does not mark more cells than a still one")
    a = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0]])
    turned = a @ np.array([[0.0, 1.0], [-1.0, 0.0]]) + [3.0, -1.0]
    if aligned_rmse(a, turned) > 1e-12:
        failures.append("a rigid motion leaves an aligned RMSE")
    for failure in failures:
        print(f"reference_floor.py --self-test: {failure}", file=sys.stderr)
    print(f"reference_floor.py --self-test: {'failed' if failures else 'passed'}")
    return 1 if failures else 0


def main(argv):
    if argv[:1] == ["--self-test"]:
        return self_test()
    if len(argv) < 2 or argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if argv else 2
    scans = read_scans(argv[0])
    labels, poses = ["reference"], [{i: s[1] for i, s in enumerate(scans)}]
    for argument in argv[1:]:
        label, _, path = argument.partition("=")
        if not path:
            sys.exit(f"reference_floor.py: '{argument}': expected LABEL=TRAJECTORY.tum")
        labels.append(label)
        poses.append(pair(read_tum(path), scans))
    common = sorted(set.intersection(*(set(p) for p in poses)))
    if len(common) < 0.8 * len(scans):
        sys.exit(f"reference_floor.py: only {len(common)} of {len(scans)} scans are placed by "
                 "every trajectory")
    xy = [np.array([p[i][:2] for i in common]) for p in poses]
    rmse = [[aligned_rmse(a, b) for b in xy] for a in xy]
    own = cornered_hat(labels, rmse) if len(labels) >= 3 else [math.nan] * len(labels)
    print(f"{len(common)} of {len(scans)} scans; cells of {CELL_M * 100:.0f} cm marked by the "
          f"returns within {RANGE_M:.0f} m")
    print(f"{'trajectory':<12} {'cells':>8} {'ATE vs ref m':>12} {'own error m':>12}")
    for k, label in enumerate(labels):
        cells = occupied_cells(scans, poses[k], common)
        print(f"{label:<12} {cells:>8} {rmse[k][0]:>12.3f} {own[k]:>12.3f}")
    print("pairwise aligned RMSE (m): " + ", ".join(
        f"{labels[i]}-{labels[j]} {rmse[i][j]:.3f}"
        for i in range(len(labels)) for j in range(i + 1, len(labels))))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
