#!/usr/bin/env python3
"""Writes lab.pgm and lab.yaml, the map_server map behind worlds/lab_map.yaml.

A 16 m x 12 m lab at 0.05 m per pixel: outer walls, two offices with doors, a slanted wall
(a staircase of cells once rasterised) and some desks. Plain Python, no dependencies:
run it again to regenerate the files byte for byte.
"""
import math
import os

RES = 0.05
W, H = 320, 240  # pixels
FREE, OCC, UNKNOWN = 254, 0, 205

here = os.path.dirname(os.path.abspath(__file__))
grid = [[FREE] * W for _ in range(H)]  # grid[row][col], row 0 = lowest y


def fill(x0, y0, x1, y1, value=OCC):
    """Fills the metric rectangle [x0, x1] x [y0, y1]."""
    for r in range(max(0, int(y0 / RES)), min(H, int(math.ceil(y1 / RES)))):
        for c in range(max(0, int(x0 / RES)), min(W, int(math.ceil(x1 / RES)))):
            grid[r][c] = value


def line(x0, y0, x1, y1, width):
    """A thick straight wall between two points."""
    n = int(math.hypot(x1 - x0, y1 - y0) / (RES / 2)) + 1
    for i in range(n + 1):
        x = x0 + (x1 - x0) * i / n
        y = y0 + (y1 - y0) * i / n
        fill(x - width / 2, y - width / 2, x + width / 2, y + width / 2)


# Outside the building is unknown, as in a map made by a SLAM run.
fill(0.0, 0.0, 16.0, 12.0, UNKNOWN)
fill(0.2, 0.2, 15.8, 11.8, FREE)
# Outer walls.
fill(0.2, 0.2, 15.8, 0.4)
fill(0.2, 11.6, 15.8, 11.8)
fill(0.2, 0.2, 0.4, 11.8)
fill(15.6, 0.2, 15.8, 11.8)
# Office 1 (north-west) with a door on its south side.
fill(0.4, 7.5, 3.0, 7.65)
fill(4.4, 7.5, 6.0, 7.65)
fill(5.85, 7.5, 6.0, 11.6)
# Office 2 (north-east) with a door on its west side.
fill(10.0, 7.5, 15.6, 7.65)
fill(10.0, 7.5, 10.15, 8.6)
fill(10.0, 10.0, 10.15, 11.6)
# A slanted partition in the south-east.
line(11.0, 1.5, 14.0, 4.5, 0.15)
# Desks and a cabinet.
fill(2.0, 9.5, 3.6, 10.3)
fill(12.0, 9.8, 14.5, 10.6)
fill(6.8, 2.8, 9.2, 3.6)
fill(0.4, 3.0, 0.9, 5.0)

with open(os.path.join(here, "lab.pgm"), "wb") as f:
    f.write(b"P5\n# slamrig lab map (make_lab_map.py)\n%d %d\n255\n" % (W, H))
    for row in reversed(grid):  # PGM rows run from the top (highest y) down
        f.write(bytes(row))
with open(os.path.join(here, "lab.yaml"), "w") as f:
    f.write("image: lab.pgm\nresolution: 0.05\norigin: [-1.0, -1.0, 0.0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n")
