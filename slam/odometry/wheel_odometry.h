#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "slam/odometry/odometry_interval.h"
#include "slam/types/pose2.h"
#include "slam/types/records.h"

namespace slamrig::slam {

/// Geometry of a differential-drive robot's wheels and encoders. Defaults are the ECE276A robot
/// (0.254 m wheels, 360 ticks per revolution, i.e. 0.0022 m per tick; effective track width
/// 0.3937 m, the mean of its inner and outer wheel spacing).
struct DiffDriveParams {
  double wheel_radius_m = 0.127;   ///< radius of every wheel
  int ticks_per_revolution = 360;  ///< encoder ticks per wheel revolution
  double track_width_m = 0.3937;   ///< lateral distance between left and right wheel contacts

  /// Distance a wheel rolls per encoder tick, metres.
  double MetresPerTick() const;

  /// One message per broken rule, e.g. "diff_drive.wheel_radius_m = 0; must be > 0".
  std::vector<std::string> Validate() const;
};

/// How WheelOdometry turns tick increments (and gyro samples) into poses.
struct WheelOdometryOptions {
  DiffDriveParams robot;
  /// Yaw change from the mean gyro z rate since the previous ticks times the interval (the
  /// ECE276A reports' v from encoders, omega from the IMU); false: from the wheel difference.
  bool use_gyro = true;

  /// One message per broken rule (prefixed "wheel_odometry.").
  std::vector<std::string> Validate() const;
};

/// Integrates encoder tick increments, optionally with gyro yaw rate, into an odometry pose in the
/// `odom` frame, which starts at the identity. Each interval is integrated as one
/// constant-curvature arc (the exact differential-drive model with the sinc term, Wang, ECE276A
/// report, Eq. 6). Yaw comes from the gyro when `use_gyro` and at least one IMU sample fell into
/// the interval; otherwise (first ticks record, gyro dropout) from the encoders, and that is
/// counted.
class WheelOdometry {
 public:
  explicit WheelOdometry(const WheelOdometryOptions& options);

  /// Buffers a gyro sample for the next AddTicks. Samples must arrive in time order.
  void AddImu(const ImuSample& imu);

  /// Integrates one tick-increment record and returns the pose at `ticks.time`. Both sides must
  /// list at least one wheel (checked); per side the wheels' ticks are averaged.
  OdometryPose AddTicks(const WheelTicks& ticks);

  /// Current pose of base_link in the odom frame.
  const Pose2& pose() const { return pose_; }
  /// Intervals whose yaw came from the encoders although `use_gyro` was set.
  int gyro_fallbacks() const { return gyro_fallbacks_; }

 private:
  WheelOdometryOptions options_;
  Pose2 pose_;
  bool has_last_time_ = false;
  Time last_time_;
  OdometryInterval interval_;
  int gyro_fallbacks_ = 0;
};

}  // namespace slamrig::slam
