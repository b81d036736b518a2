// Encoder + gyro dead reckoning as in the ECE276A reports (Wang Sec. III-A, Zafari "Technical
// approach"): per side distance = mean wheel ticks * metres per tick, v from the mean of both
// sides, yaw change from the mean gyro rate over the interval, integrated with Eq. 6 (sinc term).
#include "slam/odometry/wheel_odometry.h"

#include <numbers>

#include "slam/odometry/diff_drive_model.h"
#include "slam/types/check.h"
#include "slam/types/validation.h"

namespace slamrig::slam {
double DiffDriveParams::MetresPerTick() const {
  return 2.0 * std::numbers::pi * wheel_radius_m / ticks_per_revolution;
}

std::vector<std::string> DiffDriveParams::Validate() const {
  Rules rules;
  rules.Positive("wheel_radius_m", wheel_radius_m)
      .Positive("ticks_per_revolution", ticks_per_revolution)
      .Positive("track_width_m", track_width_m);
  return PrefixErrors("diff_drive", rules.errors());
}

std::vector<std::string> WheelOdometryOptions::Validate() const {
  return PrefixErrors("wheel_odometry", robot.Validate());
}

WheelOdometry::WheelOdometry(const WheelOdometryOptions& options) : options_(options) {
  SLAMRIG_CHECK_VALID(options_, "WheelOdometryOptions");
}

void WheelOdometry::AddImu(const ImuSample& imu) {
  // Samples at or before the last ticks belong to an interval already integrated.
  if (has_last_time_ && imu.time <= last_time_) return;
  interval_.AddGyro(imu.angular_velocity_rad_s.z());
}

OdometryPose WheelOdometry::AddTicks(const WheelTicks& ticks) {
  interval_.AddTicks(ticks);
  // The first record has no interval to take a gyro rate over: its yaw is the encoders'.
  const double dt_s = has_last_time_ ? SecondsBetween(ticks.time, last_time_) : 0.0;
  const OdometryInterval::Motion motion =
      interval_.Take(options_.robot, dt_s, options_.use_gyro && has_last_time_, nullptr);
  if (options_.use_gyro && (!has_last_time_ || motion.gyro_fallback)) ++gyro_fallbacks_;
  pose_ =
      IntegrateDiffDrive(pose_, motion.distance_m, motion.yaw_rad, DiffDriveIntegration::kExactArc);
  has_last_time_ = true;
  last_time_ = ticks.time;
  return OdometryPose{ticks.time, pose_};
}

}  // namespace slamrig::slam
