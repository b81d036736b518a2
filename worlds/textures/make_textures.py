#!/usr/bin/env python3
"""Writes the floor textures the MuJoCo camera renders (tiles.png, carpet.png, concrete.png).

Pure Python (zlib and struct only) and deterministic: the same script writes the same bytes.
Each image is 256 x 256 RGB and tiles seamlessly; a world's camera spec says how many metres one
image covers. Run from anywhere: `python3 worlds/textures/make_textures.py`.
"""

import math
import os
import struct
import zlib

SIZE = 256


def write_png(path, pixels):
    """Writes `pixels` (rows of (r, g, b) tuples) as an 8-bit RGB PNG."""
    raw = bytearray()
    for row in pixels:
        raw.append(0)  # filter type: none
        for r, g, b in row:
            raw.extend((r, g, b))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", SIZE, SIZE, 8, 2, 0, 0, 0)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def hash_noise(x, y, seed):
    """A repeatable value in [0, 1) for integer (x, y): an integer hash, no global RNG state."""
    h = (x * 374761393 + y * 668265263 + seed * 2147483647) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    return ((h ^ (h >> 16)) & 0xFFFF) / 65536.0


def clamp(v):
    return max(0, min(255, int(round(v))))


def tiles():
    """Four by four square tiles, cream and terracotta in a checkerboard, with dark grout."""
    cell = SIZE // 4
    rows = []
    for y in range(SIZE):
        row = []
        for x in range(SIZE):
            if x % cell < 3 or y % cell < 3:
                row.append((60, 55, 50))
                continue
            base = (225, 210, 175) if ((x // cell) + (y // cell)) % 2 == 0 else (180, 85, 50)
            n = (hash_noise(x, y, 1) - 0.5) * 16
            row.append(tuple(clamp(c + n) for c in base))
        rows.append(row)
    return rows


def carpet():
    """A blue carpet with a red diamond lattice and fibre noise."""
    rows = []
    for y in range(SIZE):
        row = []
        for x in range(SIZE):
            u = (x % 64) - 32
            v = (y % 64) - 32
            diamond = abs(abs(u) + abs(v) - 24) < 4
            base = (170, 40, 45) if diamond else (40, 60, 140)
            n = (hash_noise(x, y, 2) - 0.5) * 30
            row.append(tuple(clamp(c + n) for c in base))
        rows.append(row)
    return rows


def concrete():
    """Grey concrete: smooth light and dark blotches (periodic sines, so it tiles) and grain."""
    rows = []
    k = 2.0 * math.pi / SIZE
    for y in range(SIZE):
        row = []
        for x in range(SIZE):
            blotch = (math.sin(k * x) * math.cos(2 * k * y) + 0.6 * math.sin(3 * k * (x + y))
                      + 0.4 * math.cos(k * (2 * x - y)))
            g = 140 + 35 * blotch + (hash_noise(x, y, 3) - 0.5) * 24
            row.append((clamp(g), clamp(g - 3), clamp(g - 8)))
        rows.append(row)
    return rows


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    for name, make in (("tiles", tiles), ("carpet", carpet), ("concrete", concrete)):
        write_png(os.path.join(here, name + ".png"), make())


if __name__ == "__main__":
    main()
