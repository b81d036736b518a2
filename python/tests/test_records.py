"""Records and arrays through the module agree with the command line's files for the same seed."""

import os

import numpy as np

import slamrig
from conftest import run


def simulate_in_python(seed, duration_s):
    # As `slamrig simulate --duration` does: step while t < limit - half a step, then flush.
    sim = slamrig.Simulator("office", seed=seed)
    steps = []
    while sim.time < duration_s - 0.5 * sim.step_s:
        steps.append(sim.step())
    steps.append(sim.flush())
    return steps


def test_simulated_scans_and_truth_equal_the_cli_log(cli, tmp_path):
    out = run([cli, "simulate", "office", "--duration", "6", "--seed", "7", "--out", str(tmp_path)])
    assert out.returncode == 0, out.stderr
    log = slamrig.read_log(str(tmp_path / "run.log"))
    steps = simulate_in_python(7, 6.0)
    scans, truth = [], []
    for step in steps:
        for record, sample in zip(step.records, step.truth):
            if isinstance(record, slamrig.LaserScan):
                scans.append(record)
                truth.append(sample)
    logged = log.scans()
    assert len(scans) == len(logged) > 200
    # The log writes the shortest text that reads back to the same float: equal bits.
    for mine, theirs in zip(scans, logged):
        assert mine.time_ns == theirs.time_ns
        assert np.array_equal(mine.ranges, theirs.ranges)
        assert mine.angle_min == theirs.angle_min
        assert mine.angle_increment == theirs.angle_increment
    # truth.tum: t x y z qx qy qz qw at every scan.
    tum = np.loadtxt(tmp_path / "truth.tum")
    assert tum.shape[0] == len(truth)
    xy = np.array([[t.map_from_base.x, t.map_from_base.y] for t in truth])
    yaw = np.array([t.map_from_base.theta for t in truth])
    np.testing.assert_allclose(tum[:, 1:3], xy, rtol=0, atol=1e-9)
    np.testing.assert_allclose(2 * np.arctan2(tum[:, 6], tum[:, 7]), yaw, rtol=0, atol=1e-9)
    np.testing.assert_allclose(tum[:, 0], [t.time for t in truth], rtol=0, atol=1e-9)
    # The log's reference channel is the TRUEPOS lines: the same truth, as a zero-copy view.
    np.testing.assert_allclose(log.reference_poses[:, :2], xy, rtol=0, atol=1e-9)


def test_same_seed_same_bits_other_seed_other_noise():
    a = simulate_in_python(3, 2.0)
    b = simulate_in_python(3, 2.0)
    c = simulate_in_python(4, 2.0)

    def ranges(steps):
        return np.concatenate([r.ranges for s in steps for r in s.records
                               if isinstance(r, slamrig.LaserScan)])
    assert ranges(a).tobytes() == ranges(b).tobytes()
    assert ranges(a).shape == ranges(c).shape
    assert ranges(a).tobytes() != ranges(c).tobytes()


def test_log_arrays_are_views_that_keep_their_owner(intel):
    log = slamrig.read_log(intel)
    scans = log.scans()
    assert len(scans) == 910
    first = scans[0].ranges
    assert not first.flags.writeable and not first.flags.owndata
    assert np.shares_memory(first, log.scans()[0].ranges)  # the same buffer, twice
    poses = log.reference_poses
    assert poses.shape == (910, 3) and not poses.flags.owndata
    expected = poses.copy()
    stacked = log.scan_ranges()
    assert stacked.shape == (910, 180)
    np.testing.assert_array_equal(stacked[0], first)
    del log, scans
    import gc
    gc.collect()
    # The dataset lives as long as a view of it.
    np.testing.assert_array_equal(poses, expected)
    assert np.isfinite(first).all()


def test_records_of_every_kind_from_a_simulation():
    kinds = set()
    for step in simulate_in_python(1, 1.0):
        for r in step.records:
            kinds.add(type(r).__name__)
            if isinstance(r, slamrig.WheelTicks):
                assert r.right_ticks.dtype == np.int32 and len(r.right_ticks) == 2
            if isinstance(r, slamrig.ImuSample):
                assert abs(r.linear_acceleration[2] - 9.8) < 0.5  # gravity
    assert kinds == {"LaserScan", "WheelTicks", "ImuSample"}


def test_a_bad_log_raises_parse_error_with_file_and_line(tmp_path):
    bad = tmp_path / "bad.log"
    bad.write_text("ODOM 0 0 0 0 0 0 1.0 host 1.0\nFLASER 3 1.0 nan 1.0 0 0 0 0 0 0 1.0 h 1.0\n")
    try:
        slamrig.read_log(str(bad))
    except slamrig.ParseError as e:
        assert "bad.log:2" in str(e) and "\n" not in str(e)
    else:
        raise AssertionError("no ParseError")
