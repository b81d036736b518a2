#!/usr/bin/env python3
"""Measure intel's per-scan odometry error and the odometry profiles' on simulated runs.

Usage: scripts/odometry_profiles.py SLAMRIG [--seeds N] [--duration S] [PROFILE ...]
  e.g. scripts/odometry_profiles.py build/apps/slamrig

1. `SLAMRIG odometry-noise carmen_corrected/intel-corrected.log.gz`: intel's odometry increment
   between consecutive scans against the GMapping-corrected reference's (the corrected log keeps
   about one scan per metre or half radian of motion).
2. `SLAMRIG world generate office --seed 1`: a generated office whose route turns often (loops,
   in-place turns, dead-end reversals). For each robot profile (default: odom_calibrated
   sick_lms200_1deg odom_intel odom_2x_intel odom_poor) and seeds 1..N:
   `SLAMRIG simulate WORLD --robot P --duration S --seed K`, then
   `SLAMRIG odometry-noise run.log --every-m 1 --every-rad 0.5`: the same statistic against
   the simulation's truth, the scans thinned as GMapping thins them (1 m or 0.5 rad).
Prints a markdown table: per profile the mean over the seeds (and the spread, min-max).
Exit status 0 when every run worked, 1 otherwise.
"""
import os
import re
import subprocess
import sys
import tempfile

DEFAULT_PROFILES = ["odom_calibrated", "sick_lms200_1deg", "odom_intel", "odom_2x_intel",
                    "odom_poor"]
SPACING = ["--every-m", "1", "--every-rad", "0.5"]
FIELDS = ["scans", "path_m", "turned_rad", "rms_m", "rms_rad", "noise_per_m", "noise_per_rad",
          "scale", "rotation_scale", "rotation_per_m", "rotation_per_rad"]
NUMBER = r"([\d.]+)"
LINE = re.compile(
    r"scans (\d+), path N m, per scan RMS N m N rad, noise_per_m N, noise_per_rad N, scale N, "
    r"turned N rad, rotation_scale N, rotation_per_m N, rotation_per_rad N".replace("N", NUMBER))


def measure(slamrig, log, extra):
    out = subprocess.run([slamrig, "odometry-noise", log] + extra, check=True,
                         capture_output=True, text=True).stdout
    m = LINE.search(out)
    if not m:
        raise RuntimeError("unexpected odometry-noise output: " + out)
    v = [float(g) for g in m.groups()]
    return [v[0], v[1], v[7]] + v[2:7] + v[8:]


def row(name, values):
    return "| " + name + " | " + " | ".join(values) + " |"


def main(argv):
    args = [a for a in argv[1:]]
    if not args or args[0].startswith("-"):
        print(__doc__, file=sys.stderr)
        return 2
    slamrig = args.pop(0)
    seeds, duration = 3, 600
    profiles = []
    while args:
        a = args.pop(0)
        if a == "--seeds":
            seeds = int(args.pop(0))
        elif a == "--duration":
            duration = int(args.pop(0))
        else:
            profiles.append(a)
    profiles = profiles or DEFAULT_PROFILES
    print(row("log / profile", FIELDS))
    print(row("---", ["---"] * len(FIELDS)))
    intel = measure(slamrig, "carmen_corrected/intel-corrected.log.gz", [])
    print(row("intel (corrected log)",
              ["%d" % intel[0], "%.1f" % intel[1], "%.1f" % intel[2]] +
              ["%.4f" % v for v in intel[3:]]))
    with tempfile.TemporaryDirectory() as world_dir:
        subprocess.run([slamrig, "world", "generate", "office", "--seed", "1", "--out", world_dir],
                       check=True, capture_output=True)
        world = os.path.join(world_dir, "world.yaml")
        for profile in profiles:
            print_profile(slamrig, world, profile, seeds, duration)
    return 0


def print_profile(slamrig, world, profile, seeds, duration):
    runs = []
    for seed in range(1, seeds + 1):
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run([slamrig, "simulate", world, "--robot", profile, "--duration",
                            str(duration), "--seed", str(seed), "--out", tmp, "--quiet"],
                           check=True)
            runs.append(measure(slamrig, os.path.join(tmp, "run.log"), SPACING))
    cells = ["%d" % runs[0][0], "%.1f" % runs[0][1], "%.1f" % runs[0][2]]
    for i in range(3, len(FIELDS)):
        values = [r[i] for r in runs]
        mean = sum(values) / len(values)
        cells.append("%.4f (%.4f-%.4f)" % (mean, min(values), max(values)))
    print(row(profile, cells))


if __name__ == "__main__":
    sys.exit(main(sys.argv))
