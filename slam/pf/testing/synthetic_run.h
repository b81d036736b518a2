#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "slam/matching/testing/segment_world.h"
#include "slam/odometry/scan_sync.h"
#include "slam/odometry/wheel_odometry.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam::testing {

/// A differential-drive robot driving laps of a closed waypoint loop through a SegmentWorld,
/// with ECE276A-like sensors: encoders and lidar at 40 Hz, gyro at 100 Hz.
struct SyntheticRunOptions {
  std::vector<Eigen::Vector2d> waypoints;  ///< closed loop, driven in order, starting at [0]
  int laps = 1;
  double max_duration_s = 1e9;  ///< stop early after this long
  double speed_m_s = 0.5;
  double scan_rate_hz = 40.0;
  double encoder_rate_hz = 40.0;
  double imu_rate_hz = 100.0;
  RangeFinderSpec lidar;
  DiffDriveParams robot;
  double right_scale_error = 0.01;  ///< systematic wheel-distance error (calibration), relative
  double left_scale_error = -0.01;
  double wheel_noise = 0.02;  ///< random relative error per encoder interval
  double gyro_sigma_rad_s = 0.01;
  double gyro_bias_rad_s = 0.002;
  std::uint64_t seed = 1;
};

/// The records in time order and the true poses at every scan.
struct SyntheticRun {
  std::vector<Record> records;
  std::vector<GroundTruthPose> truth;
  int num_scans = 0;
};

/// Simulates the run at 1 kHz (kinematic, no dynamics) and samples the sensors.
SyntheticRun MakeSyntheticRun(const SegmentWorld& world, const SyntheticRunOptions& options);

/// The corridor loop of SegmentWorld::Office(), 52 m per lap.
std::vector<Eigen::Vector2d> OfficeLoop();

/// A short, fast run for filter tests: one leg and a corner of the office loop (36 s), scans at
/// 10 Hz with 271 beams, wheels miscalibrated by +-3 % and a 0.01 rad/s gyro bias; the records
/// synchronised to scans. Built once per process.
struct ShortOfficeRun {
  SyntheticRun run;
  std::vector<SyncedScan> scans;
};
const ShortOfficeRun& GetShortOfficeRun();

/// The records of a 20 s stretch of the office loop (scans at 10 Hz, 181 beams, the right wheel
/// 2 % long), for estimator-seam tests. Built once per process.
const std::vector<Record>& SmallOfficeRecords();

/// Position RMSE of `estimate` (one pose per true pose) against the truth, the estimate anchored
/// at the first true pose.
double AnchoredPositionRmse(const std::vector<Pose2>& estimate,
                            const std::vector<GroundTruthPose>& truth);

/// Scans `from` to `to` of a run.
struct Stretch {
  std::size_t from = 0;
  std::size_t to = 0;
};
/// The first stretch from scan `first` on over which the truth turns by more than `min_turn_rad`
/// within `max_scans` scans (the shortest from its start); {0, 0} when there is none.
Stretch FirstTurn(const std::vector<GroundTruthPose>& truth, double min_turn_rad, std::size_t first,
                  std::size_t max_scans);
/// `scans` with a gap in the log over `gap`: the scans strictly inside it are missing (scan and
/// odometry), and scan `gap.to` comes with no motion and the odometry's silence since `gap.from`
/// (SyncedScan::odometry_gap_s), as a reader hands a log without ODOM lines there.
std::vector<SyncedScan> WithOdometryGap(const std::vector<SyncedScan>& scans, Stretch gap);

/// How far the last pose of an estimate (anchored at the first true pose) ends from the truth's.
struct EndError {
  double position_m = 0.0;
  double heading_rad = 0.0;
};
EndError EndPoseError(const Pose2& last_estimate, const std::vector<GroundTruthPose>& truth);

}  // namespace slamrig::slam::testing
