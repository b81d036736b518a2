#!/usr/bin/env python3
"""Reads `slamrig simulate --format ece276a` output the way the ECE276A reports' Python does.

An independent reader of the layout (numpy for the npz files, a small zlib PNG decoder for the
images, the reports' formulas), so the check does not share code with slamrig's reader:
  - the arrays and shapes the reports' load_data() takes (Encoders, Imu, Hokuyo, Kinect);
  - dead reckoning as the reports do it (v from the encoders at 0.0022 m per tick, yaw rate from
    the IMU's z gyro) ends near the simulator's truth;
  - a Kinect disparity image through depth = 1.03 / (-0.00304 d + 3.31), the reports' intrinsics
    and the robot's camera mounting puts the floor pixels at height 0 in the world.

Usage: recording_ece276a_check.py SLAMRIG OUT_DIR
Exit 0 when every check passes, 1 with one line per failure otherwise.
"""
import math
import os
import shutil
import struct
import subprocess
import sys
import zlib

import numpy as np

FAILURES = []


def check(ok, message):
    if not ok:
        FAILURES.append(message)


def read_png(path):
    """8-bit RGB or 16-bit grey PNG (no interlace) as a numpy array, rows top first."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    assert interlace == 0, path
    channels = {0: 1, 2: 3}[colour]
    bpp = channels * depth // 8  # bytes per pixel
    stride = width * bpp
    raw = zlib.decompress(idat)
    out = np.zeros((height, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for r in range(height):
        kind = raw[r * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, r * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, dtype=np.int32)
        if kind == 0:
            cur = line
        elif kind == 2:
            cur = (line + prev) & 0xFF
        elif kind in (1, 3, 4):
            for i in range(stride):
                a = cur[i - bpp] if i >= bpp else 0
                b = prev[i]
                if kind == 1:
                    pred = a
                elif kind == 3:
                    pred = (a + b) // 2
                else:
                    c = prev[i - bpp] if i >= bpp else 0
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[i] = (line[i] + pred) & 0xFF
        else:
            raise ValueError(f"{path}: filter {kind}")
        out[r] = cur
        prev = cur
    if depth == 16:
        return (out[:, 0::2] << 8 | out[:, 1::2]).reshape(height, width)
    return out.reshape(height, width, channels)


def main():
    slamrig, out = sys.argv[1], sys.argv[2]
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "..", "robots", "ece276a.yaml")) as f:
        robot = f.read()
    # The ECE276A Kinect as the reports describe it (640 x 480, f = 585.05 px), at 2 Hz.
    robot_path = os.path.join(out, "robot.in.yaml")
    with open(robot_path, "w") as f:
        f.write(robot + "camera: {rate_hz: 2}\n")
    run = os.path.join(out, "run")
    subprocess.run([slamrig, "simulate", "office", "--robot", robot_path, "--duration", "12",
                    "--format", "ece276a", "--dataset", "21", "--out", run], check=True,
                   stdout=subprocess.DEVNULL)

    # The reports' load_data().
    with np.load(os.path.join(run, "Encoders21.npz")) as d:
        counts, enc_t = d["counts"], d["time_stamps"]
    with np.load(os.path.join(run, "Hokuyo21.npz")) as d:
        angle_min, angle_max = float(d["angle_min"]), float(d["angle_max"])
        angle_inc, ranges, lidar_t = float(d["angle_increment"]), d["ranges"], d["time_stamps"]
        range_max = float(d["range_max"])
    with np.load(os.path.join(run, "Imu21.npz")) as d:
        gyro, accel, imu_t = d["angular_velocity"], d["linear_acceleration"], d["time_stamps"]
    with np.load(os.path.join(run, "Kinect21.npz")) as d:
        disp_t, rgb_t = d["disparity_time_stamps"], d["rgb_time_stamps"]

    check(counts.shape == (4, enc_t.size) and enc_t.size > 400, f"counts {counts.shape}")
    check(ranges.shape == (1081, lidar_t.size) and ranges.dtype == np.float32,
          f"ranges {ranges.shape} {ranges.dtype}")
    check(abs(angle_min + 0.75 * math.pi) < 1e-6 and abs(angle_max - 0.75 * math.pi) < 1e-6,
          f"lidar angles {angle_min} .. {angle_max}")
    check(abs(angle_inc - math.radians(0.25)) < 1e-9, f"angle_increment {angle_inc}")
    check(range_max == 30.0, f"range_max {range_max}")
    check(gyro.shape == (3, imu_t.size) and abs(np.median(accel[2]) - 1.0) < 0.05,
          f"imu {gyro.shape}, median az {np.median(accel[2])} g")
    check(disp_t.size == rgb_t.size == 24, f"{disp_t.size} disparity, {rgb_t.size} rgb stamps")

    # Dead reckoning as the reports do it: 0.0022 m per tick, the yaw rate from the IMU.
    truth = np.loadtxt(os.path.join(run, "truth.tum"))
    x, y, th = truth[0, 1], truth[0, 2], 0.0
    wz = np.interp(enc_t, imu_t, gyro[2])
    for i in range(1, enc_t.size):
        tau = enc_t[i] - enc_t[i - 1]
        dr = (counts[0, i] + counts[2, i]) / 2 * 0.0022
        dl = (counts[1, i] + counts[3, i]) / 2 * 0.0022
        v = (dr + dl) / 2 / tau
        x += v * tau * math.cos(th)
        y += v * tau * math.sin(th)
        th += wz[i] * tau
    end = truth[-1]
    q_yaw = 2 * math.atan2(end[6], end[7])
    path = np.sum(np.hypot(np.diff(truth[:, 1]), np.diff(truth[:, 2])))
    error = math.hypot(x - end[1], y - end[2])
    check(path > 3.0, f"the robot drove {path:.2f} m")
    check(error < 0.05 * path + 0.05, f"dead reckoning ends {error:.3f} m off after {path:.2f} m")
    check(abs(math.remainder(th - q_yaw, 2 * math.pi)) < 0.05, f"yaw {th} vs {q_yaw}")

    # Texture mapping's first step: disparity -> depth -> world; the floor comes out flat.
    k = 5
    disparity = read_png(os.path.join(run, "dataRGBD", "Disparity21", f"disparity21_{k}.png"))
    rgb = read_png(os.path.join(run, "dataRGBD", "RGB21", f"rgb21_{k}.png"))
    check(disparity.shape == (480, 640) and rgb.shape == (480, 640, 3),
          f"images {disparity.shape} {rgb.shape}")
    valid = disparity < 2047
    depth = 1.03 / (-0.00304 * disparity + 3.31)
    fsu, cu, cv = 585.05108211, 315.83800193, 242.94140713
    v, u = np.mgrid[0:480, 0:640]
    # Optical (x right, y down, z forward) -> camera body (x forward, y left, z up) -> robot.
    xo = (u - cu) / fsu * depth + 0.025  # the depth camera sits 2.5 cm right of the colour one
    yo, zo = (v - cv) / fsu * depth, depth
    cam = np.stack([zo, -xo, -yo])
    roll, pitch, yaw = 0.0, 0.36, 0.021
    rz = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]])
    ry = np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0],
                   [-math.sin(pitch), 0, math.cos(pitch)]])
    base = (rz @ ry).reshape(3, 3) @ cam.reshape(3, -1) + np.array([[0.18], [0.005], [0.36]])
    z_world = base[2].reshape(480, 640)
    bottom = valid & (v > 360)
    flat = np.abs(z_world[bottom]) < 0.03
    check(bottom.sum() > 10000, f"only {bottom.sum()} valid pixels in the bottom rows")
    check(flat.mean() > 0.95, f"{100 * flat.mean():.1f}% of the bottom rows' pixels at floor height")

    for f in FAILURES:
        print("recording_ece276a_check:", f)
    if FAILURES:
        return 1
    print(f"recording_ece276a_check: all checks pass (dead reckoning {error:.3f} m off after "
          f"{path:.2f} m, {100 * flat.mean():.1f}% of floor pixels within 3 cm of z = 0)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
