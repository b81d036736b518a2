#!/usr/bin/env python3
"""examples/external/mrpt/mrpt_slam.py without MRPT: its own conversion and its failures.

    mrpt_wrapper_check.py REPO

Fake carmen2rawlog, rawlog_to_sf and icp-slam (small Python programs on a PATH of their own)
stand in for MRPT: the fake icp-slam answers each scan with the odometry pose its line carries, so
the TUM file must hold exactly those poses at the scans' own stamps. Checked: the CARMEN log
written for MRPT (each scan turned symmetric about its laser's heading), the strictly increasing
times given to MRPT, the .ini (headless), the TUM file, and each failure as one line on stderr,
exit code 1 and no output: MRPT not installed, MRPT failing, a path one pose short, a laser
message the wrapper does not read. The fake rbpf-slam also saves a grid as MRPT does (an 8-bit
grey PNG and its limits), which must come back as a map_server map with the same pixels.
"""

import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

FAKE_CARMEN2RAWLOG = """
import shutil, sys
a = sys.argv
shutil.copy(a[a.index("-i") + 1], a[a.index("-o") + 1])
"""

# Copies the "rawlog" (the CARMEN text) and checks the times: one per scan, strictly increasing.
FAKE_RAWLOG_TO_SF = """
import shutil, sys
times = [float(l) for l in open(sys.argv[2])]
scans = sum(1 for l in open(sys.argv[1]) if l.startswith("ROBOTLASER1"))
if len(times) != scans or any(b <= a for a, b in zip(times, times[1:])):
    sys.exit("bad times")
shutil.copy(sys.argv[1], sys.argv[3])
print(scans)
"""

# Writes log_estimated_path.txt as icp-slam does ("step x y yaw", %f), the odometry of each scan.
FAKE_ICP_SLAM = """
import os, sys
ini = dict(l.split("=", 1) for l in open(sys.argv[1]) if "=" in l and not l.startswith("#"))
ini = {k.strip(): v.strip() for k, v in ini.items()}
window = "SHOW_PROGRESS_IN_WINDOW" if "rbpf" in sys.argv[0] else "SHOW_PROGRESS_3D_REAL_TIME"
assert ini["LOG_FREQUENCY"] == "0" and ini["SAVE_3D_SCENE"] == "0" and ini[window] == "0", ini
mode = os.environ.get("FAKE_MODE", "")
if mode == "fail":
    print("==== MRPT exception ====")
    print("Message:  boom in the map")
    print("Press any key to continue...")
    sys.exit(255)
out = ini["logOutput_dir"]
os.makedirs(out, exist_ok=True)
lines = [l.split() for l in open(sys.argv[2]) if l.startswith("ROBOTLASER1")]
if mode == "short":
    lines = lines[:-1]
with open(os.path.join(out, "log_estimated_path.txt"), "w") as path:
    for step, f in enumerate(lines):
        k = 10 + int(f[8]) + int(f[9 + int(f[8])])
        path.write("%i %f %f %f\\n" % (step, float(f[k + 3]), float(f[k + 4]), float(f[k + 5])))
"""

# rbpf-slam's outputs: the path ("step x y z yaw pitch roll t") and the final grid as an 8-bit grey
# PNG, one row per PNG filter in turn (0 none, 1 sub, 2 up, 3 average, 4 Paeth), with its limits.
FAKE_RBPF_SLAM = FAKE_ICP_SLAM.replace(
    '"%i %f %f %f\\n" % (step,', '"%i %f %f 0 %f 0 0 1\\n" % (step,') + """
import json, struct, zlib
W, H = 14, 10
pixels = [[(r * 7919 + c * c * 104729 + (r * c) ** 3) % 251 for c in range(W)] for r in range(H)]
def paeth(a, b, c):
    p = a + b - c
    return min((abs(p - a), 0, a), (abs(p - b), 1, b), (abs(p - c), 2, c))[2]
raw = b""
for r, row in enumerate(pixels):
    above = pixels[r - 1] if r else [0] * W
    kind = r % 5
    filtered = []
    for c, v in enumerate(row):
        a, b, d = (row[c - 1] if c else 0), above[c], (above[c - 1] if c else 0)
        filtered.append((v - (0, a, b, (a + b) // 2, paeth(a, b, d))[kind]) % 256)
    raw += bytes([kind] + filtered)
def chunk(kind, body):
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
png = (b"\\x89PNG\\r\\n\\x1a\\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 0, 0, 0, 0)) +
       chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
base = os.path.join(out, "finalMap_mrpt__maps__COccupancyGridMap2D_00")
open(base + ".png", "wb").write(png)
open(base + "_limits.txt", "w").write("% limits\\n-1.0 6.0 -2.0 3.0\\n")
open(os.path.join(out, "pixels.txt"), "w").write(json.dumps(pixels))
"""


def robotlaser(t, odom, start, fov, n=5):
    """A ROBOTLASER1 line as slamrig writes it: laser 0.1 m ahead of the base."""
    x, y, th = odom
    lx, ly = x + 0.1 * math.cos(th), y + 0.1 * math.sin(th)
    ranges = " ".join("2.5" for _ in range(n))
    return (f"ROBOTLASER1 0 {start!r} {fov!r} {fov / (n - 1)!r} 30 0.01 0 {n} {ranges} 0 "
            f"{lx!r} {ly!r} {th!r} {x!r} {y!r} {th!r} 0 0 0 0 0 {t!r} slamrig {t!r}\n")


def main():
    repo = Path(sys.argv[1]).resolve()
    script = repo / "examples/external/mrpt/mrpt_slam.py"
    failures = []

    def check(condition, what):
        if not condition:
            failures.append(what)

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        bin_dir, empty = tmp / "bin", tmp / "empty"
        bin_dir.mkdir()
        empty.mkdir()
        for name, body in (("carmen2rawlog", FAKE_CARMEN2RAWLOG), ("icp-slam", FAKE_ICP_SLAM),
                           ("rbpf-slam", FAKE_RBPF_SLAM), ("rawlog_to_sf", FAKE_RAWLOG_TO_SF)):
            (bin_dir / name).write_text(f"#!{sys.executable}\n{body}")
            (bin_dir / name).chmod(0o755)

        # 12 scans along an arc; stamps 25 ms apart but one repeated and one going back (as intel).
        stamps = [0.025 * i for i in range(12)]
        stamps[5] = stamps[4]
        stamps[8] = stamps[7] - 0.01
        odom = [(0.3 * i, 0.05 * i * i, 0.1 * i - 0.4) for i in range(12)]
        start, fov = -1.5, 2.0  # not symmetric: the centre is 0.5 rad left of the laser's heading
        log = tmp / "input.log"
        log.write_text("# CARMEN log\nPARAM robot_front_laser_max 30 slamrig 0\n" +
                       "".join(f"ODOM 0 0 0 0 0 0 {t!r} slamrig {t!r}\n" +
                               robotlaser(t, o, start, fov) for t, o in zip(stamps, odom)))

        def run(out_name, path, mode="", input_log=log, method="icp"):
            env = dict(os.environ, PATH=str(path), FAKE_MODE=mode,
                       SLAMRIG_MRPT_RAWLOG_TO_SF=str(bin_dir / "rawlog_to_sf"))
            output = tmp / out_name / "output.tum"
            output.parent.mkdir()
            result = subprocess.run([sys.executable, str(script), str(input_log), str(output),
                                     "--method", method], env=env, capture_output=True, text=True)
            return result, output

        result, output = run("good", bin_dir)
        check(result.returncode == 0, f"good run: exit {result.returncode}: {result.stderr}")
        if result.returncode == 0:
            rows = [l.split() for l in output.read_text().splitlines()]
            check(len(rows) == 12, f"{len(rows)} poses for 12 scans")
            for i, (row, t, (x, y, th)) in enumerate(zip(rows, stamps, odom)):
                yaw = 2 * math.atan2(float(row[6]), float(row[7]))
                check(abs(float(row[0]) - t) < 1e-9, f"pose {i}: stamp {row[0]}, scan at {t}")
                check(abs(float(row[1]) - x) < 1e-6 and abs(float(row[2]) - y) < 1e-6 and
                      abs(math.remainder(yaw - th, 2 * math.pi)) < 1e-6 and
                      row[3:6] == ["0", "0", "0"], f"pose {i}: {row}, odometry {(x, y, th)}")
            work = output.parent / "mrpt"
            times = [float(l) for l in (work / "times.txt").read_text().split()]
            check(times[5] == stamps[4] + 1e-6 and times[8] == times[7] + 1e-6 and
                  times[9] == stamps[9], f"MRPT's times not made increasing: {times}")
            first = (work / "mrpt_input.log").read_text().splitlines()[0].split()
            check(float(first[2]) == -fov / 2 and float(first[3]) == fov,
                  f"scan not symmetric: start {first[2]}, fov {first[3]}")
            check(abs(float(first[-12]) - (odom[0][2] + start + fov / 2)) < 1e-12,
                  f"laser heading {first[-12]}, want {odom[0][2] + start + fov / 2}")
            ini = (work / "icp.ini").read_text()
            check("@" not in ini and f"logOutput_dir = {work / 'out'}" in ini, "icp.ini: " + ini)

        # rbpf-slam: the same poses, and its grid as a map_server map beside the trajectory.
        result, output = run("rbpf", bin_dir, method="rbpf")
        check(result.returncode == 0, f"rbpf run: exit {result.returncode}: {result.stderr}")
        if result.returncode == 0:
            check(output.read_text() == (tmp / "good/output.tum").read_text(),
                  "rbpf: another trajectory than icp's from the same poses")
            pixels = json.loads((output.parent / "mrpt/out/pixels.txt").read_text())
            pgm = output.with_suffix(".pgm").read_bytes()
            check(pgm == b"P5\n14 10\n255\n" + bytes(sum(pixels, [])), f"rbpf map: {pgm!r}")
            meta = output.with_suffix(".yaml").read_text()
            check("image: output.pgm\nresolution: 0.5\norigin: [-1.0, -2.0, 0.0]\n" in meta,
                  "rbpf map: " + meta)
            ini = (output.parent / "mrpt/rbpf.ini").read_text()
            check("sampleSize = 20\n" in ini and "RANDOM_SEED = 1\n" in ini, "rbpf.ini: " + ini)

        bad_log = tmp / "bad.log"
        bad_log.write_text("RAWLASER1 0 -1.5 2 0.5 30 0.01 0 1 2.5 0 0.0 x 0.0\n")
        cases = [
            ("missing", empty, "", log,
             "mrpt_slam.py: mrpt-apps is not installed: apt-get install mrpt-apps"),
            ("fail", bin_dir, "fail", log,
             "mrpt_slam.py: icp-slam: exit code 255: Message:  boom in the map (all of it in "),
            ("short", bin_dir, "short", log, "log_estimated_path.txt: 11 poses for 12 scans"),
            ("rawlaser", bin_dir, "", bad_log,
             "bad.log:1: RAWLASER1: only ROBOTLASER1 lines carry a scan here"),
        ]
        for name, path, mode, input_log, expected in cases:
            result, output = run(name, path, mode, input_log)
            lines = result.stderr.splitlines()
            check(result.returncode == 1 and len(lines) == 1 and expected in lines[0],
                  f"{name}: exit {result.returncode}, stderr {result.stderr!r}, want {expected!r}")
            check(not output.exists(), f"{name}: wrote {output} all the same")

    for failure in failures:
        print("FAIL", failure)
    print(f"mrpt_wrapper_check: {'FAIL' if failures else 'ok'}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
