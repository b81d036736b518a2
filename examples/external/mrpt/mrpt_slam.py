#!/usr/bin/env python3
"""MRPT's ICP-SLAM or RBPF-SLAM (Debian mrpt-apps) as an external slamrig estimator.

    mrpt_slam.py INPUT.log OUTPUT.tum --method icp|rbpf [--particles N] [--seed S]

slamrig runs it with `input: carmen` (docs/external.md). Its steps, all in the folder
OUTPUT's folder/mrpt/:
  1. the CARMEN log's ROBOTLASER1 lines, each scan turned so that it is symmetric about the
     laser's heading (MRPT spreads a scan's beams over -fov/2..+fov/2), are written to
     mrpt_input.log and converted by MRPT's carmen2rawlog to an observation-only rawlog;
  2. rawlog_to_sf.cc (beside this file, compiled once against the Debian MRPT headers into
     ~/.cache/slamrig-mrpt/) turns it into the action/sensory-frame rawlog that rbpf-slam needs,
     one entry per scan, each stamped with its scan's time (made strictly increasing: MRPT's
     odometry filter ignores a reading not later than the one before);
  3. icp-slam or rbpf-slam runs on it with icp.ini or rbpf.ini (beside this file; headless, no
     window, no 3D scene), stdout and stderr to mrpt/NAME.out;
  4. its per-step path log_estimated_path.txt (one pose per entry, so per scan) becomes OUTPUT,
     a TUM trajectory stamped with the scans' own times (as slamrig asks: one pose per scan);
     rbpf-slam's final occupancy grid becomes a map_server map beside it (OUTPUT.yaml and .pgm).

Any failure: exit code 1 and one line on stderr; OUTPUT is written only when all went well.
Python 3 standard library only.
"""

import argparse
import hashlib
import math
import os
import shutil
import struct
import subprocess
import sys
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
PROGRAMS = {"icp": "icp-slam", "rbpf": "rbpf-slam"}


class Failure(Exception):
    pass


def convert_scans(path, mrpt_log):
    """Writes the ROBOTLASER1 lines to mrpt_log, each scan symmetric (symmetric_line), and
    returns the scans' times. Any other laser message is refused. A line at a time: a long run
    has gigabytes of ranges."""
    times = []
    with open(path) as log, open(mrpt_log, "w") as out:
        for number, line in enumerate(log, 1):
            f = line.split()
            if not f or f[0] in ("PARAM", "ODOM", "TRUEPOS") or f[0].startswith("#"):
                continue
            if f[0] != "ROBOTLASER1":
                raise Failure(f"{path}:{number}: {f[0]}: only ROBOTLASER1 lines carry a scan here")
            try:
                n = int(f[8])
                k = 10 + n + int(f[9 + n])  # the laser pose, after the ranges and remissions
                if len(f) < k + 12:
                    raise ValueError(f"{len(f)} fields, {k + 12} needed")
                times.append(float(f[k + 11]))
                out.write(symmetric_line(f, k))
            except (IndexError, ValueError) as e:
                raise Failure(f"{path}:{number}: ROBOTLASER1: {e}") from None
    if not times:
        raise Failure(f"{path}: no ROBOTLASER1 line (no scans)")
    return times


def symmetric_line(f, k):
    """A ROBOTLASER1 line (fields f, laser pose at f[k]) whose scan starts at -fov/2: the
    laser's heading turned to the scan's centre."""
    start, fov = float(f[2]), float(f[3])
    f[k + 2] = repr(float(f[k + 2]) + start + fov / 2)
    f[2] = repr(-fov / 2)
    return " ".join(f) + "\n"


def mrpt_times(times):
    """The scans' times, each at least 1 us after the one before."""
    increasing, last = [], -math.inf
    for t in times:
        last = max(t, last + 1e-6)
        increasing.append(last)
    return increasing


def run(command, log_path):
    """Runs an MRPT program headless, its output to log_path; a failure names its last line."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    with open(log_path, "w") as log:
        result = subprocess.run(command, stdin=subprocess.DEVNULL, stdout=log,
                                stderr=subprocess.STDOUT, env=env)
    if result.returncode != 0:
        lines = [l.strip() for l in open(log_path, errors="replace") if l.strip()]
        # An MRPT exception: its "Message:" line says what; the last line is a prompt.
        lines = [l for l in lines if l.startswith("Message:")] or [
            l for l in lines if not l.startswith("Press any key")]
        how = (f"killed by signal {-result.returncode}" if result.returncode < 0
               else f"exit code {result.returncode}")
        raise Failure(f"{command[0]}: {how}: {lines[-1] if lines else 'no output'} "
                      f"(all of it in {log_path})")


def rawlog_to_sf():
    """The converter's binary: SLAMRIG_MRPT_RAWLOG_TO_SF, or rawlog_to_sf.cc compiled once."""
    if os.environ.get("SLAMRIG_MRPT_RAWLOG_TO_SF"):
        return os.environ["SLAMRIG_MRPT_RAWLOG_TO_SF"]
    source = HERE / "rawlog_to_sf.cc"
    digest = hashlib.sha1(source.read_bytes()).hexdigest()[:12]
    cache = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "slamrig-mrpt"
    binary = cache / f"rawlog_to_sf-{digest}"
    if binary.exists():
        return str(binary)
    if not Path("/usr/include/mrpt/obs").is_dir():
        raise Failure("libmrpt-obs-dev is not installed: apt-get install libmrpt-obs-dev")
    cache.mkdir(parents=True, exist_ok=True)
    includes = [f"-I{d}" for d in sorted(Path("/usr/include/mrpt").glob("*/include"))]
    libs = [f"-lmrpt-{m}" for m in ("obs", "poses", "serialization", "io", "system", "math",
                                    "rtti", "core")]
    partial = cache / f"rawlog_to_sf-{digest}.{os.getpid()}"
    run(["c++", "-std=c++17", "-O2", *includes, "-I/usr/include/eigen3", str(source),
         "-o", str(partial), *libs], cache / f"rawlog_to_sf-{digest}.build.txt")
    partial.replace(binary)
    return str(binary)


def read_path(path, count):
    """log_estimated_path.txt: 'step x y yaw' (icp-slam) or 'step x y z yaw pitch roll t'."""
    poses = []
    for number, line in enumerate(open(path), 1):
        f = line.split()
        if not f or f[0].startswith("%"):
            continue
        try:
            if len(f) not in (4, 8) or int(f[0]) != len(poses):
                raise ValueError(f"expected step {len(poses)} with 4 or 8 fields")
            yaw = float(f[3] if len(f) == 4 else f[4])
            pose = (float(f[1]), float(f[2]), yaw)
            if not all(map(math.isfinite, pose)):
                raise ValueError("not finite")
        except ValueError as e:
            raise Failure(f"{path}:{number}: {e}") from None
        poses.append(pose)
    if len(poses) != count:
        raise Failure(f"{path}: {len(poses)} poses for {count} scans")
    return poses


def read_png_grey(path):
    """The rows of an 8-bit grey, non-interlaced PNG (what MRPT saves a grid as)."""
    data = Path(path).read_bytes()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise Failure(f"{path}: not a PNG")
    pos, compressed, header = 8, b"", None
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", data[pos + 8:pos + 21])
        elif kind == b"IDAT":
            compressed += data[pos + 8:pos + 8 + length]
        pos += 12 + length
    if header is None or (header[2], header[3], header[6]) != (8, 0, 0):
        raise Failure(f"{path}: not an 8-bit grey PNG")
    width, height = header[0], header[1]
    raw = zlib.decompress(compressed)
    if len(raw) != height * (width + 1):
        raise Failure(f"{path}: {len(raw)} bytes of pixels for {width} x {height}")
    rows, above = [], bytearray(width)
    for r in range(height):
        kind, row = raw[r * (width + 1)], bytearray(raw[r * (width + 1) + 1:(r + 1) * (width + 1)])
        for i in range(width):  # the five PNG filters, one byte a pixel
            a, b, c = (row[i - 1] if i else 0), above[i], (above[i - 1] if i else 0)
            if kind == 4:  # Paeth: the neighbour nearest a + b - c
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                a = a if pa <= pb and pa <= pc else b if pb <= pc else c
            row[i] = (row[i] + (0, a, b, (a + b) // 2, a)[kind]) & 255
        rows.append(bytes(row))
        above = row
    return width, height, rows


def write_map(out_dir, output):
    """rbpf-slam's final grid (PNG, row 0 at y_max, white free) as a map_server map beside output."""
    png = out_dir / "finalMap_mrpt__maps__COccupancyGridMap2D_00.png"
    limits = out_dir / "finalMap_mrpt__maps__COccupancyGridMap2D_00_limits.txt"
    width, height, rows = read_png_grey(png)
    try:
        x_min, x_max, y_min, y_max = map(float, limits.read_text().splitlines()[1].split())
    except (IndexError, ValueError) as e:
        raise Failure(f"{limits}: {e}") from None
    resolution = (x_max - x_min) / width
    if abs((y_max - y_min) / height - resolution) > 1e-6 * resolution:
        raise Failure(f"{limits}: the limits do not fit a {width} x {height} grid")
    pgm = output.with_suffix(".pgm")
    pgm.write_bytes(f"P5\n{width} {height}\n255\n".encode() + b"".join(rows))
    output.with_suffix(".yaml").write_text(
        f"image: {pgm.name}\nresolution: {resolution!r}\norigin: [{x_min!r}, {y_min!r}, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")


def write_tum(path, times, poses):
    partial = path.with_name(path.name + ".partial")
    with open(partial, "w") as out:
        for t, (x, y, yaw) in zip(times, poses):
            out.write(f"{t:.9f} {x:.9f} {y:.9f} 0 0 0 {math.sin(yaw / 2):.12f} "
                      f"{math.cos(yaw / 2):.12f}\n")
    partial.replace(path)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--method", choices=sorted(PROGRAMS), required=True)
    parser.add_argument("--particles", type=int, default=20, help="rbpf: particles (20)")
    parser.add_argument("--seed", type=int, default=1, help="rbpf: RANDOM_SEED (1)")
    args = parser.parse_args()
    program = PROGRAMS[args.method]
    try:
        if args.particles < 1:
            raise Failure(f"--particles {args.particles}: must be >= 1")
        for tool in (program, "carmen2rawlog"):
            if shutil.which(tool) is None:
                raise Failure("mrpt-apps is not installed: apt-get install mrpt-apps")
        output = Path(args.output).resolve()
        work = output.parent / "mrpt"
        out_dir = work / "out"
        work.mkdir(parents=True, exist_ok=True)
        times = convert_scans(args.input, work / "mrpt_input.log")
        (work / "times.txt").write_text("".join(f"{t!r}\n" for t in mrpt_times(times)))
        run(["carmen2rawlog", "-q", "-w", "-i", str(work / "mrpt_input.log"),
             "-o", str(work / "obs.rawlog")], work / "carmen2rawlog.out")
        run([rawlog_to_sf(), str(work / "obs.rawlog"), str(work / "times.txt"),
             str(work / "sf.rawlog")], work / "rawlog_to_sf.out")
        written = (work / "rawlog_to_sf.out").read_text(errors="replace").split()
        if written != [str(len(times))]:
            raise Failure(f"rawlog_to_sf wrote {' '.join(written)[:40]!r} scans for {len(times)}")

        values = {"OUT_DIR": str(out_dir), "PARTICLES": str(args.particles),
                  "SEED": str(args.seed % 2**31)}
        ini = (HERE / f"{args.method}.ini").read_text()
        for key, value in values.items():
            ini = ini.replace(f"@{key}@", value)
        (work / f"{args.method}.ini").write_text(ini)
        run([program, str(work / f"{args.method}.ini"), str(work / "sf.rawlog")],
            work / f"{program}.out")

        poses = read_path(out_dir / "log_estimated_path.txt", len(times))
        if args.method == "rbpf":  # icp-slam's map is a point cloud: no map
            write_map(out_dir, output)
        write_tum(output, times, poses)
    except (Failure, OSError) as e:
        print(f"mrpt_slam.py: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
