#!/usr/bin/env python3
"""Dead reckoning as an external slamrig estimator: a start to copy.

    dead_reckoning.py INPUT.log OUTPUT.tum

slamrig runs it as `command: [python3, ./dead_reckoning.py, "{input}", "{output}"]` with
`input: carmen` (docs/external.md). It reads the CARMEN log INPUT and writes one pose per laser
scan to OUTPUT in TUM format (`t x y z qx qy qz qw`, seconds and metres), stamped with the
scan's own time. The pose at a scan is the robot's odometry there: the odometry pose a
ROBOTLASER1 (or FLASER) line carries, or else the ODOM lines interpolated to the scan's time,
expressed in the frame of the first scan. Any frame would do: slamrig places the first pose on
the reference. Python 3 standard library only; exit code 1 with one line on stderr on bad input.
"""

import math
import sys


def compose(a, b):
    """a * b for SE(2) poses (x, y, theta)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], normalise(a[2] + b[2]))


def inverse(a):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2])


def normalise(theta):
    return math.atan2(math.sin(theta), math.cos(theta))


def interpolate(before, after, t):
    """The odometry at time t between two (time, pose) samples (linear, shortest yaw)."""
    (t0, p0), (t1, p1) = before, after
    f = 0.0 if t1 <= t0 else (t - t0) / (t1 - t0)
    dtheta = normalise(p1[2] - p0[2])
    return (p0[0] + f * (p1[0] - p0[0]), p0[1] + f * (p1[1] - p0[1]), normalise(p0[2] + f * dtheta))


def read_log(path):
    """The scans as (time, odometry pose or None) and the ODOM lines as (time, pose)."""
    scans, odometry = [], []
    with open(path) as log:
        for number, line in enumerate(log, 1):
            f = line.split()
            if not f:
                continue
            try:
                if f[0] == "ODOM":  # ODOM x y theta tv rv accel timestamp host logger_timestamp
                    odometry.append((float(f[7]), (float(f[1]), float(f[2]), float(f[3]))))
                elif f[0] == "ROBOTLASER1":
                    # type start fov resolution max_range accuracy remission_mode n r1..rn
                    # m e1..em laser_x laser_y laser_theta x y theta tv rv fs ss ta timestamp ...
                    n = int(f[8])
                    m = int(f[9 + n])
                    k = 10 + n + m
                    pose = (float(f[k + 3]), float(f[k + 4]), float(f[k + 5]))
                    scans.append((float(f[k + 11]), pose))
                elif f[0] == "FLASER":  # n r1..rn x y theta odom_x odom_y odom_theta timestamp ...
                    n = int(f[1])
                    pose = (float(f[n + 5]), float(f[n + 6]), float(f[n + 7]))
                    scans.append((float(f[n + 8]), pose))
                elif f[0] == "RAWLASER1":  # no pose: taken from the ODOM lines
                    n = int(f[8])
                    m = int(f[9 + n])
                    scans.append((float(f[10 + n + m]), None))
            except (IndexError, ValueError) as e:
                raise ValueError(f"{path}:{number}: {f[0]}: {e}") from None
    return scans, odometry


def odometry_at(odometry, t):
    """The ODOM lines interpolated to time t (held at the ends)."""
    if not odometry:
        raise ValueError("a scan without an odometry pose, and no ODOM lines")
    lo, hi = 0, len(odometry)
    while lo < hi:  # the first ODOM at or after t
        mid = (lo + hi) // 2
        lo, hi = (mid + 1, hi) if odometry[mid][0] < t else (lo, mid)
    if lo == 0:
        return odometry[0][1]
    if lo == len(odometry):
        return odometry[-1][1]
    return interpolate(odometry[lo - 1], odometry[lo], t)


def main(argv):
    if len(argv) != 3:
        print("usage: dead_reckoning.py INPUT.log OUTPUT.tum", file=sys.stderr)
        return 2
    try:
        scans, odometry = read_log(argv[1])
        poses = [(t, p if p is not None else odometry_at(odometry, t)) for t, p in scans]
    except (OSError, ValueError) as e:
        print(f"dead_reckoning.py: {e}", file=sys.stderr)
        return 1
    with open(argv[2], "w") as out:
        start = inverse(poses[0][1]) if poses else None
        for t, odom in poses:
            x, y, theta = compose(start, odom)  # in the frame of the first scan
            out.write(f"{t:.9f} {x!r} {y!r} 0 0 0 {math.sin(theta / 2)!r} {math.cos(theta / 2)!r}\n")
    print(f"dead_reckoning.py: {len(poses)} poses from {len(scans)} scans, {len(odometry)} ODOM lines")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
