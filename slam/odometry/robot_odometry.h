#pragma once

#include <optional>

#include "slam/odometry/wheel_odometry.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// The odometry a robot logs about itself, as record sinks write it (CARMEN ODOM lines, a bag's
/// /odom and /tf): encoder ticks integrated with the nominal geometry (and the gyro, when
/// `options.use_gyro`) by WheelOdometry; OdometryPose records (a log replayed) pass through.
/// One object per recorded stream, fed every record in time order.
class RobotOdometry {
 public:
  explicit RobotOdometry(const WheelOdometryOptions& options) : odometry_(options) {}

  /// Takes the next record: an ImuSample feeds the gyro and returns nothing; a WheelTicks
  /// returns the integrated pose at its time; an OdometryPose returns itself; anything else
  /// returns nothing.
  std::optional<OdometryPose> Add(const Record& record);

  /// The integrated pose after the last WheelTicks record (odom frame, identity at the start).
  const Pose2& pose() const { return odometry_.pose(); }
  /// ImuSample records taken so far.
  int imu_samples() const { return imu_samples_; }
  /// Poses returned so far (integrated or passed through).
  int poses() const { return poses_; }

 private:
  WheelOdometry odometry_;
  int imu_samples_ = 0;
  int poses_ = 0;
};

}  // namespace slamrig::slam
