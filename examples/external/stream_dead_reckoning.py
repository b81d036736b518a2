#!/usr/bin/env python3
"""Dead reckoning as a streaming slamrig estimator (`mode: stream`): a start to copy.

slamrig runs it as `command: [python3, ./stream_dead_reckoning.py]` and writes the run to its
stdin as an MCAP stream of ROS 2 messages (CDR); after each /scan it waits for one
geometry_msgs/PoseStamped on /estimate on stdout, stamped like the scan (docs/external.md).
The pose is the wheel odometry between scans as slamrig's built-in dead reckoning computes it:
encoder ticks (/joint_states) summed, gyro rates (/imu) averaged, one exact-arc step per scan
(the robot's geometry from the stream's `slamrig.robot` metadata). Same arithmetic, same bits.
A log without encoders has its odometry poses on /odom: they are interpolated to each scan.
Python 3 standard library only (numpy is welcome in a real one: np.frombuffer reads the
ranges of a /scan); no slamrig code.
"""

import math
import struct
import sys

MAGIC = b"\x89MCAP0\r\n"
PI2 = 2.0 * math.pi


def strings(buf, pos, count):  # MCAP strings: uint32 length, bytes
    out = []
    for _ in range(count):
        (n,) = struct.unpack_from("<I", buf, pos)
        out.append(buf[pos + 4:pos + 4 + n].decode())
        pos += 4 + n
    return out, pos


class Cdr:  # little-endian CDR after the 4-byte encapsulation header
    def __init__(self, data):
        self.d, self.p = data, 4

    def take(self, fmt, size):
        self.p += (-(self.p - 4)) % size  # align to the primitive's size
        v = struct.unpack_from("<" + fmt, self.d, self.p)
        self.p += struct.calcsize("<" + fmt)
        return v

    def string(self):  # uint32 length with the NUL, the bytes, the NUL
        (n,) = self.take("I", 4)
        self.p += n
        return self.d[self.p - n:self.p - 1].decode()

    def stamp_ns(self):  # std_msgs/Header: stamp, frame_id
        sec, nsec = self.take("iI", 4)
        self.string()
        return sec * 1_000_000_000 + nsec


class Writer:  # an unchunked MCAP stream with one channel, /estimate
    def __init__(self, out):
        self.out, self.seq = out, 0
        out.write(MAGIC)
        self.record(1, self.s(b"ros2") + self.s(b"stream_dead_reckoning.py"))  # Header
        self.record(3, struct.pack("<H", 1) + self.s(b"geometry_msgs/msg/PoseStamped") +
                    self.s(b"ros2msg") + self.s(b"std_msgs/Header header\ngeometry_msgs/Pose pose\n"))
        self.record(4, struct.pack("<HH", 0, 1) + self.s(b"/estimate") + self.s(b"cdr") +
                    struct.pack("<I", 0))  # Channel 0 on schema 1, no metadata

    @staticmethod
    def s(b):
        return struct.pack("<I", len(b)) + b

    def record(self, op, content):
        self.out.write(struct.pack("<BQ", op, len(content)) + content)

    def pose(self, t_ns, x, y, theta):  # PoseStamped: stamp, frame "odom", position, quaternion
        cdr = (b"\0\1\0\0" + struct.pack("<iII", t_ns // 10**9, t_ns % 10**9, 5) + b"odom\0" +
               bytes(7) + struct.pack("<7d", x, y, 0.0, 0.0, 0.0, math.sin(0.5 * theta),
                                      math.cos(0.5 * theta)))
        self.record(5, struct.pack("<HIQQ", 0, self.seq, t_ns, t_ns) + cdr)
        self.seq += 1
        self.out.flush()  # the bench waits for it

    def close(self):
        self.record(15, struct.pack("<I", 0))  # DataEnd
        self.record(2, struct.pack("<QQI", 0, 0, 0))  # Footer without a summary
        self.out.write(MAGIC)
        self.out.flush()


def normalise(a):  # into (-pi, pi], as slamrig's Pose2
    a = math.remainder(a, PI2)
    return a + PI2 if a <= -math.pi else a


def compose(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], normalise(a[2] + b[2]))


def inverse(a):
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], normalise(-a[2]))


def interpolate(odom, t):  # between the last two (time, pose), linear, shortest yaw; held at ends
    (t0, p0), (t1, p1) = odom[0], odom[-1]
    f = min(max((t - t0) / (t1 - t0), 0.0), 1.0) if t1 > t0 else 1.0
    return (p0[0] + f * (p1[0] - p0[0]), p0[1] + f * (p1[1] - p0[1]),
            normalise(p0[2] + f * normalise(p1[2] - p0[2])))


def sinc(x):
    return 1.0 - x * x / 6.0 if abs(x) < 1e-4 else math.sin(x) / x


def main():
    inp, out = sys.stdin.buffer, Writer(sys.stdout.buffer)
    if inp.read(8) != MAGIC:
        sys.exit("stream_dead_reckoning.py: stdin is not an MCAP stream")
    robot, topics, total, tpr = {}, {}, None, None
    right = left = gyro = 0.0
    count, held, last_ns, pose = 0, None, None, (0.0, 0.0, 0.0)
    odom, last_odom = [], None
    while True:
        head = inp.read(9)
        if len(head) < 9:
            sys.exit("stream_dead_reckoning.py: the stream ended without its Footer")
        op, n = struct.unpack("<BQ", head)
        body = inp.read(n)
        if op == 2:  # Footer: the end of the run
            break
        if op == 12:  # Metadata: name, then a map (its byte length, then key, value, ...)
            (name,), pos = strings(body, 0, 1)
            kv, end = [], pos + 4 + struct.unpack_from("<I", body, pos)[0]
            pos += 4
            while pos < end:
                pair, pos = strings(body, pos, 2)
                kv.append(pair)
            if name == "slamrig.robot":
                robot = dict(kv)
                tpr = float(robot["ticks_per_revolution"])
        elif op == 4:  # Channel: id, schema id, topic
            (topic,), _ = strings(body, 4, 1)
            topics[struct.unpack_from("<H", body)[0]] = topic
        elif op == 5:  # Message: channel, sequence, log time, publish time, CDR
            topic, cdr = topics[struct.unpack_from("<H", body)[0]], Cdr(body[22:])
            if topic == "/joint_states":  # wheel positions: accumulated ticks * 2 pi / tpr
                cdr.stamp_ns()
                names = [cdr.string() for _ in range(cdr.take("I", 4)[0])]
                (m,) = cdr.take("I", 4)
                ticks = [round(p * tpr / PI2) for p in cdr.take(f"{m}d", 8)]
                delta = [t - u for t, u in zip(ticks, total or [0] * m)]
                total = ticks
                rights = [d for d, s in zip(delta, names) if "right" in s or s in ("wheel_fr", "wheel_rr")]
                lefts = [d for d, s in zip(delta, names) if not ("right" in s or s in ("wheel_fr", "wheel_rr"))]
                right += float(sum(rights)) / len(rights)  # each side's mean, as slamrig's
                left += float(sum(lefts)) / len(lefts)
            elif topic == "/imu":
                cdr.stamp_ns()
                gyro += cdr.take("13d3d", 8)[15]  # orientation, its covariance; angular z
                count += 1
            elif topic == "/odom" and total is None:  # a log's odometry poses, no encoders
                t = cdr.stamp_ns()
                cdr.string()  # child_frame_id
                x, y, _, _, _, qz, qw = cdr.take("7d", 8)
                odom = odom[-1:] + [(t, (x, y, 2.0 * math.atan2(qz, qw)))]
            elif topic == "/scan":
                t = cdr.stamp_ns()
                if total is None and odom:  # the odometry poses interpolated to the scan
                    o = interpolate(odom, t)
                    pose = compose(pose, compose(inverse(last_odom), o)) if last_odom else pose
                    last_odom = o
                elif last_ns is not None:
                    dt = (t - last_ns) * 1e-9
                    mpt = 2.0 * math.pi * float(robot["wheel_radius_m"]) / tpr
                    r_m, l_m = right * mpt, left * mpt
                    d, yaw = 0.5 * (r_m + l_m), (r_m - l_m) / float(robot["track_width_m"])
                    if robot["use_gyro"] == "true":
                        if count > 0:
                            held = gyro / count
                        if held is not None:
                            yaw = held * dt
                    half = 0.5 * yaw
                    chord = d * sinc(half)
                    pose = compose(pose, (chord * math.cos(half), chord * math.sin(half),
                                          normalise(yaw)))
                last_ns, right, left, gyro, count = t, 0.0, 0.0, 0.0, 0
                out.pose(t, *pose)
    out.close()


if __name__ == "__main__":
    main()
