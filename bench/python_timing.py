#!/usr/bin/env python3
"""Speed of the Python module against the command line's C++ (issue 15's done-when):

  read:  the 910 intel-corrected scans into NumPy through the module (read_log, a view of every
         scan's ranges, and the stacked (910, 180) array) against the C++ parse the command line
         does (ReadLog, build/bench/map_benchmark --benchmark_filter=BM_ReadLogIntel); target
         within 1.5x.
  sim:   the office world stepped from Python one physics step at a time (step(), touching each
         step's records), as simulated seconds per CPU second; target >= 200x real time. Also
         sim.run(), which steps in C++ and returns the steps with records.

  python3 bench/python_timing.py [BUILD_DIR] [REPETITIONS]      (defaults: build, 5)

Medians of REPETITIONS runs; on a shared machine quote the machine's load with them.
"""

import os
import re
import statistics
import subprocess
import sys
import time

build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "build")
repetitions = int(sys.argv[2]) if len(sys.argv) > 2 else 5
sys.path.insert(0, os.path.join(build, "python"))
import slamrig  # noqa: E402

INTEL = "carmen_corrected/intel-corrected.log.gz"


def cpu(f):
    start = time.process_time()
    f()
    return time.process_time() - start


def read_into_numpy():
    log = slamrig.read_log(INTEL)
    views = [s.ranges for s in log.scans()]
    stacked = log.scan_ranges()
    assert len(views) == 910 and stacked.shape == (910, 180)


def cli_parse_ms():
    bench = os.path.join(build, "bench", "map_benchmark")
    out = subprocess.run([bench, "--benchmark_filter=BM_ReadLogIntel",
                          "--benchmark_repetitions=%d" % repetitions,
                          "--benchmark_report_aggregates_only=true"],
                         capture_output=True, text=True, check=True).stdout
    # "BM_ReadLogIntel_median   123 ms   122 ms" : wall, then CPU.
    match = re.search(r"BM_ReadLogIntel_median\s+([\d.]+) ms\s+([\d.]+) ms", out)
    return float(match.group(2))


def step_office(seconds):
    sim = slamrig.Simulator("office", seed=1)
    records = 0
    while sim.time < seconds:
        records += len(sim.step().records)
    assert records > 0


def run_office(seconds):
    sim = slamrig.Simulator("office", seed=1)
    assert len(sim.run(seconds)) > 0


read_once = cpu(read_into_numpy)  # warm the file cache
read_ms = statistics.median(cpu(read_into_numpy) for _ in range(repetitions)) * 1e3
parse_ms = cli_parse_ms()
print("read: module %.1f ms CPU (median of %d), C++ ReadLog %.1f ms CPU: %.2fx (target <= 1.5x)"
      % (read_ms, repetitions, parse_ms, read_ms / parse_ms))

SIM_S = 60.0
step_x = statistics.median(SIM_S / cpu(lambda: step_office(SIM_S)) for _ in range(repetitions))
run_x = statistics.median(SIM_S / cpu(lambda: run_office(SIM_S)) for _ in range(repetitions))
print("sim: office, %.0f s simulated: step() from Python %.0fx real time, run() %.0fx "
      "(CPU time, median of %d; target >= 200x)" % (SIM_S, step_x, run_x, repetitions))
