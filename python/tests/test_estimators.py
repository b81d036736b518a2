"""Python estimators through the runner equal the same estimator fed by hand; built-in estimators
through the module equal the command line."""

import json
import math
import os

import numpy as np
import pytest

import slamrig
from conftest import HERE, run
from numpy_pf import ReportsParticleFilter

DATA = os.path.join(HERE, "data")


def by_hand(dataset, duration_s, seed, **options):
    """The runner's loop, written out: every record to add_record (when there is one), each scan
    its synchroniser completes to add_scan, the records of the first duration_s seconds."""
    estimator = ReportsParticleFilter(seed=seed, **options)
    config = slamrig.EstimatorConfig("mine", "dead-reckoning")  # the default odometry options
    sync = slamrig.ScanSynchronizer(config, slamrig.resolve_odometry_source(dataset))
    poses, first = [], None
    for record in dataset:
        first = record.time_ns if first is None else first
        if (record.time_ns - first) * 1e-9 > duration_s:
            break
        for scan in sync.add(record):
            poses.append((scan.scan.time_ns,) + tuple(estimator.add_scan(scan)["pose"]))
    for scan in sync.flush():
        poses.append((scan.scan.time_ns,) + tuple(estimator.add_scan(scan)["pose"]))
    return np.array(poses), estimator


def test_runner_trajectory_equals_the_estimator_fed_by_hand(intel):
    spec = slamrig.load_scenario(os.path.join(DATA, "intel_numpy_pf.yaml"))
    result = slamrig.run_scenario(spec)
    online = result.configs["mine"].run.online
    assert len(online) > 100
    hand, estimator = by_hand(slamrig.read_log(intel), spec.duration_s,
                              slamrig.estimator_seed(spec.seed, "mine"),
                              particles=8, beam_step=4, shift_cells=1)
    # Same records, same seed: the same bits.
    np.testing.assert_array_equal(online.stamps_ns, hand[:, 0].astype(np.int64))
    np.testing.assert_array_equal(online.poses, hand[:, 1:])
    stats = result.configs["mine"].run.statistics
    assert stats["updates"] == estimator.updates and stats["resamples"] == estimator.resamples
    # Scored like any estimator: its map and metrics are in the result.
    metrics = result.configs["mine"].metrics
    assert math.isfinite(metrics["ate_rmse_m"]) and metrics["scans"] == len(online)
    assert result.passed  # the file's expectation on the python configuration
    assert result.configs["mine"].run.map.log_odds.shape[0] > 10


def test_a_python_object_passed_from_python_runs_beside_the_file_configs(intel, tmp_path):
    class Odometry:
        """Composes the odometry increments: dead reckoning written in Python."""

        def __init__(self, scale=1.0):
            self.pose = slamrig.Pose2()
            self.scale = scale

        def add_scan(self, scan):
            self.pose = self.pose * scan.increment
            return self.pose

    spec = slamrig.load_scenario(os.path.join(DATA, "intel_numpy_pf.yaml"))
    spec.add_config(slamrig.EstimatorConfig.python("odometry_py", Odometry, scale=1.0))
    result = slamrig.run_scenario(spec)
    mine = result.configs["odometry_py"].run.online.poses
    builtin = result.configs["dead_reckoning"].run.online.poses
    # Dead reckoning composes the same increments in C++.
    np.testing.assert_allclose(mine, builtin, rtol=0, atol=1e-9)
    result.write_report(str(tmp_path))
    metrics = json.load(open(tmp_path / "metrics.json"))
    assert "odometry_py" in json.dumps(metrics)
    assert os.path.exists(tmp_path / "odometry_py.tum")


def test_builtin_estimator_through_the_module_equals_slamrig_slam(cli, intel, tmp_path):
    out = run([cli, "slam", intel, "--algorithm", "icp-odometry", "--out", str(tmp_path)])
    assert out.returncode == 0, out.stderr
    config = slamrig.EstimatorConfig("icp", "icp-odometry")
    result = slamrig.run_estimator(config, slamrig.read_log(intel))
    tum = np.loadtxt(tmp_path / "trajectory.tum")
    poses = result.final.poses
    assert tum.shape[0] == len(poses)
    # The TUM file is in the estimator's frame placed at the reference: compare relative motion.
    rel_mine = np.diff(poses[:, 2])
    rel_cli = np.diff(2 * np.arctan2(tum[:, 6], tum[:, 7]))
    wrap = lambda a: (a + math.pi) % (2 * math.pi) - math.pi
    np.testing.assert_allclose(wrap(rel_mine - rel_cli), 0, atol=1e-6)


def test_estimator_interface_by_hand_on_a_builtin():
    sim = slamrig.Simulator("office", seed=2)
    config = slamrig.EstimatorConfig("pf", "pf", particles=5)
    estimator = slamrig.Estimator(config, run_seed=2)
    sync = slamrig.ScanSynchronizer(config, slamrig.OdometrySource.wheel_ticks)
    estimates = []
    for step in sim.run(3.0):
        for record in step.records:
            estimator.add_record(record)
            estimates += [estimator.add_scan(s) for s in sync.add(record)]
    assert len(estimates) == 120
    assert estimator.particles().shape == (5, 4)
    assert estimator.map().width > 0
    assert set(estimator.statistics()) >= {"mean_neff", "resamples", "updates"}


def test_evaluation_against_independent_numbers():
    rng = np.random.default_rng(1)
    t = np.arange(200) * 0.1
    reference = np.column_stack([t, np.cos(t), np.sin(2 * t), t * 0.3])
    # The estimate: the reference moved rigidly, plus known noise on x.
    c, s = math.cos(0.7), math.sin(0.7)
    noise = rng.normal(0, 0.01, len(t))
    x = c * reference[:, 1] - s * reference[:, 2] + 3 + noise * c
    y = s * reference[:, 1] + c * reference[:, 2] - 1 + noise * s
    estimate = np.column_stack([t, x, y, reference[:, 3] + 0.7])
    ate = slamrig.ate(estimate, reference)
    # After the best rigid alignment the residual is at most the noise and about its RMS.
    assert ate["translation"]["rmse"] <= math.sqrt(np.mean(noise ** 2)) + 1e-12
    assert ate["translation"]["rmse"] > 0.5 * math.sqrt(np.mean(noise ** 2))
    assert abs(ate["reference_from_estimate"].theta + 0.7) < 0.01
    exact = slamrig.ate(reference, reference)
    assert exact["translation"]["rmse"] < 1e-12
    nees = slamrig.nees(reference[:, 1:], reference[:, 1:] + [0.1, 0, 0],
                        np.tile(np.eye(3) * 0.01, (len(t), 1, 1)))
    np.testing.assert_allclose(nees, 1.0, rtol=1e-12)


def test_broken_scenarios_raise_with_file_line_and_key(cli):
    path = os.path.join(DATA, "broken_key.yaml")
    with pytest.raises(slamrig.ConfigError) as raised:
        slamrig.load_scenario(path)
    message = str(raised.value)
    assert "broken_key.yaml:6:" in message and "slam.pf.particlez" in message
    assert "\n" not in message
    # The command line prints the same message.
    out = run([cli, "run", path, "--out", "/tmp/never"])
    assert out.returncode == 2 and message in out.stderr
    # A Python estimator that cannot be imported names the module.
    spec = slamrig.load_scenario(os.path.join(DATA, "broken_python.yaml"))
    with pytest.raises(slamrig.ConfigError, match="no_such_module_here"):
        slamrig.run_scenario(spec)
    # An unknown option of a built-in algorithm, from Python.
    with pytest.raises(slamrig.ConfigError, match="particlez"):
        slamrig.EstimatorConfig("pf", "pf", particlez=3)
